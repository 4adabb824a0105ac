#!/usr/bin/env bash
# The README's main command: boots the demo system (config/demo-local.yaml) on this host.
# Installs what is missing, builds, starts every module, follows their merged log until Ctrl-C
# (or for --duration SECONDS), then shuts the modules down in order and leaves nothing behind.
set -euo pipefail
cd "$(dirname "$0")/.."
duration=0
system=config/demo-local.yaml
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) duration="$2"; shift 2 ;;
    --system) system="$2"; shift 2 ;;
    *) echo "usage: scripts/demo.sh [--duration SECONDS] [--system FILE]" >&2; exit 2 ;;
  esac
done

bash scripts/setup.sh
bash scripts/build.sh

pids=()
stop() {
  trap - INT TERM EXIT
  echo "demo: shutting down ${#pids[@]} modules"
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  echo "demo: all modules stopped"
}
trap stop INT TERM EXIT

echo "demo: booting $system (Ctrl-C to stop)"
for module in $(build/bin/oscar-run "$system" --list-modules); do
  build/bin/oscar-run "$system" --module "$module" &
  pids+=($!)
done
if [ "$duration" -gt 0 ]; then
  sleep "$duration"
else
  wait
fi
