#!/usr/bin/env bash
# Installs the Debian 12 packages statsim needs, only those missing.
# Silent when everything is present; uses sudo when not run as root.
#   tools/setup.sh            packages for the runtime, tests, examples and host tools
#   tools/setup.sh --minimal  only what a runtime-only build needs (compiler, CMake, Eigen)
set -euo pipefail

minimal=0
for arg in "$@"; do
  case "$arg" in
    --minimal) minimal=1 ;;
    -h|--help) sed -n '2,5p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option '$arg' (try --help)" >&2; exit 2 ;;
  esac
done

# Runtime build: compiler, CMake and Eigen.
packages=(g++ make cmake libeigen3-dev)
if [ "$minimal" = 0 ]; then
  # Tests (doctest), host tools (reference engines, command line, JSON, images, meshes).
  packages+=(doctest-dev libbox2d-dev libbullet-dev libcli11-dev nlohmann-json3-dev
             libstb-dev libmeshoptimizer-dev libtinyobjloader-dev libassimp-dev)
  # The firmware example and its test: Cortex-M toolchain, C and C++ libraries, and the emulator.
  packages+=(gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib qemu-system-arm)
  # The web example and its tests (examples/web): emscripten for the .wasm, Debian's chromium for
  # the browser test. Node.js and npm are the machine's own (emscripten's dependency on nodejs is
  # met by them); npm installs the test's driver into the build tree.
  packages+=(emscripten chromium)
  # Pictures: glTF export (tinygltf), GIF writing (giflib) and optimising (gifsicle).
  packages+=(libtinygltf-dev libgif-dev gifsicle)
  # Charts: the plotting scripts of tools/plot (matplotlib for Debian's python3).
  packages+=(python3-matplotlib)
  # Fuzzing (tests/fuzz, STATSIM_FUZZ=ON): clang with libFuzzer and the sanitizer runtimes.
  packages+=(clang-14 libclang-rt-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null | grep -qx installed; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -eq 0 ]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "setup.sh: need root or sudo to install: ${missing[*]}" >&2
  exit 1
fi

echo "setup.sh: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup.sh: done" >&2
