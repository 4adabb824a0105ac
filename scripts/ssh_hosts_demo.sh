#!/usr/bin/env bash
# Boots a system over SSH on one machine (docs/boot.md, "Booting over SSH"): two network
# namespaces as two computers, an OpenSSH server in the second listening only on its namespace
# address, keys made for this run in a temporary folder. `oscar boot` runs in the first and
# reaches the second only through `ssh:`. Root only; removes everything afterwards.
#   sudo bash scripts/ssh_hosts_demo.sh [BUILD_DIR] [SECONDS]
set -euo pipefail
build=$(realpath "${1:-build}")
seconds=${2:-5}
[ "$(id -u)" -eq 0 ] || { echo "run as root (it creates network namespaces)"; exit 2; }
[ -x /usr/sbin/sshd ] || { echo "needs openssh-server (scripts/setup.sh installs it)"; exit 2; }
tmp=$(mktemp -d /tmp/oscar_ssh_demo.XXXXXX)
cleanup() {
  for ns in oscar_sd1 oscar_sd2 oscar_sdbr; do
    ip netns pids $ns 2>/dev/null | xargs -r kill 2>/dev/null || true
    ip netns del $ns 2>/dev/null || true
  done
  rm -rf "$tmp"
}
trap cleanup EXIT

# Two hosts on 10.77.250.0/24, joined by a bridge in a namespace of its own.
ip netns add oscar_sdbr
ip -n oscar_sdbr link add br0 type bridge && ip -n oscar_sdbr link set br0 up
for i in 1 2; do
  ip netns add oscar_sd$i && ip -n oscar_sd$i link set lo up
  ip link add oscar_sdh$i netns oscar_sd$i type veth peer name oscar_sdb$i netns oscar_sdbr
  ip -n oscar_sdbr link set oscar_sdb$i master br0 up
  ip -n oscar_sd$i addr add 10.77.250.$i/24 dev oscar_sdh$i
  ip -n oscar_sd$i link set oscar_sdh$i up
done

# The second host's sshd: its own host key, the client key of this run, key authentication only.
ssh-keygen -q -t ed25519 -N '' -f "$tmp/host_key"
ssh-keygen -q -t ed25519 -N '' -f "$tmp/client_key"
cp "$tmp/client_key.pub" "$tmp/authorized_keys"
echo "[10.77.250.2]:2222 $(cat "$tmp/host_key.pub")" > "$tmp/known_hosts"
cat > "$tmp/sshd_config" <<CONFIG
ListenAddress 10.77.250.2:2222
HostKey $tmp/host_key
AuthorizedKeysFile $tmp/authorized_keys
PidFile $tmp/sshd.pid
UsePAM no
StrictModes no
PasswordAuthentication no
KbdInteractiveAuthentication no
PermitRootLogin prohibit-password
ClientAliveInterval 1
ClientAliveCountMax 3
CONFIG
mkdir -p /run/sshd
ip netns exec oscar_sd2 /usr/sbin/sshd -f "$tmp/sshd_config"

# A source on pc1, a sink on pc2: the cues cross from one host to the other.
cat > "$tmp/system.yaml" <<SYSTEM
system: ssh_demo
lease: 1s
hosts:
  pc1: { local: true, address: 10.77.250.1 }
  pc2:
    ssh: root@10.77.250.2
    address: 10.77.250.2
    ssh_options: [Port=2222, IdentityFile=$tmp/client_key, UserKnownHostsFile=$tmp/known_hosts]
modules:
  - name: src
    host: pc1
    kernels: [ { type: bench_source, name: src, params: { type: Bool } } ]
    mode: { continuous: 100ms }
  - name: sink
    host: pc2
    kernels: [ { type: bench_sink, name: sink, params: { type: Bool, log_every: 1s }, inputs: { in: src/out } } ]
    mode: single_step
SYSTEM
ip netns exec oscar_sd1 "$build/bin/oscar" boot "$tmp/system.yaml" --domain 77 \
  --log-dir "$tmp/logs" --duration "$seconds"
