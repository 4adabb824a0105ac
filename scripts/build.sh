#!/usr/bin/env bash
# Configures and builds OSCAR into build/ (executables in build/bin/). Extra arguments go to the
# CMake configure step, e.g. -DOSCAR_SANITIZE=address. BUILD_DIR overrides build/.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build}"
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" "$@" >/dev/null
cmake --build "$build_dir" -j "${JOBS:-2}"
