"""The pile models' chart: pile error against thread CPU time per step, one point per method and
shape, from the JSON of `statsim fidelity --scenes-only --scenes heap,bin,... --json` runs (their
`pile_summary`: the mean of |distance| / goal over the heap's and the bin's figures, and the CPU
time per step of those runs). Methods whose heap or bin runs did not all fall asleep are drawn
hollow. The goal line is at 1.

    python3 tools/plot/pile_models.py box.json lshape.json --out pile_models.png
"""

import argparse

import style

MARKERS = ["o", "s", "^", "D", "v"]


def read(path):
    j = style.read_json(path)
    try:
        shape = str(j["shape"])
        summary = j["pile_summary"]
        scenes = j["scenes"]
        points = []
        for name, s in summary.items():
            runs = [r for k in ("heap", "bin") if k in scenes for r in scenes[k]["methods"][name]["runs"]]
            rested = all(not r["time_limited"] for r in runs)
            points.append((name, float(s["step_ms"]), float(s["pile_error"]), rested))
    except (KeyError, TypeError, ValueError) as e:
        style.fail(f"{path}: not a fidelity run with heap and bin scenes ({e})")
    if not points:
        style.fail(f"{path}: no method in pile_summary")
    return shape, points


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("json", nargs="+", help="JSON of `statsim fidelity --json` with heap and bin scenes")
    parser.add_argument("--out", required=True, help="FILE.png (and FILE.svg)")
    args = parser.parse_args()
    style.outputs(args.out)
    runs = [read(p) for p in args.json]
    names = []
    for _, points in runs:
        for name, *_ in points:
            if name not in names:
                names.append(name)
    fig, ax = style.figure(11.0, 7.0)
    labels = []
    for r, (shape, points) in enumerate(runs):
        marker = MARKERS[r % len(MARKERS)]
        for name, ms, err, rested in points:
            c = style.color(names.index(name))
            hollow = not rested
            ax.scatter([ms], [err], marker=marker, s=70, zorder=3, edgecolors=c,
                       facecolors="none" if hollow else c, linewidths=1.8)
            labels.append((ms, err, f"{name} ({shape})", c))
        ax.scatter([], [], marker=marker, color=style.DARK, label=shape)
    ax.scatter([], [], marker="o", facecolors="none", edgecolors=style.DARK, label="hollow: some run did not come to rest")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.margins(x=0.08, y=0.15)  # room for the labels of the points at the edges
    style.log_axis(ax.xaxis)
    style.log_axis(ax.yaxis)
    style.minor_grid(ax)
    style.reference_line(ax, 1.0, "goals")
    ax.set_xlabel("thread CPU time per step of the heap and bin runs (ms)")
    ax.set_ylabel("pile error (mean |distance| / goal, heap and bin)")
    ax.set_title("statsim pile models: accuracy against time per step")
    ax.legend(loc="upper right", fontsize=10)
    style.label_points(ax, labels)
    for path in style.save(fig, args.out):
        print(path)


if __name__ == "__main__":
    main()
