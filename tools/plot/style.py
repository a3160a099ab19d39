"""Shared look, input checks and output of the statsim charts (tools/plot/*.py).

Each script reads what a host tool wrote (CSV or JSON) and draws one chart family with
matplotlib. `--out FILE.png` writes FILE.png and FILE.svg side by side. Both are written to a
temporary name and renamed, so a failed run leaves no partial file, and both are byte-identical
from one run to the next with the same matplotlib: no date or software version in the files
(`metadata`), and SVG element ids from a fixed salt (`svg.hashsalt`) instead of random ones.

Errors are a line on stderr, `SCRIPT: error: ...`, and exit status 1 (a Python without
matplotlib: status 3, NO_MATPLOTLIB, and the package to install). The host tools run the scripts
through tools/common/plot.hpp, which picks a python3 that has matplotlib.
"""

import argparse
import csv
import json
import math
import os
import sys

NO_MATPLOTLIB = 3
PROG = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "plot"


def fail(message):
    print(f"{PROG}: error: {message}", file=sys.stderr)
    sys.exit(1)


try:
    import matplotlib

    matplotlib.use("Agg")  # files only: no display needed
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, LogLocator
    from matplotlib.transforms import Bbox
except ImportError as e:
    print(
        f"{PROG}: error: {sys.executable} cannot import matplotlib ({e}); install Debian's "
        "python3-matplotlib (tools/setup.sh does)",
        file=sys.stderr,
    )
    sys.exit(NO_MATPLOTLIB)

# Okabe & Ito (2008), reordered so that the first colours are the most distinct on white.
PALETTE = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#646464", "#F0E442"]
GREY = "#6E6E6E"
DARK = "#3C3C3C"
GOAL_RED = "#C85050"

matplotlib.rcParams.update(
    {
        "font.family": "DejaVu Sans",  # matplotlib's default, there wherever it is: the same glyphs
        "font.size": 12,
        "axes.titlesize": 15,
        "axes.labelsize": 13,
        "legend.fontsize": 11,
        "axes.prop_cycle": matplotlib.cycler(color=PALETTE),
        "axes.grid": True,
        "grid.color": "#DDDDDD",
        "grid.linewidth": 0.8,
        "axes.axisbelow": True,
        "legend.framealpha": 0.92,
        "savefig.dpi": 100,
        # Text stays text in the SVG (searchable, selectable, small); the PNG has it rasterised.
        "svg.fonttype": "none",
        "svg.hashsalt": "statsim",
    }
)


def color(i):
    """The i-th colour of the palette (cycles after 8)."""
    return PALETTE[i % len(PALETTE)]


def read_csv(path, columns):
    """The rows of a CSV as dicts; fails unless every name in `columns` is in the header."""
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            header = reader.fieldnames or []
            rows = list(reader)
    except OSError as e:
        fail(f"cannot read {path}: {e.strerror}")
    missing = [c for c in columns if c not in header]
    if missing:
        fail(f"{path}: no column {', '.join(missing)} (header: {','.join(header) or 'empty'})")
    return rows


def csv_chart(doc, csv_help, columns):
    """The command line of a chart drawn from one CSV (`CSV --out FILE.png`): its arguments and
    the CSV's rows, checked for `columns` and for at least one row. A bad --out name fails before
    anything is read."""
    parser = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", help=csv_help)
    parser.add_argument("--out", required=True, help="FILE.png: writes FILE.png and FILE.svg")
    args = parser.parse_args()
    outputs(args.out)
    rows = read_csv(args.csv, columns)
    if not rows:
        fail(f"{args.csv}: no rows")
    return args, rows


def read_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except OSError as e:
        fail(f"cannot read {path}: {e.strerror}")
    except json.JSONDecodeError as e:
        fail(f"{path}: not JSON ({e})")


def number(text, where):
    try:
        return float(text)
    except (TypeError, ValueError):
        fail(f"{where}: '{text}' is not a number")


def column(rows, key, path):
    """The values of one column of read_csv()'s rows as floats."""
    return [number(r[key], f"{path} line {i + 2}, {key}") for i, r in enumerate(rows)]


def figure(width=11.0, height=7.0):
    """A figure of width x height inches (100 pixels each in the PNG) and its one axes."""
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)  # a renderer for text sizes (label placement) before saving
    return fig, fig.add_subplot()


def plain_number(v, _pos=None):
    """Tick text without powers of ten: 0.01, 1, 10,000."""
    if v == 0:
        return "0"
    if 1e-4 <= abs(v) < 1e7:
        return f"{v:,.6f}".rstrip("0").rstrip(".")
    return f"{v:g}"


def log_axis(axis):
    """A log10 axis with plain tick labels, also at 2x and 5x when it spans under two decades
    (and 3x under one)."""

    def minor_label(v, _pos=None):
        lo, hi = sorted(axis.get_view_interval())
        if lo <= 0 or hi / lo > 100:
            return ""
        labelled = (2, 3, 5) if hi / lo <= 10 else (2, 5)
        leading = v / 10 ** math.floor(math.log10(v))
        return plain_number(v) if round(leading) in labelled else ""

    axis.set_major_formatter(FuncFormatter(plain_number))
    axis.set_minor_locator(LogLocator(base=10, subs=range(2, 10), numticks=100))
    axis.set_minor_formatter(FuncFormatter(minor_label))


def minor_grid(ax):
    ax.grid(True, which="minor", color="#F0F0F0", linewidth=0.6)


def reference_line(ax, y, label, line_color=GREY):
    """A dashed horizontal line across the plot, its label above it at the right end."""
    ax.axhline(y, color=line_color, linestyle="--", linewidth=1.3, zorder=1.5)
    ax.annotate(
        label,
        xy=(1, y),
        xycoords=("axes fraction", "data"),
        xytext=(-6, 3),
        textcoords="offset points",
        ha="right",
        va="bottom",
        color=line_color,
        fontsize=10.5,
    )


def label_points(ax, points):
    """Writes each (x, y, text, colour) next to its point, trying places around it until the
    text overlaps no label placed before, no point and stays inside the plot."""
    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()  # final layout, so that data maps to its final pixels
    plot_box = ax.get_window_extent(renderer)
    taken = []
    for x, y, _, _ in points:
        px, py = ax.transData.transform((x, y))
        taken.append(Bbox.from_extents(px - 5, py - 5, px + 5, py + 5))
    # (dx, dy) in points, horizontal and vertical alignment.
    places = [
        ((7, 3), "left", "bottom"),
        ((7, -3), "left", "top"),
        ((-7, 3), "right", "bottom"),
        ((-7, -3), "right", "top"),
        ((0, 8), "center", "bottom"),
        ((0, -8), "center", "top"),
        ((7, 12), "left", "bottom"),
        ((7, -12), "left", "top"),
    ]
    for x, y, text, text_color in points:
        chosen = None
        for offset, ha, va in places:
            a = ax.annotate(text, (x, y), xytext=offset, textcoords="offset points", ha=ha, va=va,
                            color=text_color, fontsize=10.5)
            box = a.get_window_extent(renderer)
            inside = plot_box.contains(box.x0, box.y0) and plot_box.contains(box.x1, box.y1)
            if inside and not any(box.overlaps(t) for t in taken):
                chosen = a
                break
            a.remove()
        if chosen is None:
            offset, ha, va = places[0]
            chosen = ax.annotate(text, (x, y), xytext=offset, textcoords="offset points", ha=ha, va=va,
                                 color=text_color, fontsize=10.5)
        taken.append(chosen.get_window_extent(renderer))


def outputs(out, option="--out"):
    """The PNG and SVG paths of `--out FILE.png` (or FILE.svg)."""
    stem, ext = os.path.splitext(out)
    if ext.lower() not in (".png", ".svg"):
        fail(f"{option} {out}: the name must end in .png or .svg (both are written)")
    return stem + ".png", stem + ".svg"


def save(fig, out):
    """Writes FILE.png and FILE.svg for `--out FILE.png`, each atomically; returns their paths."""
    paths = outputs(out)
    for path, fmt, metadata in (
        (paths[0], "png", {"Software": None}),
        (paths[1], "svg", {"Date": None, "Creator": None}),
    ):
        directory = os.path.dirname(path) or "."
        tmp = os.path.join(directory, f".{os.path.basename(path)}.tmp-{os.getpid()}")
        try:
            fig.savefig(tmp, format=fmt, metadata=metadata)
            os.replace(tmp, path)
        except OSError as e:
            try:
                os.remove(tmp)
            except OSError:
                pass
            fail(f"cannot write {path}: {e.strerror}")
    return paths


def finite_positive(v):
    return isinstance(v, (int, float)) and math.isfinite(v) and v > 0
