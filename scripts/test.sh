#!/usr/bin/env bash
# The README's test command (also what CI runs): installs what is missing, builds everything
# with warnings as errors (Release) and runs the tests that need the whole build (packaging,
# tools, benchmarks' output); then builds with AddressSanitizer + UBSan and with
# ThreadSanitizer and runs every unit, integration, applet and swarm test under each. Each of
# those runs under both sanitizers, so the Release pass does not run them a third time: that
# kept CI over an hour on a 2-core machine. ALL=1 also runs them in the Release build.
# SANITIZERS="address thread" (default) chooses the sanitizer passes; SANITIZERS= skips them
# (and then the Release pass runs every test).
# Sanitizer builds warn without -Werror: GCC 12 with -fsanitize=thread reports false
# maybe-uninitialized warnings inside Boost.Geometry; the Release build keeps -Werror.
# The AddressSanitizer pass runs TEST_JOBS tests at once (default 2): each test holds a DDS
# domain of its own, and an ASan test mostly waits (about half a core), so two at once took 839 s
# where one at a time took 1300-2000 s. ThreadSanitizer keeps a core busy per test: two at once
# gained a fifth and overran the timing bounds of tests that measure a restart or a cycle, so
# that pass and the Release pass (network namespaces, benchmark output) stay serial.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
bash scripts/setup.sh

sanitized="unit|integration|applets|swarm"
echo "== release build and the tests no sanitizer pass runs"
bash scripts/build.sh -DOSCAR_BUILD_TESTS=ON -DOSCAR_WERROR=ON
if [ -n "${SANITIZERS-address thread}" ] && [ -z "${ALL:-}" ]; then
  ctest --test-dir build --output-on-failure --timeout 300 -LE "$sanitized"
else
  ctest --test-dir build --output-on-failure --timeout 300
fi

# Fast DDS 2.9 itself (not OSCAR) frees a StatisticsWriterImpl through a base pointer of another
# size and keeps singletons until exit; both are excluded here, nothing of ours is.
export ASAN_OPTIONS="new_delete_type_mismatch=0:detect_leaks=1"
export LSAN_OPTIONS="suppressions=$root/tests/sanitizers/lsan.supp"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export TSAN_OPTIONS="suppressions=$root/tests/sanitizers/tsan.supp:halt_on_error=1:second_deadlock_stack=1"
for sanitizer in ${SANITIZERS-address thread}; do
  echo "== $sanitizer sanitizer: unit and integration tests"
  BUILD_DIR="build-$sanitizer" BUILD_TYPE=RelWithDebInfo bash scripts/build.sh \
    -DOSCAR_SANITIZE="$sanitizer" -DOSCAR_BUILD_TESTS=ON -DOSCAR_BUILD_BENCHMARKS=OFF -DOSCAR_WERROR=OFF
  # Tests of code that starts no thread (label threadless) give ThreadSanitizer nothing to find.
  skip=""
  [ "$sanitizer" = thread ] && skip="threadless"
  jobs=1
  [ "$sanitizer" = address ] && jobs="${TEST_JOBS:-2}"
  ctest --test-dir "build-$sanitizer" --output-on-failure --timeout 300 -j "$jobs" \
    -L "$sanitized" ${skip:+-LE "$skip"}
done
