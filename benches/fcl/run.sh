#!/usr/bin/env bash
# Side-by-side benchmark of tesseral's interference test and FCL's (Debian's
# libfcl-dev, OcTree-vs-OcTree fcl::collide on OctoMap trees) on the same pairs of
# objects, touching and separated (see crates/tesseral/benches/collide.rs).
# Installs what it uses (libfcl-dev, liboctomap-dev, g++, pkg-config) with apt-get,
# writes the pairs with the Rust bench's summary (TESSERAL_FCL_PAIRS), builds and runs
# the C++ harness on them, runs the Rust summary again right after, and prints one
# table with the ratios.
# Usage: benches/fcl/run.sh            (from anywhere; needs root or sudo for apt)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="$here/build"
mkdir -p "$build/pairs"

. "$here/../install-peers.sh"
install_peers libfcl-dev liboctomap-dev
echo "FCL $(dpkg-query -W -f='${Version}' libfcl-dev), OctoMap $(dpkg-query -W -f='${Version}' liboctomap-dev)" >&2

# shellcheck disable=SC2046
g++ -O2 -std=c++17 "$here/harness.cpp" -o "$build/fcl_bench" $(pkg-config --cflags --libs fcl octomap)

echo "writing the pairs and running the tesseral summary..." >&2
(cd "$root" && TESSERAL_SUMMARY_ONLY=1 TESSERAL_FCL_PAIRS="$build/pairs" cargo bench -q -p tesseral --bench collide) \
  | grep -E '^(RESULT|INFO)' > "$build/tesseral1.txt"
echo "running the FCL harness..." >&2
"$build/fcl_bench" "$build/pairs" | tee "$build/fcl1.txt" >&2
echo "running the tesseral summary again..." >&2
(cd "$root" && TESSERAL_SUMMARY_ONLY=1 cargo bench -q -p tesseral --bench collide) \
  | grep -E '^(RESULT|INFO)' > "$build/tesseral2.txt"
echo "running the FCL harness again..." >&2
"$build/fcl_bench" "$build/pairs" | tee "$build/fcl2.txt" >&2
cat "$build/tesseral1.txt" "$build/tesseral2.txt" >&2

# Each side alternates twice; the table takes each side's better run (the machine
# may be busy during one), so both get the same treatment.
awk '
  $1 == "RESULT" {
    k = $2 " " $3 " " $4
    if (!(k in v) || $6 < v[k]) v[k] = $6
    if (!($3 in seen)) { seen[$3] = 1; order[++n] = $3 }
  }
  END {
    printf "%-8s %-9s %12s %12s %12s %9s %9s\n", "pair", "state", "fcl ns", "tesseral ns", "linear ns", "fcl/tess", "fcl/lin"
    split("touching near apart", states, " ")
    for (i = 1; i <= n; i++) for (j = 1; j <= 3; j++) {
      p = order[i]; s = states[j]
      f = v["fcl " p " " s]; t = v["tesseral " p " " s]; l = v["tesseral-linear " p " " s]
      if (f == "" || t == "") continue
      printf "%-8s %-9s %12.0f %12.0f %12.0f %8.1fx %8.1fx\n", p, s, f, t, l, f / t, f / l
    }
  }
' "$build/tesseral1.txt" "$build/fcl1.txt" "$build/tesseral2.txt" "$build/fcl2.txt"
