#!/usr/bin/env bash
# The long-run benchmark of docs/robustness.md (not a CTest test): a 4500-frame synthetic
# sequence (the urban route driven 9 times, 4.3 km) through every stage with /usr/bin/time -v,
# then one line per stage with wall time, CPU time and peak memory.
#
#   tests/robustness/long_run.sh [OUT_DIR] [FRAMES]    default out/long, 4500; ~8.5 GB of data
#
# Environment: JVL_BIN (default build/bin), THREADS (default 2).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=${JVL_BIN:-$root/build/bin}
out=${1:-$root/out/long}
frames=${2:-4500}
threads=${THREADS:-2}
mkdir -p "$out/time"
cd "$out"
seq=data/sequences/00
common=(--threads "$threads" --log-level warn)

stage() {
  local name=$1; shift
  echo "== $name: $*"
  /usr/bin/time -v -o "time/$name.txt" "$@" "${common[@]}"
}

[ -f "$seq/times.txt" ] && [ "$(wc -l < "$seq/times.txt")" -eq "$frames" ] ||
  stage sim_sequence "$bin/sim_sequence" -o data --laps 9 --frames "$frames" --quiet
stage make_prior "$bin/make_prior" -g data/poses/00.txt -o prior.h5 --preset lidar-n1
stage lidar_odom "$bin/lidar_odom" --dataset "$seq" -o odom.h5 --quiet
stage vp_detect "$bin/vp_detect" --dataset "$seq" -o vps.h5 --quiet
stage direction_cluster "$bin/direction_cluster" --vps vps.h5 --prior prior.h5 -o directions.h5
stage visual_assoc "$bin/visual_assoc" --dataset "$seq" --prior prior.h5 \
  --directions directions.h5 -o visual.h5 --quiet > /dev/null
stage local_map "$bin/local_map" --visual visual.h5 --dataset "$seq" -o local.h5 --quiet > /dev/null
stage global_opt_fixed "$bin/global_opt" --local local.h5 --visual visual.h5 \
  --directions directions.h5 --fixed-map-points -o global_fixed.h5 --map map.ply
stage global_opt "$bin/global_opt" --local local.h5 --visual visual.h5 \
  --directions directions.h5 -o global.h5
stage evaluate "$bin/evaluate" --gt data/poses/00.txt --est prior.h5 --label prior \
  --est odom.h5 --label lidar_odom --est global_fixed.h5 --label "global (fixed points)" \
  --est global.h5 --label global --align se3 --json metrics.json --markdown metrics.md > /dev/null

echo
printf "%-18s %10s %10s %12s\n" stage "wall (s)" "CPU (s)" "peak (MiB)"
for f in time/*.txt; do
  awk -v name="$(basename "$f" .txt)" '
    /User time/ {u = $NF} /System time/ {s = $NF}
    /Elapsed \(wall clock\)/ {n = split($NF, p, ":"); w = 0; for (i = 1; i <= n; ++i) w = w * 60 + p[i]}
    /Maximum resident set size/ {m = $NF / 1024}
    END {printf "%-18s %10.1f %10.1f %12.0f\n", name, w, u + s, m}' "$f"
done
