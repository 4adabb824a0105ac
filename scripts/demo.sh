#!/usr/bin/env bash
# The README's main command: boots the demo system (config/demo-local.yaml) on this host with
# `oscar boot`. Installs what is missing, builds, boots the registry, a monitor and every module,
# follows their merged log until Ctrl-C (or for --duration SECONDS), then shuts the system down
# in order and leaves nothing behind.
set -euo pipefail
cd "$(dirname "$0")/.."
args=()
system=config/demo-local.yaml
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) args+=(--duration "$2"); shift 2 ;;
    --system) system="$2"; shift 2 ;;
    *) echo "usage: scripts/demo.sh [--duration SECONDS] [--system FILE]" >&2; exit 2 ;;
  esac
done

bash scripts/setup.sh
bash scripts/build.sh
exec build/bin/oscar boot "$system" "${args[@]+"${args[@]}"}"
