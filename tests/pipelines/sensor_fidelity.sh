#!/bin/sh
# The simulator's fidelity table on a short drive (docs/sim.md "Fidelity table"): sensor_stats on
# the robustness chain's 40-frame synthetic drive and on the real KITTI 04 excerpt, side by side
# by scripts/sensor_fidelity.py. The real side is skipped, with a message, without ../shared.
#   sensor_fidelity.sh BIN_DIR SIM_SEQUENCE OUT_DIR
set -eu
bin=$1
sim=$2
out=$3
root=$(cd "$(dirname "$0")/../.." && pwd)
real="$root/../shared/data/kitti_odometry_04_f0-50/sequences/04"
mkdir -p "$out"
"$bin/sensor_stats" -d "$sim" -o "$out/sim.json" --quiet
if [ -d "$real" ]; then
  "$bin/sensor_stats" -d "$real" -o "$out/kitti04.json" --quiet
  reference="KITTI-04=$out/kitti04.json"
else
  echo "sensor_fidelity: ../shared/data/kitti_odometry_04_f0-50 not found, the real side is" \
       "skipped (the simulated drive is compared with itself)"
  reference="sim-again=$out/sim.json"
fi
python3 "$root/scripts/sensor_fidelity.py" --markdown "$out/table.md" "$reference" \
  "sim=$out/sim.json"
for row in "scan points" "scan scattered" "scan vertical_planar" "image fast_corners" \
           "outside the band"; do
  grep -q "^| $row |" "$out/table.md" || { echo "sensor_fidelity: no row '$row'" >&2; exit 1; }
done
