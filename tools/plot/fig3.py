"""The paper's Figure 3 from `statsim fig3`'s CSV: the height of a 1x1 square's centre at its
first contact with a line against |w|/|v|, as the min..max range, the mean and mean +/- std.

    python3 tools/plot/fig3.py DIR/fig3.csv --out DIR/fig3.png   # writes fig3.png and fig3.svg
"""

import math

import style

# Every contact height lies between these two: a face lands first (the inradius) or a corner
# does (the circumradius).
INRADIUS = 0.5
CIRCUMRADIUS = math.sqrt(2) / 2

RANGE = style.color(0)
MEAN = style.color(1)


def main():
    args, rows = style.csv_chart(__doc__, "fig3.csv of `statsim fig3` (ratio,min,mean,std,max,trials)",
                                 ["ratio", "min", "mean", "std", "max", "trials"])
    col = {k: style.column(rows, k, args.csv) for k in ("ratio", "min", "mean", "std", "max", "trials")}
    trials = [int(t) for t in col["trials"]]
    x = col["ratio"]
    per_ratio = str(min(trials)) if min(trials) == max(trials) else f"{min(trials)}-{max(trials)}"

    fig, ax = style.figure(11, 6.8)
    ax.set_title("Collision height of a 1x1 square falling on a line (Box2D)")
    ax.set_xlabel("|ω| / |v|   (rad/m)")
    ax.set_ylabel("height of centre at first contact (m)")
    ax.set_ylim(0.47, 0.735)

    ax.fill_between(x, col["min"], col["max"], color=RANGE, alpha=0.18, linewidth=0,
                    label=f"min .. max of {per_ratio} drops")
    for y in (col["max"], col["min"]):
        ax.plot(x, y, color=RANGE, linewidth=1.5, marker="o", markersize=3.5)
    upper = [m + s for m, s in zip(col["mean"], col["std"])]
    lower = [m - s for m, s in zip(col["mean"], col["std"])]
    ax.plot(x, upper, color=MEAN, linewidth=1.5, linestyle="--", label="mean ± std")
    ax.plot(x, lower, color=MEAN, linewidth=1.5, linestyle="--")
    ax.plot(x, col["mean"], color=MEAN, linewidth=2.5, marker="o", markersize=5.5, label="mean")

    style.reference_line(ax, INRADIUS, "0.5: face hits first (inradius)")
    style.reference_line(ax, CIRCUMRADIUS, "√2/2 = 0.7071: corner hits first")
    ax.legend(loc="center right")
    style.save(fig, args.out)


if __name__ == "__main__":
    main()
