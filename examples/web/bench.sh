#!/usr/bin/env bash
# The page's step time against the native one, in the same run: N bunnies (default 10,000)
# poured into a heap and stepped S times (default 600, 10 s at 60 Hz), by web_demo_host and by
# statsim.wasm in headless Chromium (index.html?bench), in alternating rounds (default 3), so
# that both see the same load on the machine. Prints each run's line, which ends in the state
# hash (equal: the same bits), and the ratio of the medians of the time per step; with --csv FILE
# also writes those medians and the hash to FILE (examples/web/step_ratio.csv, which the docs'
# test checks the chapter against).
#   examples/web/bench.sh [--build DIR] [--n N] [--steps S] [--rounds R] [--shape bunny|box|lshape|square] [--csv FILE]
set -euo pipefail
build=build n=10000 steps=600 rounds=3 shape=bunny csv=
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --n) n=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --shape) shape=$2; shift 2 ;;
    --csv) csv=$2; shift 2 ;;
    *) sed -n '2,10p' "$0"; exit 2 ;;
  esac
done
here=$(cd "$(dirname "$0")" && pwd)
native=() web=()
for ((r = 1; r <= rounds; ++r)); do
  line=$("$build/bin/web_demo_host" --shape "$shape" --n "$n" --steps "$steps")
  echo "native:   $line"
  native+=("$(sed -E 's/.*ms_per_step ([0-9.]+).*/\1/' <<<"$line")")
  line=$(node "$here/chromium.mjs" --site "$build/web/site" --modules "$build/web-node/node_modules" \
           --bench "shape=$shape&n=$n&steps=$steps")
  echo "chromium: $line"
  web+=("$(sed -E 's/.*ms_per_step ([0-9.]+).*/\1/' <<<"$line")")
  hash=$(sed -E 's/.*hash (0x[0-9a-f]+).*/\1/' <<<"$line")
done
median() { printf '%s\n' "$@" | sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
mn=$(median "${native[@]}") mw=$(median "${web[@]}")
awk -v a="$mn" -v b="$mw" 'BEGIN {printf "median ms per step: native %.3f, chromium %.3f, ratio %.2f\n", a, b, b / a}'
if [ -n "$csv" ]; then
  awk -v s="$shape" -v n="$n" -v k="$steps" -v a="$mn" -v b="$mw" -v h="$hash" 'BEGIN {
    print "shape,bodies,steps,native_ms,chromium_ms,ratio,hash"
    printf "%s,%d,%d,%.3f,%.3f,%.2f,%s\n", s, n, k, a, b, b / a, h }' > "$csv"
fi
