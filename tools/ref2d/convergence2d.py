#!/usr/bin/env python3
"""Convergence of the 2D piles' reference: Box2D's pile height as its step is halved.

Runs `statsim compare2d` with Box2D in 1, 2, 4, ... substeps per step of 1/60 s (statsim's own
runs are the same at every level) and sets each halving's change of Box2D's mean pile height
beside its noise floor, with the definition of `statsim fidelity --convergence`
(tools/fidelity/convergence.hpp):

    floor = max(1.645 sqrt(s_a^2 / n + s_b^2 / n), resolution)

s the standard deviation of the pile height over the n drops of a level, resolution 0.5% of the
height (a tenth of the 5% the pile goal allows). The reference's setting is the coarsest level
from which no finer level moves the height past its floor.

Usage: tools/ref2d/convergence2d.py [--statsim build/bin/statsim] [--shape square] [--drops 10]
       [--levels 4] [--out DIR]
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import time

Z90 = 1.6448536269514722
RESOLUTION = 0.005


def run_level(statsim, shape, drops, substeps, out_dir):
    path = os.path.join(out_dir, f"{shape}_substeps{substeps}.csv")
    cmd = [statsim, "compare2d", "--shape", shape, "--drops", str(drops), "--repeat", "1",
           "--box2d-substeps", str(substeps), "--csv", path]
    t0 = time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    seconds = time.monotonic() - t0
    with open(path, newline="") as f:
        rows = {r["method"]: r for r in csv.DictReader(f)}
    box2d = rows["box2d"]
    return {
        "substeps": substeps,
        "height": float(box2d["pile_height"]),
        "sd": float(box2d["pile_height_sd"]),
        "asleep": int(box2d["asleep"]),
        "bodies": int(box2d["n"]) * drops,
        "seconds": seconds,
    }


def change(a, b, drops):
    d = b["height"] - a["height"]
    floor = max(Z90 * math.sqrt(a["sd"] ** 2 / drops + b["sd"] ** 2 / drops), RESOLUTION * abs(a["height"]))
    return d, floor


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--statsim", default="build/bin/statsim")
    p.add_argument("--shape", default="square", choices=["square", "lshape"])
    p.add_argument("--drops", type=int, default=10)
    p.add_argument("--levels", type=int, default=4, help="substeps 1, 2, 4, ... (this many levels)")
    p.add_argument("--out", default="", help="directory of the CSVs (default: a temporary one)")
    a = p.parse_args()
    if a.drops < 2 or a.levels < 2:
        sys.exit("convergence2d: --drops and --levels must be at least 2")
    out_dir = a.out or tempfile.mkdtemp(prefix="convergence2d_")
    os.makedirs(out_dir, exist_ok=True)
    levels = []
    for k in range(a.levels):
        print(f"convergence2d: {a.shape}, Box2D in {2 ** k} substeps ({k + 1} of {a.levels})", file=sys.stderr)
        levels.append(run_level(a.statsim, a.shape, a.drops, 2 ** k, out_dir))
    print(f"Box2D's pile height of {a.drops} drops of 100 {a.shape}s (compare2d, 900 steps of 1/60 s), the step "
          "halved from level to level; mean +- standard deviation over the drops, then the change to the next level "
          "and to the finest with, in brackets, the noise floor.\n")
    print("| Box2D step | pile height (m) | change to the next (floor) | change to the finest (floor) | asleep | wall s |")
    print("|---|---|---|---|---|---|")
    for k, l in enumerate(levels):
        row = f"| 1/{60 * l['substeps']} s | {l['height']:.3f} +- {l['sd']:.3f} |"
        if k + 1 < len(levels):
            d, f = change(l, levels[k + 1], a.drops)
            row += f" {d:+.3f} ({f:.3f}) {'yes' if abs(d) <= f else 'no'} |"
            d, f = change(l, levels[-1], a.drops)
            row += f" {d:+.3f} ({f:.3f}) {'yes' if abs(d) <= f else 'no'} |"
        else:
            row += " | |"
        row += f" {l['asleep']} of {l['bodies']} | {l['seconds']:.0f} |"
        print(row)
    converged = -1
    for k in range(len(levels) - 2, -1, -1):
        if all(abs(d) <= f for d, f in (change(levels[k], levels[j], a.drops) for j in range(k + 1, len(levels)))):
            converged = k
        else:
            break
    if converged >= 0:
        print(f"\n{a.shape}: converged at 1/{60 * levels[converged]['substeps']} s "
              "(no finer level moves the height past its floor)")
    else:
        print(f"\n{a.shape}: not converged within these levels")


if __name__ == "__main__":
    main()
