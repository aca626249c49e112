#!/usr/bin/env bash
# Checks tesseral's OctoMap files against the real OctoMap tools, and times reading a
# one-million-leaf .bt with OctoMap's readBinary beside tesseral's reader.
#
# Installs what it uses (octomap-tools, liboctomap-dev, g++) with apt-get; needs
# python3 and cargo. Run from anywhere (root or sudo for apt):
#   benches/octomap/run_bt.sh            # checks + timing
#   benches/octomap/run_bt.sh --quick    # checks only
# Exits non-zero at the first disagreement.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
quick=${1:-}

. "$here/../install-peers.sh"
install_peers octomap-tools liboctomap-dev
for tool in convert_octree bt2vrml binvox2bt g++ python3; do
  command -v "$tool" >/dev/null || { echo "missing $tool (apt-get install -y octomap-tools liboctomap-dev)"; exit 1; }
done

echo "== building tesseral and bt_read"
(cd "$root" && cargo build --release -q -p tesseral-cli)
T="$root/target/release/tesseral"
g++ -O2 -std=c++17 -o "$work/bt_read" "$here/bt_read.cpp" -loctomap -loctomath
B="$work/bt_read"
cd "$work"

# Sorted voxel list of any file, through tesseral.
voxels() { "$T" convert "$1" "$2.xyz" && grep -v '^#' "$2.xyz" | sort > "$2"; }
same() { if cmp -s "$1" "$2"; then echo "  ok: $3 ($(wc -l < "$1") voxels)"; else echo "  FAIL: $3"; diff "$1" "$2" | head; exit 1; fi; }

echo "== test solid: random voxels, a block, negative coordinates"
python3 - <<'PY'
import random
random.seed(5)
s = set()
while len(s) < 3000:
    s.add((random.randint(-40, 40), random.randint(-30, 50), random.randint(0, 20)))
for x in range(-60, -28):
    for y in range(0, 32):
        for z in range(-16, 16):
            s.add((x, y, z))
open("a.xyz", "w").write("".join(f"{x} {y} {z}\n" for x, y, z in sorted(s)))
PY
sort a.xyz > ref

echo "== our .bt in OctoMap (readBinary)"
"$T" convert a.xyz a.bt
"$B" a.bt --dump om.xyz | sed 's/^/  /'
sort om.xyz > om; same ref om "OctoMap readBinary of our .bt"

echo "== convert_octree: our .bt -> .ot -> .bt, read by OctoMap and by us"
convert_octree a.bt c.ot >/dev/null 2>&1
"$B" c.ot --dump omc.xyz | sed 's/^/  /'
sort omc.xyz > omc; same ref omc "OctoMap reading convert_octree's .ot"
voxels c.ot ours_c; same ref ours_c "tesseral reading convert_octree's .ot"
"$T" convert a.xyz a.ot
convert_octree a.ot d.bt >/dev/null 2>&1
voxels d.bt ours_d; same ref ours_d "our .ot -> convert_octree -> .bt -> tesseral"

echo "== bt2vrml: every Box of the VRML, expanded to voxels"
bt2vrml a.bt >/dev/null 2>&1
python3 - a.bt.wrl > vrml <<'PY'
import re, sys
text = open(sys.argv[1]).read()
out = []
for t, s in re.findall(r"translation\s+([-\d.e ]+?)\s*\n\s*children \[ Shape \{ geometry Box \{ size ([-\d.e ]+)\}", text):
    c = [float(v) for v in t.split()]
    n = int(round(float(s.split()[0])))
    lo = [int(round(c[a] - n / 2)) for a in range(3)]
    for i in range(n):
        for j in range(n):
            for k in range(n):
                out.append(f"{lo[0]+i} {lo[1]+j} {lo[2]+k}")
print("\n".join(sorted(out)))
PY
sort vrml -o vrml; same ref vrml "bt2vrml boxes of our .bt"

echo "== binvox2bt: its .bt against our own binvox import"
"$T" convert a.xyz a.binvox
# Give the grid a 5 cm voxel and a translate of whole voxels, as real binvox files have.
python3 - <<'PY'
data = open("a.binvox", "rb").read()
head, body = data.split(b"data\n", 1)
lines = head.decode().splitlines()
dim = int(lines[1].split()[1])
t = [float(v) for v in lines[2].split()[1:]]
res = 0.05
lines[2] = "translate %r %r %r" % tuple(v * res for v in t)
lines[3] = "scale %r" % (dim * res)
open("m.binvox", "wb").write(("\n".join(lines) + "\ndata\n").encode() + body)
PY
binvox2bt m.binvox -o m.bt >/dev/null 2>&1
voxels m.bt from_om; voxels m.binvox from_ours
same from_ours from_om "binvox2bt output == our binvox import"
same ref from_ours "our binvox import == the original voxels"
"$T" convert m.bt m.tess --json | sed 's/^/  /'

echo "== ColorOcTree: a coloured .vox written as .ot, read by OctoMap"
"$T" convert a.xyz a.vox
"$T" convert a.vox col.ot
"$B" col.ot --dump omcol.xyz | sed 's/^/  /'
sort omcol.xyz > omcol; voxels a.vox ours_vox
same ours_vox omcol "OctoMap reading our ColorOcTree .ot"

if [ "$quick" = "--quick" ]; then echo "all checks passed"; exit 0; fi

echo "== timing: a .bt with about 1M leaves (1M random voxels in 512^3)"
python3 - <<'PY'
import random
random.seed(8)
with open("big.xyz", "w") as f:
    for _ in range(1000000):
        f.write("%d %d %d\n" % tuple(random.randrange(-256, 256) for _ in range(3)))
PY
"$T" convert big.xyz big.bt --json | sed 's/^/  /'
echo "  OctoMap OcTree::readBinary from memory:"
"$B" big.bt --repeat 7 | sed 's/^/    /'
echo "  tesseral octomap::decode_bt from memory (criterion):"
(cd "$root" && TESSERAL_BT_FILE="$work/big.bt" cargo bench -q -p tesseral --bench io -- \
  --warm-up-time 1 --measurement-time 5 bt_read 2>&1 | grep -E "bt_read|time:" | sed 's/^/    /')
echo "all checks passed"
