#!/usr/bin/env bash
# Screenshots of OSCAR's live view in Foxglove (docs/foxglove.md): boots each demo system, serves
# it with `oscar bridge foxglove` on 127.0.0.1, opens Foxglove Studio (npm @foxglove/studio-base
# 1.48.0, MPL-2.0, mounted by scripts/foxglove/host.html) in Debian's headless chromium on the
# bridge with the committed layout, waits until every panel has data and writes
#   docs/images/foxglove-landmarks.png   (config/landmarks-1host.yaml, docs/foxglove/landmarks-layout.json)
#   docs/images/foxglove-swarm.png       (config/swarm-warehouse.yaml, docs/foxglove/swarm-layout.json)
# Installs chromium (apt) and the npm packages of scripts/foxglove/package-lock.json into
# build/foxglove-screenshots/npm (never committed). Each system runs on a free DDS domain; the
# browser reaches 127.0.0.1 only. Everything it starts is stopped when it ends, however it ends.
#
#   scripts/foxglove_screenshots.sh [--bin DIR] [--only landmarks|swarm] [--out DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/bin
only=""
out=docs/images
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --only) only="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "usage: scripts/foxglove_screenshots.sh [--bin DIR] [--only landmarks|swarm] [--out DIR]" >&2
       exit 2 ;;
  esac
done
if [ ! -x "$bin/oscar" ]; then
  echo "foxglove screenshots: $bin/oscar does not exist (build first: bash scripts/build.sh, or --bin DIR)" >&2
  exit 1
fi
work=build/foxglove-screenshots
mkdir -p "$work" "$out"

# --- what the browser needs -------------------------------------------------------------------
if ! command -v chromium >/dev/null; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  echo "foxglove screenshots: installing Debian's chromium"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium
fi
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "foxglove screenshots: needs node and npm (bash scripts/setup.sh installs them)" >&2
  exit 1
fi
if ! cmp -s scripts/foxglove/package-lock.json "$work/npm/package-lock.json"; then
  echo "foxglove screenshots: npm ci into $work/npm"
  mkdir -p "$work/npm"
  cp scripts/foxglove/package.json scripts/foxglove/package-lock.json "$work/npm/"
  (cd "$work/npm" && npm ci --no-audit --no-fund --ignore-scripts)
fi

# --- a DDS domain no one else uses: the lock files oscar::testing::FreeDomain takes -------------
locks=${OSCAR_TEST_DOMAINS_DIR:-/tmp/oscar/test-domains}
mkdir -p "$locks"
domain=""
for d in $(seq 232 -1 1); do
  exec {lock_fd}> "$locks/domain-$d.lock"
  if flock -n "$lock_fd"; then domain=$d; break; fi
  exec {lock_fd}>&-
done
if [ -z "$domain" ]; then
  echo "foxglove screenshots: every DDS domain from 1 to 232 is taken (locks in $locks)" >&2
  exit 1
fi

# --- boot, bridge, shoot, stop ------------------------------------------------------------------
boot_pid=""
bridge_pid=""
stop() {
  # background jobs of a script ignore SIGINT: SIGTERM stops boot (its system in order) and bridge
  for pid in $bridge_pid $boot_pid; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in $bridge_pid $boot_pid; do wait "$pid" 2>/dev/null || true; done
  bridge_pid=""
  boot_pid=""
}
trap stop EXIT

# wait_for FILE PATTERN SECONDS WHAT: until FILE has a line matching PATTERN
wait_for() {
  local deadline=$((SECONDS + $3))
  until grep -q -- "$2" "$1" 2>/dev/null; do
    if [ $SECONDS -ge $deadline ]; then
      echo "foxglove screenshots: no $4 within $3 s; the last lines of $1:" >&2
      tail -n 20 "$1" >&2
      exit 1
    fi
    sleep 0.5
  done
}

# shoot NAME SYSTEM LAYOUT EXPECTED_TEXT
shoot() {
  local name=$1 system=$2 layout=$3 expect=$4
  local logs="$work/$name"
  rm -rf "$logs"
  mkdir -p "$logs"
  echo "foxglove screenshots: $name: booting $system on domain $domain"
  "$bin/oscar" boot -d "$domain" --log-dir "$logs/processes" "$system" > "$logs/boot.log" 2>&1 &
  boot_pid=$!
  wait_for "$logs/boot.log" "system running" 60 "'system running' from oscar boot"
  "$bin/oscar" bridge foxglove -d "$domain" --address 127.0.0.1 --port 0 > "$logs/bridge.log" 2>&1 &
  bridge_pid=$!
  wait_for "$logs/bridge.log" "serving domain" 30 "bridge"
  local url
  url=$(grep -o 'ws://127\.0\.0\.1:[0-9]*' "$logs/bridge.log" | head -n 1)
  echo "foxglove screenshots: $name: Foxglove on $url with $layout"
  node scripts/foxglove/shoot.js --npm "$work/npm" \
    --studio "$work/npm/node_modules/@foxglove/studio-base/assets" \
    --layout "$layout" --ws "$url" --out "$out/foxglove-$name.png" --expect "$expect" \
    | tee "$logs/shoot.json"
  stop
  echo "foxglove screenshots: $name: $out/foxglove-$name.png ($(stat -c %s "$out/foxglove-$name.png") bytes)"
}

if [ -z "$only" ] || [ "$only" = landmarks ]; then
  shoot landmarks config/landmarks-1host.yaml docs/foxglove/landmarks-layout.json '"landmarks"'
fi
if [ -z "$only" ] || [ "$only" = swarm ]; then
  shoot swarm config/swarm-warehouse.yaml docs/foxglove/swarm-layout.json '"warehouse"'
fi
