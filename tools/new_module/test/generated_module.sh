#!/usr/bin/env bash
# The walkthrough of docs/tutorial.md, step by step: generates a module with two inputs, two
# outputs (one of a type of its own) and two params with the installed oscar-new-module; builds
# it out of tree against an install of this build (find_package(oscar)); runs its unit and system
# tests; boots a system that names its plugin folder under plugins: and feeds it; inspects it
# (oscar ps, oscar echo); records every cue; then boots the module alone and replays the recorded
# inputs into it.
set -euo pipefail
build_dir="$1"
work="$(mktemp -d)"
boot=""
recorder=""
stop_boot() {
  if [ -n "$boot" ] && kill -0 "$boot" 2>/dev/null; then kill -INT "$boot"; wait "$boot" || true; fi
  boot=""
}
cleanup() {
  # A failure between starting the recorder and stopping it must not leave it running.
  if [ -n "$recorder" ] && kill -0 "$recorder" 2>/dev/null; then
    kill -INT "$recorder"
    wait "$recorder" || true
  fi
  stop_boot
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAILED: $*"; exit 1; }

cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
export LD_LIBRARY_PATH="$work/prefix/lib"
bin="$work/prefix/bin"
cd "$work"

# Bad names are clear errors, and nothing is written.
if "$bin/oscar-new-module" relay --out-of-tree --output out:Bool 2>err.txt; then fail "relay accepted"; fi
grep -q "module name 'relay' is taken" err.txt || fail "$(cat err.txt)"
if "$bin/oscar-new-module" fuse_pair --out-of-tree --input x:Image --output out:Bool 2>err.txt; then
  fail "unknown type accepted"
fi
grep -q "input 'x': unknown cue type 'Image'" err.txt || fail "$(cat err.txt)"
[ ! -e fuse_pair ] || fail "a refused module left a folder"

"$bin/oscar-new-module" fuse_pair --out-of-tree --input flag:Bool --input image:GvImage \
  --output out:Bool --output summary:FuseSummary --type FuseSummary \
  --param gain:double=1.5 --param period:duration=20ms
cmake -S fuse_pair -B build -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j2 >/dev/null
# Its unit test and its system test (the module booted with a bench_source per input).
tests="$(ctest --test-dir build --output-on-failure)" || fail "ctest: $tests"
echo "$tests"
grep -Eq 'FusePairSystem\.RunsInABootedSystemAndPublishes \.+ +Passed' <<<"$tests" ||
  fail "the generated system test did not run"

domain=$(( $$ % 200 + 1 ))
cat > system.yaml <<YAML
system: generated
lease: 1s
plugins: [build/lib/oscar/plugins]   # the module's plugin, relative to this file
modules:
  - name: sig_source
    kernels: [ { type: bench_source, name: sig, params: { type: Bool } } ]
    mode: { continuous: 50ms }
  - name: cam_source
    kernels: [ { type: bench_source, name: cam, params: { type: GvImage, dx: 16, dy: 8 } } ]
    mode: { continuous: 100ms }
  - name: fuser
    kernels: [ { type: fuse_pair, name: fuse, params: { gain: 2.5 }, inputs: { flag: sig/out, image: cam/out } } ]
    mode: { continuous: 50ms }
YAML
unset OSCAR_PLUGIN_PATH  # the system file says where the plugin is
"$bin/oscar-boot" system.yaml --domain "$domain" --log-dir "$work/logs" --timeout 30 \
  >boot.log 2>&1 &
boot=$!
"$bin/oscar-record" --all -o rec.mcap --domain "$domain" >record.log 2>&1 &
recorder=$!
out="$(timeout 60 "$bin/oscar-echo" fuse/out -n 3 -d "$domain" --timeout 40 2>echo.err)" ||
  fail "oscar echo (exit $?): $out $(cat echo.err); boot: $(cat boot.log)"
echo "$out"
grep -q '^--- oscar/cue/fuse/out (oscar::Bool)' <<<"$out" || fail "no sample of fuse/out"
grep -q '  source: "fuse/out"' <<<"$out" || fail "no header source"
grep -Eq '  stamps: \[[0-9]+, [0-9]+(, [0-9]+)?\]' <<<"$out" || fail "no fused stamps"
grep -Eq '^value: (true|false)$' <<<"$out" || fail "no value"
# The module's own type, which no OSCAR program was built with: decoded from the IDL it announces.
own="$(timeout 60 "$bin/oscar-echo" fuse/summary -n 1 -d "$domain" --timeout 40 2>echo.err)" ||
  fail "oscar echo fuse/summary (exit $?): $own $(cat echo.err)"
echo "$own"
grep -q '^--- oscar/cue/fuse/summary (fuse_pair::FuseSummary)' <<<"$own" || fail "no summary"
grep -Eq '^value: [0-9]+' <<<"$own" || fail "the summary's value was not decoded"
# The registry counts a module running once its state arrives; its cues may come first (the state
# writer is made after the cue writers, and discovery matches it later), so ps is asked again.
for attempt in 1 2 3 4 5 6 7 8 9 10; do
  ps_out="$("$bin/oscar-ps" -d "$domain")" || fail "oscar ps: $ps_out"
  grep -Eq '^fuser +localhost +[0-9]+ +1 +running' <<<"$ps_out" && break
  sleep 1
done
echo "$ps_out"
grep -Eq '^fuser +localhost +[0-9]+ +1 +running' <<<"$ps_out" ||
  fail "fuser not running in oscar ps after 10 tries a second apart"
sleep 1
kill -INT "$recorder"
wait "$recorder" || fail "oscar record exited with $?: $(cat record.log)"
recorder=""
kill -INT "$boot"
wait "$boot" || fail "boot exited with $?: $(cat boot.log)"
boot=""
info="$("$bin/oscar-info" rec.mcap)" || fail "oscar info: $info"
echo "$info"
for topic in sig/out cam/out fuse/out fuse/summary; do
  grep -q "oscar/cue/$topic" <<<"$info" || fail "the recording has no oscar/cue/$topic"
done
grep -Eq 'oscar/cue/fuse/summary +fuse_pair::FuseSummary .*omgidl' <<<"$info" ||
  fail "the summary was recorded without the IDL its module announced"

# The module alone, fed by the recording: a module file (its inputs wired to kernels that are
# not there; the replay publishes their topics) run by oscar-run.
cat > fuser.yaml <<YAML
name: fuser
plugins: [build/lib/oscar/plugins]
kernels: [ { type: fuse_pair, name: fuse, inputs: { flag: sig/out, image: cam/out } } ]
mode: { continuous: 50ms }
YAML
"$bin/oscar-run" fuser.yaml --domain "$domain" >fuser.log 2>&1 &
boot=$!
timeout 60 "$bin/oscar-echo" fuse/out -n 1 -d "$domain" --timeout 30 >replayed.txt 2>&1 &
echo_pid=$!
sleep 1
"$bin/oscar-replay" rec.mcap --topics 'oscar/cue/sig/out' --topics 'oscar/cue/cam/out' \
  --domain "$domain" >replay.log 2>&1 || fail "oscar replay: $(cat replay.log)"
wait "$echo_pid" || fail "no fuse/out from the replayed inputs: $(cat replayed.txt); $(cat fuser.log)"
grep -q '^--- oscar/cue/fuse/out (oscar::Bool)' replayed.txt || fail "$(cat replayed.txt)"
kill -TERM "$boot"
wait "$boot" || fail "oscar-run exited with $?: $(cat fuser.log)"
boot=""
echo "generated module: built out of tree, unit-tested, booted with plugins:, inspected, recorded, replayed"
