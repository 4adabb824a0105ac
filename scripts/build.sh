#!/usr/bin/env bash
# Configures and builds OSCAR into build/ (executables in build/bin/). Extra arguments go to the
# CMake configure step, e.g. -DOSCAR_SANITIZE=address. BUILD_DIR overrides build/.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build}"
# A compiler cache where the machine has one (keyed on the preprocessed source and the flags, so
# a hit is exact); paths are taken relative to this checkout, so another clone hits it too.
launcher=()
if command -v ccache >/dev/null; then
  export CCACHE_BASEDIR="$PWD"
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" "${launcher[@]}" "$@" >/dev/null
cmake --build "$build_dir" -j "${JOBS:-2}"
