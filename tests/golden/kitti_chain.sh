#!/usr/bin/env bash
# The chain on frames 0-19 of the real KITTI 04 excerpt (../shared/data), with this project's
# lidar_odom as the prior (the paper's configuration), for the KITTI golden files. Without
# ../shared it writes OUT/SKIPPED and exits 0: those goldens are skipped.
#
#   tests/golden/kitti_chain.sh BIN_DIR OUT_DIR THREADS
set -euo pipefail

bin=$(cd "$1" && pwd)
out=$2
threads=$3
root=$(cd "$(dirname "$0")/../.." && pwd)
data=$root/../shared/data/kitti_odometry_04_f0-50
seq=$data/sequences/04

rm -rf "$out"
mkdir -p "$out"
if [ ! -d "$seq" ]; then
  echo "$data not found (a user's clone has no ../shared): the KITTI goldens are skipped" \
    | tee "$out/SKIPPED"
  exit 0
fi
cd "$out"
common=(--threads "$threads" --log-level warn)
frames=(--frames 0:20)

"$bin/lidar_odom" --dataset "$seq" "${frames[@]}" -o odom.h5 --quiet "${common[@]}"
"$bin/vp_detect" --dataset "$seq" "${frames[@]}" -o vps.h5 --quiet "${common[@]}"
"$bin/direction_cluster" --vps vps.h5 --prior odom.h5 -o directions.h5 "${common[@]}"
"$bin/visual_assoc" --dataset "$seq" "${frames[@]}" --prior odom.h5 --directions directions.h5 \
  -o visual.h5 --quiet "${common[@]}" > /dev/null
"$bin/local_map" --visual visual.h5 --dataset "$seq" -o local.h5 --quiet "${common[@]}" > /dev/null
"$bin/global_opt" --local local.h5 --visual visual.h5 --directions directions.h5 --vps vps.h5 -o global.h5 \
  "${common[@]}"
"$bin/global_opt" --local local.h5 --visual visual.h5 --directions directions.h5 --no-direction \
  -o global_nodir.h5 "${common[@]}"
"$bin/evaluate" --gt "$data/poses/04.txt" --est odom.h5 --est global_nodir.h5 --est global.h5 \
  --json metrics.json "${common[@]}" > /dev/null
