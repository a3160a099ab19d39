"""The firmware footprint from the CSV of `cmake --build build/firmware --target footprint`
(build/firmware/footprint.csv): flash per variant (code and tables) and RAM per body of each
world, against the goals of the footprint table (examples/firmware/README.md).

    python3 tools/plot/footprint.py build/firmware/footprint.csv --out DIR/footprint.png   # and .svg
"""

import style

COLUMNS = ["variant", "bodies", "code_bytes", "tables_bytes", "world3_per_body", "world2_per_body"]

# The goals the footprint table states: code of both worlds at most 32 KB, at most 96 bytes of
# RAM per 3D body and 64 per 2D body.
CODE_GOAL_KB = 32
BODY_GOAL_3D = 96
BODY_GOAL_2D = 64

CODE = style.color(0)
TABLES = style.color(1)
WORLD3 = style.color(2)
WORLD2 = style.color(3)


def main():
    args, rows = style.csv_chart(__doc__, "footprint.csv of the firmware build's footprint target", COLUMNS)
    names = [r["variant"] for r in rows]
    col = {k: style.column(rows, k, args.csv) for k in COLUMNS[1:]}
    code_kb = [b / 1024 for b in col["code_bytes"]]
    tables_kb = [b / 1024 for b in col["tables_bytes"]]
    x = list(range(len(rows)))

    fig = style.Figure(figsize=(12, 5.6), layout="constrained")
    style.FigureCanvasAgg(fig)
    flash, ram = fig.subplots(1, 2)

    flash.set_title("Flash per firmware variant")
    flash.bar(x, code_kb, color=CODE, label="code (both worlds, runtime, start-up)")
    flash.bar(x, tables_kb, bottom=code_kb, color=TABLES, label="tables")
    for i, (c, t) in enumerate(zip(code_kb, tables_kb)):
        # Tenths cut off, not rounded, as the footprint table prints them.
        flash.text(i, c / 2, f"{int(c * 10) / 10:.1f}", ha="center", va="center", fontsize=9, color="white")
        flash.text(i, c + t / 2, f"{int(t * 10) / 10:.1f}", ha="center", va="center", fontsize=9)
    flash.axhline(CODE_GOAL_KB, color=style.GREY, linestyle="--", linewidth=1.3, zorder=3,
                  label=f"goal for the code: {CODE_GOAL_KB} KB")
    flash.set_ylabel("KB")
    flash.set_xticks(x, names, rotation=30, ha="right")
    # Head room above the tallest bar for the legend, so that it covers no value label.
    flash.set_ylim(0, max(c + t for c, t in zip(code_kb, tables_kb)) * 1.55)
    flash.legend(loc="upper left", ncol=1)

    ram.set_title("RAM per body (each world over its bodies)")
    width = 0.38
    left = [i - width / 2 for i in x]
    right = [i + width / 2 for i in x]
    ram.bar(left, col["world3_per_body"], width, color=WORLD3, label="3D world")
    ram.bar(right, col["world2_per_body"], width, color=WORLD2, label="2D world")
    for xs, ys in ((left, col["world3_per_body"]), (right, col["world2_per_body"])):
        for i, y in zip(xs, ys):
            ram.text(i, y + 2, f"{y:.0f}", ha="center", va="bottom", fontsize=9)
    for goal, name, line in ((BODY_GOAL_3D, "3D", WORLD3), (BODY_GOAL_2D, "2D", WORLD2)):
        ram.axhline(goal, color=line, linestyle="--", linewidth=1.3, zorder=3, label=f"goal for a {name} body: {goal} B")
    ram.set_ylabel("bytes per body")
    ram.set_xticks(x, names, rotation=30, ha="right")
    ram.set_ylim(0, max(col["world3_per_body"] + col["world2_per_body"]) * 1.7)
    ram.legend(loc="upper left", ncol=2)
    style.save(fig, args.out)


if __name__ == "__main__":
    main()
