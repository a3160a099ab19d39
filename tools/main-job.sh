#!/usr/bin/env bash
# The main job: runs the demo programs on the committed tables, from a built tree (the
# paper's scenes: Figures 1, 5, 6 and 7, and the 2D drop; spawning, kicking and removing bodies).
#   tools/main-job.sh [BUILD_DIR]   (default: build)
set -euo pipefail
bin="${1:-build}/bin"
out="${1:-build}"
run() {
  local demo="$1"; shift
  if [ ! -x "$bin/$demo" ]; then
    echo "main-job.sh: $bin/$demo not found: build first (see README.md)" >&2
    exit 1
  fi
  echo "== $demo $*"
  "$bin/$demo" "$@"
}
run sphere_pile
run drop2d --png "$out/drop2d.png"
run drop_boxes
run drop_lshapes
run rest_conditions
run spawn_and_kick
run bunnies 10000
