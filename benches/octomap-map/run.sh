#!/usr/bin/env bash
# OctoMap against `tesseral map` on the same synthetic scans, cell by cell.
#
# For each workload (indoor: a room, ranges to about 10 m; outdoor: a street of
# buildings, ranges cut at 50 m) this script
#   1. generates a text scan log (gen_scans.cpp),
#   2. converts it with OctoMap's `log2graph` into a binary scan graph,
#   3. builds the map with OctoMap's `graph2tree` and with `tesseral map` from that
#      same graph, at the same resolution and max range, OctoMap's default sensor model,
#   4. compares the two `.ot` files cell by cell with compare.cpp (OctoMap's reader for
#      both): occupied / free / unknown, and explains a sample of the differences,
#   5. prints insertion time, rays per second and memory for both.
# Installs liboctomap-dev and octomap-tools (apt-get) when missing.
#
# Usage: benches/octomap-map/run.sh
#   RES=0.05 INDOOR_SCANS=100 INDOOR_RAYS=100000 OUTDOOR_SCANS=100 OUTDOOR_RAYS=100000
#   THREADS="1 0" (tesseral runs: 1 = one thread, 0 = all cores)  WORKLOADS="indoor outdoor"
# Prints RESULT lines: insertion seconds and rays/s as each tool reports them
# (graph2tree's "time to insert scans", tesseral's --json "seconds"), the map's
# memory (OctoMap memoryUsage(), tesseral's "bytes"), whole-process CPU seconds and
# peak RSS, then the cell-by-cell table and the explanation of the differences.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="$here/build"
mkdir -p "$build"
res=${RES:-0.05}

. "$here/../install-peers.sh"
install_peers liboctomap-dev octomap-tools
echo "OctoMap $(dpkg-query -W -f='${Version}' liboctomap-dev)" >&2

g++ -O2 -std=c++17 "$here/gen_scans.cpp" -o "$build/gen_scans"
# shellcheck disable=SC2046
g++ -O2 -std=c++17 "$here/compare.cpp" -o "$build/compare" $(pkg-config --cflags --libs octomap)
(cd "$root" && cargo build -q --release -p tesseral-cli)
tesseral="$root/target/release/tesseral"

run_workload() {
  local w=$1 scans=$2 rays=$3 maxrange=$4
  local log="$build/$w.log" graph="$build/$w.graph"
  echo "== $w: $scans scans x $rays rays, resolution $res, max range ${maxrange:-none}" >&2
  "$build/gen_scans" "$w" "$scans" "$rays" 1 >"$log"
  log2graph "$log" "$graph" >/dev/null 2>&1
  local m=() mr=()
  if [ -n "$maxrange" ]; then m=(-m "$maxrange"); mr=(--max-range "$maxrange"); fi
  local t0 t1
  t0=$(date +%s.%N)
  /usr/bin/time -f "%U %S %M" -o "$build/$w-octomap.time" \
    graph2tree -i "$graph" -o "$build/$w-octomap" -res "$res" "${m[@]}" >"$build/$w-octomap.txt" 2>&1
  t1=$(date +%s.%N)
  local om_insert om_mem om_rays
  om_insert=$(sed -n 's/^time to insert scans: \([0-9.e+-]*\) sec.*/\1/p' "$build/$w-octomap.txt")
  om_mem=$(sed -n 's/^Memory: \([0-9]*\) byte.*/\1/p' "$build/$w-octomap.txt" | head -n 1)
  om_rays=$(sed -n 's/^ *Data points in graph: \([0-9]*\).*/\1/p' "$build/$w-octomap.txt")
  echo "RESULT $w octomap insert_s $om_insert" 
  echo "RESULT $w octomap memory_bytes $om_mem"
  echo "RESULT $w octomap rays_per_s $(awk -v r="$om_rays" -v s="$om_insert" 'BEGIN { printf "%.0f", r / s }')"
  echo "RESULT $w octomap wall_s $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')"
  # Whole process (read graph, insert, write both .ot files): CPU seconds, peak RSS.
  awk -v w="$w" '{ printf "RESULT %s octomap process_cpu_s %.2f\nRESULT %s octomap peak_rss_kb %s\n", w, $1 + $2, w, $3 }' "$build/$w-octomap.time"
  local th
  for th in ${THREADS:-1 0}; do
    local tag="threads$th" env=()
    [ "$th" = 0 ] && tag="threads$(nproc)"
    [ "$th" != 0 ] && env=(RAYON_NUM_THREADS="$th")
    t0=$(date +%s.%N)
    /usr/bin/time -f "%U %S %M" -o "$build/$w-tesseral-$tag.time" \
      env "${env[@]}" "$tesseral" map "$graph" -o "$build/$w-tesseral.ot" --resolution "$res" "${mr[@]}" --json >"$build/$w-tesseral-$tag.json"
    t1=$(date +%s.%N)
    python3 - "$build/$w-tesseral-$tag.json" "$w" "$tag" <<'PY'
import json, sys
v = json.load(open(sys.argv[1]))
w, tag = sys.argv[2], sys.argv[3]
print(f"RESULT {w} tesseral-{tag} insert_s {v['seconds']:.4f}")
print(f"RESULT {w} tesseral-{tag} memory_bytes {v['bytes']}")
print(f"RESULT {w} tesseral-{tag} rays_per_s {v['rays_per_second']:.0f}")
print(f"RESULT {w} tesseral rays {v['rays']} occupied {v['occupied']} free {v['free']} leaves {v['leaves']}")
PY
    echo "RESULT $w tesseral-$tag wall_s $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')"
    awk -v w="$w" -v t="$tag" '{ printf "RESULT %s tesseral-%s process_cpu_s %.2f\nRESULT %s tesseral-%s peak_rss_kb %s\n", w, t, $1 + $2, w, t, $3 }' "$build/$w-tesseral-$tag.time"
  done
  echo "-- cell by cell: rows OctoMap (graph2tree), columns tesseral" >&2
  "$build/compare" "$build/$w-octomap.ot" "$build/$w-tesseral.ot" "$graph" "${maxrange:-0}" | sed "s/^RESULT /RESULT $w compare /"
}

for w in ${WORKLOADS:-indoor outdoor}; do
  case $w in
    indoor) run_workload indoor "${INDOOR_SCANS:-100}" "${INDOOR_RAYS:-100000}" "" ;;
    outdoor) run_workload outdoor "${OUTDOOR_SCANS:-100}" "${OUTDOOR_RAYS:-100000}" 50 ;;
  esac
done
