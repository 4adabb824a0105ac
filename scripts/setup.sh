#!/usr/bin/env bash
# Installs every Debian (bookworm) package OSCAR needs to build, test and run its demo.
# Idempotent: packages already present are skipped; run as root or with sudo available.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config clang-format git ccache
  libfastrtps-dev fastddsgen fastdds-tools libssl-dev
  libeigen3-dev libopencv-dev libapriltag-dev libompl-dev libboost-dev libboost-graph-dev
  libgtest-dev libgmock-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev
  nlohmann-json3-dev libexpected-dev libzstd-dev liblz4-dev zlib1g-dev libjpeg-dev
  graphviz iproute2 procps gdb gdbserver openssh-client openssh-server nodejs npm
  cyclonedds-dev cyclonedds-tools libiceoryx-posh-dev iceoryx
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# nodejs/npm may come from elsewhere (e.g. a preinstalled Node); accept a working `node`/`npm`.
if command -v node >/dev/null && command -v npm >/dev/null; then
  filtered=()
  for p in "${missing[@]}"; do [[ $p == nodejs || $p == npm ]] || filtered+=("$p"); done
  missing=("${filtered[@]+"${filtered[@]}"}")
fi

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: done"
