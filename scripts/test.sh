#!/usr/bin/env bash
# The README's test command (also what CI runs): installs what is missing, builds everything
# with warnings as errors, and runs every test with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh -DOSCAR_BUILD_TESTS=ON -DOSCAR_WERROR=ON
ctest --test-dir build --output-on-failure --timeout 300
