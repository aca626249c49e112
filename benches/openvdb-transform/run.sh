#!/usr/bin/env bash
# Issue 16 §3: rotation by any angle, side by side with OpenVDB 10 in one run.
# A solid sphere of radius 100 (4.19 M voxels) rotated by 30° about z with point
# sampling, one core each (both pinned to core 0 with taskset, TBB and rayon
# limited to one thread): OpenVDB's GridTransformer + PointSampler on a pruned
# BoolGrid, and tesseral's LinearOctree::affine (top-down), best of 5 each, in
# wall-clock time and in process CPU time.
# Installs what it uses (libopenvdb-dev libboost-dev libtbb-dev g++) with apt-get.
#   benches/openvdb-transform/run.sh [RADIUS] [DEGREES]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
. "$here/../install-peers.sh"
install_peers libopenvdb-dev libboost-dev libtbb-dev
r="${1:-100}"; deg="${2:-30}"
g++ -O3 -DNDEBUG -std=c++17 -o "$work/vdb" "$here/transform.cpp" -lopenvdb -ltbb -lpthread
(cd "$root" && cargo build --release -q -p tesseral --example rotate_sphere)
vdb="$(taskset -c 0 "$work/vdb" "$r" "$deg")"
ours="$(taskset -c 0 "$root/target/release/examples/rotate_sphere" "$r" "$deg")"
echo "$vdb"; echo "$ours"
v=$(sed -n 's/.*one thread: \([0-9.]*\) ms.*/\1/p' <<<"$vdb")
t=$(sed -n 's/.*one core: \([0-9.]*\) ms.*/\1/p' <<<"$ours")
vc=$(sed -n 's/.*(cpu \([0-9.]*\) ms).*/\1/p' <<<"$vdb")
tc=$(sed -n 's/.*(cpu \([0-9.]*\) ms).*/\1/p' <<<"$ours")
awk -v v="$v" -v t="$t" -v vc="$vc" -v tc="$tc" \
  'BEGIN { printf "OpenVDB / tesseral: %.2fx wall, %.2fx cpu\n", v / t, vc / tc }'
