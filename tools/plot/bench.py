"""Time per step against the number of bodies, log-log, from `statsim bench --csv`'s CSV: one
line per method and broad phase (Bullet's sweep-and-prune solid, its DBVT dashed; statsim thick).

    python3 tools/plot/bench.py bench.csv --out bench.png [--shape bunny] [--cpu]
"""

import argparse
import math

import style

MARKERS = ["o", "s", "D", "^"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", help="CSV of `statsim bench --csv`")
    parser.add_argument("--out", required=True, help="FILE.png: writes FILE.png and FILE.svg")
    parser.add_argument("--shape", help="the dropped shape, for the title (the CSV does not hold it; "
                                        "default: bunny, or square for a 2D run)")
    parser.add_argument("--cpu", action="store_true",
                        help="chart the thread CPU time (cpu_ms) instead of the wall-clock median (step_ms_median)")
    args = parser.parse_args()
    style.outputs(args.out)  # a bad name fails before anything is read

    value_column = "cpu_ms" if args.cpu else "step_ms_median"
    rows = style.read_csv(args.csv, ["method", "n", "broadphase", "engine", "skipped", value_column])
    if not rows:
        style.fail(f"{args.csv}: no rows")
    two_d = any(r["engine"] == "box2d" for r in rows)
    shape = args.shape or ("square" if two_d else "bunny")

    # Series in the order of their first row; one colour per method, in the order methods appear.
    methods, series = [], {}
    for i, r in enumerate(rows):
        if r["method"] not in methods:
            methods.append(r["method"])
        cells = series.setdefault((r["method"], r["broadphase"]), {"engine": r["engine"], "n": [], "ms": []})
        if r["skipped"] == "1" or r[value_column] == "":
            continue
        ms = style.number(r[value_column], f"{args.csv} line {i + 2}, {value_column}")
        if ms > 0:
            cells["n"].append(style.number(r["n"], f"{args.csv} line {i + 2}, n"))
            cells["ms"].append(ms)

    fig, ax = style.figure(10, 6.8)
    ax.set_title(f"Time per step vs bodies: {shape} drop ({'Box2D' if two_d else 'Bullet'} vs statsim)")
    ax.set_xlabel("bodies N")
    ax.set_ylabel(("thread CPU ms" if args.cpu else "ms") + " per step (median of repeats)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    style.log_axis(ax.xaxis)
    style.log_axis(ax.yaxis)
    style.minor_grid(ax)

    drawn = 0
    top = 0.0
    for (method, broadphase), s in series.items():
        if not s["n"]:
            continue
        statsim = s["engine"] == "statsim"
        if s["engine"] == "bullet":
            name = f"{method} ({broadphase})"
        else:
            name = f"{method} (statsim)" if statsim else method
        ax.plot(s["n"], s["ms"], label=name, color=style.color(methods.index(method)),
                linestyle="--" if broadphase == "dbvt" else "-", linewidth=3.0 if statsim else 2.0,
                marker=MARKERS[drawn % len(MARKERS)], markersize=6)
        drawn += 1
        top = max(top, max(s["ms"]))
    if drawn == 0:
        style.fail(f"{args.csv}: no cell has a time in {value_column} (all skipped?)")
    # A free decade above the data for the legend, top left: the slow methods start high at small N
    # and climb to the right, the fast ones run along the bottom.
    ax.set_ylim(top=10 ** (math.ceil(math.log10(top)) + 1))
    ax.legend(loc="upper left")
    style.save(fig, args.out)


if __name__ == "__main__":
    main()
