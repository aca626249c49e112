#!/usr/bin/env bash
# Side-by-side benchmark of tesseral's DynamicOctree and OctoMap (Debian's
# liboctomap-dev) on the same workloads:
#   random: 1,000,000 random cells in [-256, 256)^3
#   shell:  every cell whose centre is at distance [200, 230) from the origin
# Installs what it uses (liboctomap-dev, g++, pkg-config) with apt-get, builds the C++
# harness, runs it, runs the Rust summary (crates/tesseral/benches/dynamic.rs with
# TESSERAL_SUMMARY_ONLY=1), and prints one table with the ratios.
# Usage: benches/octomap/run.sh            (from anywhere; needs root or sudo for apt)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="$here/build"
mkdir -p "$build"

. "$here/../install-peers.sh"
install_peers liboctomap-dev
echo "OctoMap $(dpkg-query -W -f='${Version}' liboctomap-dev)" >&2

# shellcheck disable=SC2046
g++ -O2 -std=c++17 "$here/harness.cpp" -o "$build/octomap_bench" $(pkg-config --cflags --libs octomap)

echo "running the OctoMap harness..." >&2
"$build/octomap_bench" | tee "$build/octomap.txt" >&2
echo "running the tesseral summary..." >&2
(cd "$root" && TESSERAL_SUMMARY_ONLY=1 cargo bench -q -p tesseral --bench dynamic) \
  | grep '^RESULT' | tee "$build/tesseral.txt" >&2

awk '
  $1 == "RESULT" { k = $2 " " $3 " " $4; if (!(k in v)) order[++n] = k; v[k] = $5 }
  function row(w, label, tm, om,   t, o) {
    t = v["tesseral " w " " tm]; o = v["octomap " w " " om]
    if (t == "" || o == "") return
    if (t > 0 && o > 0)
      printf "| %-7s | %-34s | %12.2f | %12.2f | %8.1fx |\n", w, label, t, o, o / t
    else
      printf "| %-7s | %-34s | %12.2f | %12.2f |      n/a |\n", w, label, t, o
  }
  END {
    print "| work    | measure                            |     tesseral |      OctoMap | OctoMap/tesseral |"
    print "|---------|------------------------------------|--------------|--------------|----------|"
    split("random shell", ws, " ")
    for (i = 1; i <= 2; i++) {
      w = ws[i]
      row(w, "insert ns (updateNode point)", "insert_ns", "insert_ns")
      row(w, "insert ns (updateNode key)", "insert_ns", "insert_key_ns")
      row(w, "lookup ns, random cells (search)", "lookup_random_ns", "lookup_random_ns")
      row(w, "lookup ns, occupied cells (search)", "lookup_occupied_ns", "lookup_occupied_ns")
      row(w, "bytes per stored voxel (own count)", "bytes_per_voxel", "bytes_per_voxel")
      row(w, "bytes per stored voxel (RSS delta)", "rss_bytes_per_voxel", "rss_bytes_per_voxel")
    }
    print ""
    print "tesseral only (same run):"
    for (i = 1; i <= n; i++) {
      split(order[i], p, " ")
      if (p[1] == "tesseral") printf "  %s %s = %s\n", p[2], p[3], v[order[i]]
    }
    print "OctoMap bytes per leaf (memoryUsage / getNumLeafNodes):"
    printf "  random %s, shell %s\n", v["octomap random bytes_per_leaf"], v["octomap shell bytes_per_leaf"]
  }' "$build/octomap.txt" "$build/tesseral.txt"
