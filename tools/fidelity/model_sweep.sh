#!/usr/bin/env bash
# Response models against table size: gathers SHAPE at two resolutions and writes, from each
# gathering's trials, the JSON of every response model at several sizes and both precisions
# (`statsim gather --model-json`), then runs `statsim fidelity` over all of them against the
# Bullet reference (single drops, no piles) and draws summary error against table bytes and
# against time per step, one point per model and resolution.
#
# Usage: tools/fidelity/model_sweep.sh SHAPE [OUT] [RUNS]
#   SHAPE  box, lshape or bunny (compiled tables), or FILE.obj (a mesh: its first table classifies
#          the rest poses)
#   OUT    output directory (default /tmp/statsim-models-SHAPE)
#   RUNS   single drops per sample (default 500)
# Environment: STATSIM_BUILD (default build), VARIANTS (default "coarse medium").
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${STATSIM_BUILD:-$root/build}
bin=$build/bin/statsim
shape=${1:?usage: model_sweep.sh SHAPE [OUT] [RUNS]}
name=$(basename "$shape" .obj)
out=${2:-/tmp/statsim-models-$name}
runs=${3:-500}
mkdir -p "$out"
cd "$root"

if [[ "$shape" == *.obj ]]; then source_args=(--mesh "$shape"); else source_args=(--shape "$shape"); fi

axes() {
  case "$1" in
    coarse)
      echo "--cos-theta 0.1,0.4,0.7,1 --cos-phi -1,-0.5,0,0.5,1 --spin-ratios 0,0.25,0.5,1,2,3,5,8" \
           "--height-ratios 0,0.5,1,2,4,8,16,64" ;;
    medium) echo "" ;;  # the defaults: 7 x 10 x 16 cells, 16 h_coll samples
    *) echo "model_sweep: unknown variant $1" >&2; exit 2 ;;
  esac
}

tables=()
for variant in ${VARIANTS:-coarse medium}; do
  models=()
  for m in paper correlated empirical:4 empirical:8 empirical:16; do
    for p in f32 i16; do
      id="${variant}_${m//:/}_$p"
      models+=(--model-json "$m:$p=$out/$id.json")
      tables+=(--table "$id=$out/$id.json")
    done
  done
  echo "model_sweep: gathering $name ($variant)" >&2
  # shellcheck disable=SC2046
  "$bin" gather "${source_args[@]}" --name "${name}_$variant" $(axes "$variant") --out "$out/${variant}.hpp" \
    --cell-report "$out/${variant}_cells.md" "${models[@]}" --quiet > "$out/${variant}_gather.txt"
done

methods=full
for t in "${tables[@]}"; do
  [[ "$t" == --table ]] && continue
  methods+=",statistical:${t%%=*}"
done
mesh_args=()
[[ "$shape" == *.obj ]] && mesh_args=(--mesh "$shape") || mesh_args=(--shape "$shape")
"$bin" fidelity "${mesh_args[@]}" --runs "$runs" --no-piles "${tables[@]}" --methods "$methods" \
  --json "$out/fidelity.json" --chart "$out/error_vs_time.png" --chart-bytes "$out/error_vs_bytes.png" \
  > "$out/fidelity.txt"
echo "model_sweep: $out/fidelity.txt, $out/error_vs_bytes.png, $out/error_vs_time.png" >&2
