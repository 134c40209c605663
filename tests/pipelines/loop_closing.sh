#!/usr/bin/env bash
# End to end: loop closing on a short simulated revisit. Renders the loop route (seed 21) up to
# frame 780, where the second circuit of the block has run about 80 m over the first, runs
# loop_detect with both detectors on the ground-truth path, and requires each detector to accept
# at least 5 loops, every one of them right against the ground truth (1 m, 2 deg).
#
#   tests/pipelines/loop_closing.sh BIN_DIR OUT_DIR
set -euo pipefail
bin=$1
out=$2
rm -rf "$out"
mkdir -p "$out"
"$bin/sim_sequence" --scenario loop --laps 2 --seed 21 --frames 780 -o "$out/data" --threads 2 \
  --quiet > "$out/sim.log" 2>&1 || { cat "$out/sim.log"; exit 1; }
seq="$out/data/sequences/00"
gt="$out/data/poses/00.txt"
"$bin/loop_detect" -d "$seq" --poses "$gt" --gt "$gt" -o "$out/loops.h5" --csv "$out/loops.csv" \
  --threads 2 --quiet > "$out/loop_detect.log" 2>&1 || { cat "$out/loop_detect.log"; exit 1; }
cat "$out/loop_detect.log"
status=0
for detector in LiDAR visual; do
  line=$(grep -oE "against --gt, $detector: [0-9]+ accepted loops, [0-9]+ right" "$out/loop_detect.log" || true)
  accepted=$(echo "$line" | grep -oE "[0-9]+ accepted" | grep -oE "[0-9]+" || echo 0)
  right=$(echo "$line" | grep -oE "[0-9]+ right" | grep -oE "[0-9]+" || echo 0)
  if [ -z "$line" ] || [ "$accepted" -lt 5 ] || [ "$accepted" -ne "$right" ]; then
    echo "loop_closing: the $detector detector accepted ${accepted:-0} loops, ${right:-0} right (want >= 5, all right)" >&2
    status=1
  else
    echo "loop_closing: the $detector detector accepted $accepted loops, all right"
  fi
done
exit $status
