#!/usr/bin/env bash
# Generates a module in tree — into modules/ of a copy of this repository (the source tree is not
# touched) — and builds it with the project: only the targets the module needs, then its unit
# test and its system test (the module booted with a bench_source per input), which must pass.
# Uses ccache when the project build does: the copy's build folder sits where the project's does
# (src/build) and CCACHE_BASEDIR makes paths relative, so the project's objects are cache hits.
set -euo pipefail
source_dir="$1"
build_dir="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "FAILED: $*"; exit 1; }

mkdir "$work/src"
(cd "$source_dir" && git ls-files -z 2>/dev/null || find . -type f -not -path './build*' -print0) |
  (cd "$source_dir" && xargs -0 cp --parents -t "$work/src")
cd "$work/src"
"$build_dir/bin/oscar-new-module" fuse_pair --input flag:Bool --input image:GvImage \
  --output out:Bool --output summary:FuseSummary --type FuseSummary \
  --param gain:double=1.5 --param period:duration=20ms
grep -q '^add_subdirectory(fuse_pair)$' modules/CMakeLists.txt || fail "not added to modules/"
launcher="$(grep -E '^CMAKE_CXX_COMPILER_LAUNCHER:' "$build_dir/CMakeCache.txt" | cut -d= -f2 || true)"
export CCACHE_BASEDIR="$work/src"
cmake -S . -B "$work/src/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  ${launcher:+-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher} >/dev/null
cmake --build "$work/src/build" -j2 --target oscar_kernel_fuse_pair oscar_kernel_fuse_pair_test \
  oscar_kernel_fuse_pair_system_test \
  >"$work/build.log" 2>&1 || { tail -30 "$work/build.log"; fail "the in-tree build failed"; }
"$work/src/build/bin/oscar_kernel_fuse_pair_test"
ctest --test-dir "$work/src/build" -R '^FusePairSystem\.' --output-on-failure ||
  fail "the generated system test failed"
[ -f "$work/src/build/lib/oscar/plugins/liboscar_kernel_fuse_pair.so" ] || fail "no plugin"
echo "generated module: built in tree with the project, unit and system tests passed"
