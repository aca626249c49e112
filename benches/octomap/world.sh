#!/usr/bin/env bash
# Issue 12's interop check: a map that OctoMap itself made (0.05 m, with free space
# from insertPointCloud, and a ColorOcTree) goes through tesseral's translate, op and
# rotate, and OctoMap's own tools say what survived: resolution, occupied and free
# volumes, colours, and compare_octrees on the input and a translate-by-zero output.
#
# Installs what it uses (octomap-tools, liboctomap-dev, g++) with apt-get. Run from
# anywhere (root or sudo for apt):   benches/octomap/world.sh
# Exits non-zero at the first disagreement.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

. "$here/../install-peers.sh"
install_peers octomap-tools liboctomap-dev
(cd "$root" && cargo build --release -q -p tesseral-cli)
T="$root/target/release/tesseral"
for tool in map_make map_stats; do
  g++ -O2 -std=c++17 -o "$work/$tool" "$here/$tool.cpp" -loctomap -loctomath
done
cd "$work"
./map_make .
stats() { ./map_stats "$1" | sed 's/^[^:]*: //'; }
same() {
  if [ "$(stats "$1")" != "$(stats "$2")" ]; then
    echo "FAIL: $1 and $2 differ:"; stats "$1"; stats "$2"; exit 1
  fi
  echo "ok: $2 = $1: $(stats "$2")"
}
# Volumes must survive even where leaves are cut differently.
volumes() { stats "$1" | sed 's/occupied [0-9]* leaves/occupied/; s/free [0-9]* leaves/free/'; }

"$T" translate scan.bt --by 0,0,0 -o zero.bt >/dev/null
"$T" translate scan.ot --by 0,0,0 -o zero.ot >/dev/null
"$T" translate color.ot --by 0,0,0 -o zerocolor.ot >/dev/null
same scan.bt zero.bt
same scan.ot zero.ot
same color.ot zerocolor.ot
cmp scan.bt zero.bt && cmp scan.ot zero.ot && cmp color.ot zerocolor.ot && echo "ok: translate by zero writes the same bytes (.bt, .ot, ColorOcTree)"
echo "compare_octrees scan.ot zero.ot:"
compare_octrees scan.ot zero.ot 2>&1 | grep -E "KLD|Error|error" | tee kld.txt
grep -q "^KLD: 0$" kld.txt || { echo "FAIL: compare_octrees reports a difference"; exit 1; }

"$T" translate scan.bt --by-world 0.1,0,0 -o moved.bt >/dev/null
[ "$(volumes moved.bt)" = "$(volumes scan.bt)" ] || { echo "FAIL: moved.bt volumes"; volumes moved.bt; exit 1; }
echo "ok: translate --by-world 0.1,0,0: $(stats moved.bt)"
"$T" op union scan.ot zero.ot -o union.ot >/dev/null
same scan.ot union.ot
"$T" rotate color.ot --axis z --turns 1 -o rot.ot >/dev/null
[ "$(volumes rot.ot)" = "$(volumes color.ot)" ] || { echo "FAIL: rot.ot"; volumes rot.ot; exit 1; }
echo "ok: rotate a ColorOcTree: $(stats rot.ot)"
echo "all OctoMap interop checks passed"
