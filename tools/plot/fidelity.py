"""The charts of `statsim fidelity`, from its JSON (`--json`):

  --chart FILE.png          summary error against thread CPU time per step (log x), one point per
                            method with its 90% interval, the Pareto front, the noise floor with
                            its interval, and the goal line (1 = at the goals)
  --chart-bytes FILE.png    summary error against signature table bytes (log x), one point per
                            method with a table, the noise floor and the goal line
  --metric-charts DIR       DIR/KEY.png (and .svg) for each distance against time per step

    python3 tools/plot/fidelity.py fidelity.json --chart fidelity.png
"""

import argparse
import math
import os

import style

METRICS = [  # (file and title name, place in a method's JSON)
    ("rest_tvd", ("rest_tvd",)),
    ("rest_height_err", ("rest_height_err",)),
    ("travel_w1", ("travel_w1",)),
    ("bounce_w1", ("bounce_w1",)),
    ("rest_time_w1", ("rest_time_w1",)),
    ("first_impact_ks", ("first_impact_ks",)),
    ("pile_radial_w1", ("pile", "radial_w1")),
    ("pile_height_w1", ("pile", "height_w1")),
    ("pile_rest_tvd", ("pile", "rest_tvd")),
]


class Data:
    """What the charts need from the JSON, checked on reading."""

    def __init__(self, path):
        j = style.read_json(path)
        self.path = path
        try:
            self.shape = str(j["shape"])
            self.bench_n = int(j["options"]["bench_n"])
            self.floor = j["noise_floor"]
            self.methods = list(j["methods"].items())
            for name, m in self.methods:
                self.distance(m, ("summary_error",))
                for key in ("step_ms", "table_bytes"):
                    if key not in m:
                        raise KeyError(f"methods.{name}.{key}")
            self.distance(self.floor, ("summary_error",))
        except (KeyError, TypeError, ValueError, AttributeError) as e:
            style.fail(f"{path}: not a statsim fidelity JSON (missing or bad {e})")

    def distance(self, where, place):
        """(value, interval low, interval high) of a distance at `place` in `where`."""
        for key in place[:-1]:
            where = where[key]
        value = float(where[place[-1]])
        lo, hi = where[place[-1] + "_ci"]
        return value, float(lo), float(hi)


def floor_and_goal(ax, data, x_range):
    """The summary error's noise floor, its 90% interval across the chart, and the goal line."""
    floor, lo, hi = data.distance(data.floor, ("summary_error",))
    ax.fill_between(x_range, [lo, lo], [hi, hi], color=style.GREY, alpha=0.22, linewidth=0,
                    label="noise floor 90% interval", zorder=1)
    style.reference_line(ax, floor, "noise floor")
    style.reference_line(ax, 1.0, "at the goals", style.GOAL_RED)


def points_chart(data, title, xlabel, ylabel, place, x_of, name_of):
    """Points (x_of(method), distance at `place`) with vertical 90% intervals and labels; the
    figure, its axes, the points drawn and the x range (a factor 2 of room on either side)."""
    fig, ax = style.figure(11, 7)
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_xscale("log")
    style.log_axis(ax.xaxis)
    style.minor_grid(ax)
    drawn = []
    for i, (name, m) in enumerate(data.methods):
        x = x_of(m)
        if not style.finite_positive(x):
            continue
        try:
            value, lo, hi = data.distance(m, place)
        except (KeyError, TypeError, ValueError):
            style.fail(f"{data.path}: method {name} has no {'.'.join(place)}")
        c = style.color(i)  # by the method's place in the run: the same colour on every chart
        ax.plot([x, x], [lo, hi], color=c, linewidth=1.5, zorder=3)
        ax.plot([x], [value], linestyle="none", marker="o", markersize=9, color=c, label=name_of(name), zorder=4,
                clip_on=False)  # whole at y = 0 too
        drawn.append((x, value, name_of(name), c))
    if not drawn:
        return fig, ax, drawn, None
    xs = [d[0] for d in drawn]
    x_range = [min(xs) / 2, max(xs) * 2]
    ax.set_xlim(*x_range)
    ax.set_ylim(bottom=0)
    return fig, ax, drawn, x_range


def finish(fig, ax, drawn, out):
    ax.legend(loc="best")
    style.label_points(ax, drawn)
    return style.save(fig, out)


def step_ms(m):
    return m["step_ms"]


def summary_chart(data, out):
    fig, ax, drawn, x_range = points_chart(
        data, f"statsim fidelity: {data.shape}, accuracy against time per step",
        f"thread CPU time per step (ms), {data.bench_n} bodies", "summary error (1 = at the goals)",
        ("summary_error",), step_ms, lambda name: name)
    if not drawn:
        style.fail(f"--chart: no method has a step time (step_ms) in {data.path} (a --no-timing run?)")
    # Pareto front: in order of time, each point more accurate than every faster one.
    front, best = [], math.inf
    for x, y, _, _ in sorted(drawn):
        if y < best:
            best = y
            front.append((x, y))
    if len(front) > 1:
        ax.plot([p[0] for p in front], [p[1] for p in front], color=style.DARK, linestyle="--", linewidth=1.5,
                label="Pareto front", zorder=2)
    floor_and_goal(ax, data, x_range)
    return finish(fig, ax, drawn, out)


def bytes_chart(data, out):
    # "statistical:NAME" is labelled NAME; the compiled table's methods keep their names.
    def short(name):
        return name[len("statistical:"):] if name.startswith("statistical:") else name

    fig, ax, drawn, x_range = points_chart(
        data, f"statsim fidelity: {data.shape}, summary error against table bytes", "signature table bytes",
        "summary error, 90% interval (1 = at the goals)", ("summary_error",), lambda m: m["table_bytes"], short)
    if not drawn:
        style.fail(f"--chart-bytes: no method has a table (table_bytes) in {data.path}")
    floor_and_goal(ax, data, x_range)
    return finish(fig, ax, drawn, out)


def metric_charts(data, directory):
    try:
        os.makedirs(directory, exist_ok=True)
    except OSError as e:
        style.fail(f"cannot create {directory}: {e.strerror}")
    written = []
    for key, place in METRICS:
        if place[0] == "pile" and "pile" not in data.floor:
            continue
        fig, ax, drawn, _ = points_chart(
            data, f"statsim fidelity: {data.shape}, {key} against time per step", "thread CPU time per step (ms)",
            f"{key} (90% interval)", place, step_ms, lambda name: name)
        if not drawn:
            continue
        style.reference_line(ax, data.distance(data.floor, place)[0], "noise floor")
        written += finish(fig, ax, drawn, os.path.join(directory, key + ".png"))
    return written


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("json", help="JSON of `statsim fidelity --json`")
    parser.add_argument("--chart", help="FILE.png: summary error against time per step (and FILE.svg)")
    parser.add_argument("--chart-bytes", help="FILE.png: summary error against table bytes (and FILE.svg)")
    parser.add_argument("--metric-charts", help="DIR: one chart per distance against time per step")
    args = parser.parse_args()
    if not (args.chart or args.chart_bytes or args.metric_charts):
        style.fail("nothing to draw: give --chart, --chart-bytes or --metric-charts")
    for option, out in (("--chart", args.chart), ("--chart-bytes", args.chart_bytes)):
        if out:
            style.outputs(out, option)  # a bad name fails before anything is drawn
    data = Data(args.json)
    if args.chart:
        summary_chart(data, args.chart)
    if args.chart_bytes:
        bytes_chart(data, args.chart_bytes)
    if args.metric_charts:
        metric_charts(data, args.metric_charts)


if __name__ == "__main__":
    main()
