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
# pruneGrid (a new canonical tree, what tesseral's call returns). tesseral: LinearOctree::set_op, which
# returns a new canonical tree (allocation and merging of blocks included).
# Both pinned to core 0 (taskset), TBB and rayon limited to one thread; best of REPS,
# each time the process's CPU time (all threads, user + system, page faults
# included), since the machine is shared and wall time would count other processes'
# turns on the core.
# A last column runs tesseral on two threads (taskset -c 0,1, wall time), for
# information.
# Memory: bytes per voxel of the result (OpenVDB memUsage of the pruned result;
# tesseral the leaf list's heap capacity).
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
taskset -c 0 "$peer" "$work" "$reps" 1 "$root/scenes" >"$work/ours1.txt"
taskset -c 0,1 "$peer" "$work" "$reps" 2 "$root/scenes" >"$work/ours2.txt"
names=$(awk '$1 == "INPUT" { print $2 }' "$work/ours1.txt")
args=()
for n in $names; do args+=("$work" "$n"); done
taskset -c 0 "$work/vdb" "$reps" "${args[@]}" >"$work/vdb.txt"
awk '$1 == "INPUT" { printf "%-30s voxels %d + %d, tesseral leaves %d + %d\n", $2, $3, $4, $5, $6 }' "$work/ours1.txt"
awk '$1 == "INPUT" { printf "%-30s OpenVDB voxels %d + %d, leaf nodes %d + %d\n", $2, $3, $4, $5, $6 }' "$work/vdb.txt"
echo
printf '%-30s %-12s %9s %9s %9s %9s %8s %8s %9s %8s %8s %s\n' workload op "vdb op" "+prune" "copy+op+p" "ours" ratio "ratio2" "ours 2c" "vdb B/v" "ours B/v" check
awk -v o1="$work/ours1.txt" -v o2="$work/ours2.txt" '
  BEGIN {
    while ((getline l < o1) > 0) { split(l, f); if (f[1] == "RESULT") { t1[f[2] " " f[3]] = f[4]; n1[f[2] " " f[3]] = f[5]; m1[f[2] " " f[3]] = f[6] } }
    while ((getline l < o2) > 0) { split(l, f); if (f[1] == "RESULT") { t2[f[2] " " f[3]] = f[4] } }
  }
  $1 == "RESULT" {
    k = $2 " " $3
    check = (n1[k] == $7) ? "same voxels" : "VOXELS DIFFER (" n1[k] " vs " $7 ")"
    printf "%-30s %-12s %9.4f %9.4f %9.4f %9.4f %7.2fx %7.2fx %9.4f %8.3f %8.3f %s\n", $2, $3, $4, $5, $6, t1[k], $4 / t1[k], $6 / t1[k], t2[k], $8, m1[k], check
  }' "$work/vdb.txt"
echo "times in ms, best of $reps; ratio = OpenVDB op / tesseral one core (above 1: tesseral faster);"
echo "ratio2 = OpenVDB copy+op+prune / tesseral one core; ours 2c = tesseral on two threads"
