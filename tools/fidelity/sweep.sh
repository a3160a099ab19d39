#!/usr/bin/env bash
# Table resolution sweep: how much of the bunny's signature does a scene need?
#
# Gathers bunny tables of several resolutions and precisions (JSON and header) into OUT, then
# runs `statsim fidelity` over all of them to chart the summary error against the signature's
# bytes. Run from the repository root:
#
#   tools/fidelity/sweep.sh [OUT]            # OUT defaults to build/fidelity-sweep
#
# Environment: STATSIM (default build/bin/statsim), THREADS (default 2), RUNS (single drops per
# sample of `statsim fidelity`, default 500), PILES=1 to include fidelity's piles (slow), SHAPE
# (default bunny), VARIANTS (space-separated subset of the names below; default all), FIDELITY=0
# to skip the fidelity step, NICE (default "nice -n 10").
#
# The fidelity step compares every swept table (method statistical:NAME) and the committed table
# (method statistical) with Bullet on the same single drops; the Bullet reference is run once for
# all of them. Step times are not measured (--no-timing): the chart's x axis here is bytes, which
# OUT/sweep.csv lists per table.
#
# Variants (scaled layout unless noted; the medium axes are the committed default tables'):
#   coarse  cos theta 4 x cos phi 5 x spin ratio 8 cells, h_coll 8 spin ratios
#   medium  7 x 10 x 16 (the defaults), h_coll 16
#   fine    10 x 13 x 24, h_coll 24
#   paper   the paper's 4D layout: the medium axes x 3 speeds (0.5, 2, 8 m/s)
# each as f32 and i16 (NAME_f32, NAME_i16). To keep the sweep affordable on 2 cores the trial
# counts are reduced for every variant alike: 10 impacts per response cell (default 30), 200
# flights per h_coll sample (default 1000), 200 rest drops (default 1000). The table sizes do not
# depend on them; the errors carry more sampling noise than a default gathering's.
#
# f32 and i16 of one variant are gathered with the same seed, so their statistics must be the same
# numbers: the script checks that (the JSON "mean" arrays are compared) as a determinism check.
# Gathers whose JSON already exists are skipped, so an interrupted sweep resumes. Per table it
# writes OUT/sweep.csv: name,layout,precision,cells,height_samples,bytes,gather_seconds.
# After the fidelity step, OUT/error_vs_bytes.md lists summary error against bytes (smallest first)
# and names the smallest table within 10% of the best summary error, and OUT/error_vs_bytes.png
# charts it (log bytes, 90% intervals, the noise floor); `statsim fidelity --replot
# OUT/fidelity.json --chart-bytes FILE.png` redraws it. The single drops' reference is fidelity's
# default, --reference gather: Bullet with the settings the tables were gathered with.
# "bytes" are the signature's numbers (axes, h_coll, response mean and std at 4 or 2 bytes a value
# with the i16 scales and offsets, rest poses, the scalar fields), as signature_bytes() in
# tools/ref3d/signature_json.hpp counts them.
set -euo pipefail

OUT=${1:-build/fidelity-sweep}
STATSIM=${STATSIM:-build/bin/statsim}
THREADS=${THREADS:-2}
RUNS=${RUNS:-500}
PILES=${PILES:-0}
SHAPE=${SHAPE:-bunny}
VARIANTS=${VARIANTS:-"coarse medium fine paper"}
FIDELITY=${FIDELITY:-1}
NICE=${NICE:-nice -n 10}
REDUCED=(--trials 10 --height-trials 200 --rest-drops 200)

mkdir -p "$OUT"

axes_for() {
  case "$1" in
    coarse)
      echo "--cos-theta 0.1,0.4,0.7,1 --cos-phi -1,-0.5,0,0.5,1 --spin-ratios 0,0.25,0.5,1,2,3,5,8" \
           "--height-ratios 0,0.5,1,2,4,8,16,64" ;;
    medium)
      echo "" ;;
    fine)
      echo "--cos-theta 0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,1" \
           "--cos-phi -1,-0.8333333333333334,-0.6666666666666666,-0.5,-0.3333333333333333,-0.16666666666666666,0,0.16666666666666666,0.3333333333333333,0.5,0.6666666666666666,0.8333333333333334,1" \
           "--spin-ratios 0,0.05,0.1,0.15,0.2,0.25,0.3,0.4,0.5,0.65,0.8,0.9,1,1.125,1.25,1.5,1.75,2,2.5,3,4,5,6,8" \
           "--height-ratios 0,0.125,0.25,0.375,0.5,0.75,1,1.25,1.5,2,2.5,3,4,5,6,8,10,12,16,24,32,40,48,64" ;;
    paper)
      echo "--layout paper --speeds 0.5,2,8" ;;
    *)
      echo "sweep.sh: unknown variant '$1'" >&2; return 1 ;;
  esac
}

# The "mean" array of a gather JSON, one number a line (for the f32 / i16 determinism check).
means() {
  python3 -c 'import json,sys; print("\n".join(repr(x) for x in json.load(open(sys.argv[1]))["response"]["mean"]))' "$1"
}

CSV="$OUT/sweep.csv"
[[ -f "$CSV" ]] || echo "name,layout,precision,cells,height_samples,bytes,gather_seconds" > "$CSV"
TABLE_ARGS=()
METHODS=statistical
for v in $VARIANTS; do
  read -r -a axes <<< "$(axes_for "$v")"
  for p in f32 i16; do
    name="${SHAPE}_${v}_${p}"
    json="$OUT/$name.json"
    TABLE_ARGS+=(--table "$name=$json")
    METHODS+=",statistical:$name"
    if [[ -f "$json" ]]; then
      echo "sweep.sh: $name: $json exists, skipped" >&2
      continue
    fi
    echo "sweep.sh: gathering $name" >&2
    start=$(date +%s.%N)
    $NICE "$STATSIM" gather --shape "$SHAPE" --name "$name" --precision "$p" "${REDUCED[@]}" "${axes[@]}" \
      --threads "$THREADS" --json "$json.tmp" --out "$OUT/$name.hpp" > "$OUT/$name.log"
    end=$(date +%s.%N)
    mv "$json.tmp" "$json"
    python3 - "$json" "$name" "$p" "$(echo "$end - $start" | bc)" >> "$CSV" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
r = j["response"]
cells = 1
for a in r["axes"]:
    cells *= len(a["values"])
nh = len(j["h_coll"]["ratio"])
# The scaled layout stores an unused fourth axis of one sample.
axis_values = sum(len(a["values"]) for a in r["axes"]) + (4 - len(r["axes"]))
i16 = sys.argv[3] == "i16"
# L, bounding radius, mass, 3 unit inertia, 3 material, threshold: 10 floats, and layout and axis
# count as two 4-byte words; rest poses: 5 floats each.
floats = 10 + 3 * nh + axis_values + 5 * len(j["rest"])
resp = 2 * cells * 6 * (2 if i16 else 4) + (16 if i16 else 0)
print(f'{sys.argv[2]},{r["layout"]},{sys.argv[3]},{cells},{nh},{4 * floats + 8 + resp},{float(sys.argv[4]):.1f}')
EOF
  done
  if [[ -f "$OUT/${SHAPE}_${v}_f32.json" && -f "$OUT/${SHAPE}_${v}_i16.json" ]]; then
    if ! cmp -s <(means "$OUT/${SHAPE}_${v}_f32.json") <(means "$OUT/${SHAPE}_${v}_i16.json"); then
      echo "sweep.sh: $v: the f32 and i16 gatherings differ (same seed): not deterministic" >&2
      exit 1
    fi
  fi
done
echo "sweep.sh: tables and sizes in $CSV" >&2
column -s, -t < "$CSV" >&2 || cat "$CSV" >&2

if [[ "$FIDELITY" == 0 ]]; then
  echo "sweep.sh: FIDELITY=0: fidelity step skipped" >&2
  exit 0
fi
if ! "$STATSIM" --help 2>/dev/null | grep -Eq '^ +fidelity( |$)'; then
  echo "sweep.sh: $STATSIM has no 'fidelity' command yet: fidelity step skipped" >&2
  exit 0
fi
echo "sweep.sh: statsim fidelity over $(( ${#TABLE_ARGS[@]} / 2 )) tables" >&2
PILE_ARGS=(--no-piles)
[[ "$PILES" == 1 ]] && PILE_ARGS=()
$NICE "$STATSIM" fidelity --shape "$SHAPE" "${TABLE_ARGS[@]}" --methods "$METHODS" --runs "$RUNS" \
  "${PILE_ARGS[@]}" --no-timing --threads "$THREADS" --json "$OUT/fidelity.json" \
  --chart-bytes "$OUT/error_vs_bytes.png" | tee "$OUT/fidelity.txt"
# Summary error against bytes, smallest first, and the smallest table within 10% of the best.
python3 - "$OUT/fidelity.json" "$CSV" > "$OUT/error_vs_bytes.md" <<'EOF'
import csv, json, sys
methods = json.load(open(sys.argv[1]))["methods"]
seconds = {r["name"]: r["gather_seconds"] for r in csv.DictReader(open(sys.argv[2]))}
rows = []
for name, m in methods.items():
    if m.get("table_bytes") is None or m.get("summary_error") is None:
        continue
    table = name.split(":", 1)[1] if ":" in name else "(committed table)"
    rows.append((m["table_bytes"], m["summary_error"], m["summary_error_ci"], table, seconds.get(table, "-")))
rows.sort(key=lambda r: (r[0], r[1]))
best = min(r[1] for r in rows)
print("| table | bytes | gather (s) | summary error [90% interval] | / best |")
print("|---|---|---|---|---|")
for b, e, ci, t, sec in rows:
    print(f"| {t} | {b} | {sec} | {e:.3f} [{ci[0]:.3f}, {ci[1]:.3f}] | {e / best:.3f} |")
ok = [r for r in rows if r[1] <= 1.1 * best]
print(f"\nbest {best:.3f}; smallest within 10% of it: {ok[0][3]} ({ok[0][0]} bytes, {ok[0][1]:.3f})")
EOF
cat "$OUT/error_vs_bytes.md"
echo "sweep.sh: wrote $OUT/fidelity.json, $OUT/fidelity.txt, $OUT/error_vs_bytes.md and $OUT/error_vs_bytes.png" >&2
