#!/bin/sh
# The simulator's fidelity table on a short drive (docs/sim.md "Fidelity table"): sensor_stats on
# the robustness chain's 40-frame synthetic drive and on the real KITTI 04 excerpt, side by side
# by scripts/sensor_fidelity.py, with what the stages see on both (lidar_odom's frame-to-frame
# error and drift, vp_detect's forward VP, visual_assoc's map: the robustness chain's artifacts
# on the simulated side, the same stages run here on the real one). The real side is skipped,
# with a message, without ../shared.
#   sensor_fidelity.sh BIN_DIR SIM_SEQUENCE OUT_DIR [SIM_RUN_DIR]
# SIM_RUN_DIR holds the simulated drive's odom.h5, vps.h5 and visual.h5 (default: the folder
# two levels above SIM_SEQUENCE's data/sequences/NN).
set -eu
bin=$1
sim=$2
out=$3
run=${4:-$(cd "$sim/../../.." && pwd)}
root=$(cd "$(dirname "$0")/../.." && pwd)
real="$root/../shared/data/kitti_odometry_04_f0-50/sequences/04"
mkdir -p "$out"
"$bin/sensor_stats" -d "$sim" -o "$out/sim.json" --quiet --odometry "$run/odom.h5" \
  --vps "$run/vps.h5" --visual "$run/visual.h5"
if [ -d "$real" ]; then
  k="$out/kitti04"
  mkdir -p "$k"
  # The stages as the chain runs them on a drive: lidar_odom N = 1 is the prior of visual_assoc.
  "$bin/lidar_odom" --dataset "$real" --scan-map-size 1 -o "$k/odom.h5" --quiet
  "$bin/vp_detect" --dataset "$real" -o "$k/vps.h5" --quiet
  "$bin/direction_cluster" --vps "$k/vps.h5" --prior "$k/odom.h5" -o "$k/directions.h5" --quiet
  "$bin/visual_assoc" --dataset "$real" --prior "$k/odom.h5" --directions "$k/directions.h5" \
    -o "$k/visual.h5" --quiet > /dev/null
  "$bin/sensor_stats" -d "$real" -o "$out/kitti04.json" --quiet --odometry "$k/odom.h5" \
    --vps "$k/vps.h5" --visual "$k/visual.h5"
  reference="KITTI-04=$out/kitti04.json"
else
  echo "sensor_fidelity: ../shared/data/kitti_odometry_04_f0-50 not found, the real side is" \
       "skipped (the simulated drive is compared with itself)"
  reference="sim-again=$out/sim.json"
fi
python3 "$root/scripts/sensor_fidelity.py" --markdown "$out/table.md" "$reference" \
  "sim=$out/sim.json"
for row in "scan points" "scan scattered" "scan vertical_planar" "image fast_corners" \
           "stages odom_rpe_m_mean" "stages odom_drift_percent" "stages vp_forward_found_mean" \
           "stages vp_forward_error_deg_p90" "stages visual_reprojection_px" "outside the band"; do
  grep -q "^| $row |" "$out/table.md" || { echo "sensor_fidelity: no row '$row'" >&2; exit 1; }
done
