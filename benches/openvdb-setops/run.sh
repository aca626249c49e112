#!/usr/bin/env bash
# Issue 17 §1: set operations side by side with OpenVDB 10 in one run, one core each.
# Workloads (both operands of a pair in one space; the tesseral side builds them and
# writes their leaves, which the OpenVDB side reads, so the solids are identical):
#   spheres-r100-d9               two solid spheres r=100, centres 50 voxels apart,
#                                 wholly inside a depth-9 space (nothing clipped)
#   spheres-r400-d11              two solid spheres r=400, 200 apart, depth 11
#   porous-128-d8                 two 128^3 blocks of random voxels (density 0.3,
#                                 splitmix64 seeds 1 and 2), overlapping by half
#   scenes-tank-truck-d7          scenes/tank.tss and scenes/truck.tss as built
#   scenes-showcase-aircraft-d10  scenes/showcase.tss and scenes/aircraft.tss, the
#                                 aircraft placed over the dome
# OpenVDB: pruned BoolGrids; the first is deep-copied outside the clock, then
# topologyUnion / topologyIntersection / topologyDifference alone is timed (the ratio
# is against this); further columns: the op followed by pruneGrid, and deepCopy + op +
# pruneGrid (a new canonical tree, what tesseral's call returns).
# tesseral: LinearOctree::set_op on operands whose bricked forms were made outside
# the clock (as OpenVDB's grids are built outside it); it returns a new canonical
# tree in bricked form (allocation and merging of blocks included). Further columns:
# the same operation on the leaf lists ("leaf path"), the first leaves() call on the
# result (its leaf list made from the bricks), and (per workload) the time to make
# both operands' bricked forms from their leaf lists.
# Both pinned to core 0 (taskset), TBB and rayon limited to one thread; best of REPS,
# each time the process's CPU time (all threads, user + system, page faults
# included), since the machine is shared and wall time would count other processes'
# turns on the core.
# Memory: bytes per voxel of the result (OpenVDB memUsage of the pruned result;
# tesseral the heap capacity of the result as returned, bricked form only).
# Installs what it uses (libopenvdb-dev libboost-dev libtbb-dev g++) with apt-get.
#   benches/openvdb-setops/run.sh [REPS]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
. "$here/../install-peers.sh"
install_peers libopenvdb-dev libboost-dev libtbb-dev
reps="${1:-20}"
g++ -O3 -DNDEBUG -std=c++17 -o "$work/vdb" "$here/setops.cpp" -lopenvdb -ltbb -lpthread
(cd "$root" && cargo build --release -q -p tesseral --example setops_peer)
peer="$root/target/release/examples/setops_peer"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
taskset -c 0 "$peer" "$work" "$reps" 1 "$root/scenes" >"$work/ours.txt"
names=$(awk '$1 == "INPUT" { print $2 }' "$work/ours.txt")
args=()
for n in $names; do args+=("$work" "$n"); done
taskset -c 0 "$work/vdb" "$reps" "${args[@]}" >"$work/vdb.txt"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
awk '$1 == "INPUT" { printf "%-30s voxels %d + %d, tesseral leaves %d + %d, bricking both %.4f ms, bricked bytes %d\n", $2, $3, $4, $5, $6, $7, $8 }' "$work/ours.txt"
awk '$1 == "INPUT" { printf "%-30s OpenVDB voxels %d + %d, leaf nodes %d + %d\n", $2, $3, $4, $5, $6 }' "$work/vdb.txt"
echo
printf '%-30s %-12s %9s %9s %9s %9s %8s %8s %9s %9s %8s %8s %s\n' workload op "vdb op" "+prune" "copy+op+p" "ours" ratio "ratio2" "leaf path" "leaves()" "vdb B/v" "ours B/v" check
awk -v o="$work/ours.txt" '
  BEGIN {
    while ((getline l < o) > 0) {
      split(l, f)
      if (f[1] == "RESULT") { k = f[2] " " f[3]; t[k] = f[4]; n[k] = f[5]; m[k] = f[6]; lp[k] = f[8]; lv[k] = f[9] }
    }
  }
  $1 == "RESULT" {
    k = $2 " " $3
    check = (n[k] == $7) ? "same voxels" : "VOXELS DIFFER (" n[k] " vs " $7 ")"
    printf "%-30s %-12s %9.4f %9.4f %9.4f %9.4f %7.2fx %7.2fx %9.4f %9.4f %8.3f %8.3f %s\n", $2, $3, $4, $5, $6, t[k], $4 / t[k], $6 / t[k], lp[k], lv[k], $8, m[k], check
  }' "$work/vdb.txt"
echo "times in ms, best of $reps, one core; ratio = OpenVDB op / tesseral (above 1: tesseral faster);"
echo "ratio2 = OpenVDB copy+op+prune / tesseral; leaf path = tesseral on leaf lists; leaves() = making the result's leaf list"
