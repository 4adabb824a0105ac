#!/usr/bin/env bash
# Configures the source tree the way a user who wants only the programs would: without the tests,
# and without the tests and the benchmarks. Each must configure (the package still has
# oscar::testing, which needs GoogleTest, not the tests).
set -euo pipefail
source_dir="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for options in "-DOSCAR_BUILD_TESTS=OFF" "-DOSCAR_BUILD_TESTS=OFF -DOSCAR_BUILD_BENCHMARKS=OFF"; do
  rm -rf "$work/build"
  # shellcheck disable=SC2086
  if ! cmake -S "$source_dir" -B "$work/build" -G Ninja $options > "$work/log" 2>&1; then
    echo "cmake $options failed:"
    cat "$work/log"
    exit 1
  fi
  echo "cmake $options: configured"
done
