#!/usr/bin/env bash
# Proves find_package(oscar): installs this build into a temporary prefix, builds the module in
# tests/out_of_tree/module against it, runs its unit test and its system test (a system booted by
# the installed oscar-boot, oscar_add_system_test), and loads its plugin with the installed
# oscar-run; then builds and tests the same module against the build tree itself
# (-DCMAKE_PREFIX_PATH=<build folder>, no install).
set -euo pipefail
build_dir="$1"
here="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
cmake -S "$here/module" -B "$work/build" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" -j2 >/dev/null
system_tests() {
  local n
  n="$(ctest --test-dir "$1" -N -L system | sed -n 's/^Total Tests: //p')"
  [ "$n" = 1 ] || { echo "expected one system test in $1, found '$n'"; exit 1; }
}
system_tests "$work/build"
LD_LIBRARY_PATH="$work/prefix/lib" ctest --test-dir "$work/build" --output-on-failure
types="$(OSCAR_PLUGIN_PATH="$work/build/lib/oscar/plugins" \
  LD_LIBRARY_PATH="$work/prefix/lib" "$work/prefix/bin/oscar-run" --list-types)"
echo "installed oscar-run loads: $(echo $types)"
echo "$types" | grep -qx blinker || { echo "the out-of-tree plugin was not loaded"; exit 1; }
check="$("$work/build/bin/oscar-module-blinker" --name b -k blinker:b -m continuous:10ms --check)"
echo "stand-alone runner: $check"
[ "$check" = "b (blinker): continuous" ] || { echo "unexpected --check output"; exit 1; }

cmake -S "$here/module" -B "$work/build-tree" -G Ninja -DCMAKE_PREFIX_PATH="$build_dir" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build-tree" -j2 >/dev/null
system_tests "$work/build-tree"
ctest --test-dir "$work/build-tree" --output-on-failure
echo "built and tested against the build tree: $build_dir"
