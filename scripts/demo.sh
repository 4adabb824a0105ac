#!/usr/bin/env bash
# The README's main command: seed 004's landmark application (config/landmarks-1host.yaml: two
# synthetic cameras, MarkADetect, MarkBDetect and the pose fusion in one multi-core module,
# sequenced by CobraControl, an applet in the coordinator) booted with `oscar boot` on this
# host, its detections and fused poses shown live in the merged log, every cue recorded to an
# MCAP file by `oscar record`. Ctrl-C (or --duration SECONDS) shuts everything down in order and
# prints how to replay the recording into the detectors. Installs what is missing and builds
# first.
set -euo pipefail
cd "$(dirname "$0")/.."
args=()
system=config/landmarks-1host.yaml
recording=landmarks.mcap
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) args+=(--duration "$2"); shift 2 ;;
    --system) system="$2"; shift 2 ;;
    --record) recording="$2"; shift 2 ;;
    *) echo "usage: scripts/demo.sh [--duration SECONDS] [--system FILE] [--record FILE.mcap]" >&2
       exit 2 ;;
  esac
done

bash scripts/setup.sh
bash scripts/build.sh

domain=$(awk '/^domain:/ { print $2 }' "$system")
domain=${domain:-0}
echo "demo: booting $system; recording every cue to $recording (Ctrl-C stops both)"
build/bin/oscar record --all -o "$recording" --domain "$domain" > "$recording.log" 2>&1 &
recorder=$!
finish() {
  kill -TERM "$recorder" 2>/dev/null || true  # background jobs of a script ignore SIGINT
  wait "$recorder" 2>/dev/null || true
  echo
  echo "demo: recording: $(tail -n 2 "$recording.log" | tr '\n' ' ')"
  build/bin/oscar info "$recording" || true
  if [ "$system" = config/landmarks-1host.yaml ]; then
    echo "demo: replay the camera images into the detectors (docs/landmarks.md); the detectors"
    echo "run in the background and are stopped when the replay ends:"
    echo "  build/bin/oscar-run config/landmarks-replay.yaml --module detect & detect=\$!"
    echo "  build/bin/oscar replay $recording --topics 'oscar/cue/cam_*/frame' --domain 45; kill \$detect"
  fi
}
trap finish EXIT
build/bin/oscar boot "$system" "${args[@]+"${args[@]}"}"
