#!/usr/bin/env bash
# MCAP interop with @mcap/core (npm) both ways. $1 = the build directory.
# Exit 77 (ctest: skipped) if node or npm is missing.
set -euo pipefail
build=$1
here=$(cd "$(dirname "$0")" && pwd)
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "SKIPPED: node/npm not found; the interop test needs Node.js to run @mcap/core"
  exit 77
fi
prefix=$build/mcap-interop
if [ ! -d "$prefix/node_modules/@mcap/core" ]; then
  npm install --prefix "$prefix" --no-audit --no-fund --loglevel=error \
    @mcap/core@2 @foxglove/wasm-zstd@1 @foxglove/wasm-lz4@1
fi
echo "@mcap/core $(node -p "require('$prefix/node_modules/@mcap/core/package.json').version"), node $(node --version)"
ref() { NODE_PATH=$prefix/node_modules node "$here/mcap_interop.js" "$@"; }
ours=$build/tests/oscar-mcap-interop
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
expected='{"schemas":2,"channels":3,"messages":1000,"sum":'
status=0
for c in none zstd lz4; do
  "$ours" write "$work/ours_$c.mcap" "$c"
  a=$("$ours" summary "$work/ours_$c.mcap")
  b=$(ref summary "$work/ours_$c.mcap")
  echo "ours ($c) read by oscar::mcap: $a"
  echo "ours ($c) read by @mcap/core:  $b"
  if [ "$a" != "$b" ] || [[ "$b" != "$expected"* ]]; then echo "MISMATCH ($c)"; status=1; fi
done
ref write "$work/reference.mcap"
a=$(ref summary "$work/reference.mcap")
b=$("$ours" summary "$work/reference.mcap")
echo "@mcap/core's file read by @mcap/core:  $a"
echo "@mcap/core's file read by oscar::mcap: $b"
if [ "$a" != "$b" ] || [[ "$b" != "$expected"* ]]; then echo "MISMATCH (reference file)"; status=1; fi
exit $status
