#!/usr/bin/env bash
# End to end: loop closing on a short simulated revisit. Renders the loop route (seed 21) up to
# frame 780, where the second circuit of the block has run about 80 m over the first, runs
# loop_detect on the ground-truth path with each detector alone (visual, LiDAR, proximity) and
# with the three together (the default: each later detector verifies only the queries left
# open), and requires each run to accept at least 5 loops, every one of them right against the
# ground truth (1 m, 2 deg), and its --report to give the log's figures.
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
status=0
for run in visual:visual lidar:LiDAR proximity:proximity visual,lidar,proximity:combined; do
  detectors=${run%%:*}
  label=${run#*:}
  log="$out/loop_detect_$label.log"
  "$bin/loop_detect" -d "$seq" --poses "$gt" --gt "$gt" -o "$out/loops_$label.h5" \
    --csv "$out/loops_$label.csv" --report "$out/report_$label.json" --detectors "$detectors" \
    --threads 2 --quiet > "$log" 2>&1 || { cat "$log"; exit 1; }
  grep "against --gt, $label:" "$log" || true
  line=$(grep -oE "against --gt, $label: [0-9]+ accepted loops, [0-9]+ right" "$log" || true)
  accepted=$(echo "$line" | grep -oE "[0-9]+ accepted" | grep -oE "[0-9]+" || echo 0)
  right=$(echo "$line" | grep -oE "[0-9]+ right" | grep -oE "[0-9]+" || echo 0)
  # --report holds the figures of the log line (its last entry: this run's label).
  if command -v python3 > /dev/null; then
    reported=$(python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))["detectors"][-1]
print(d["detector"], d["accepted"], d["right"])' "$out/report_$label.json")
    if [ "$reported" != "$label $accepted $right" ]; then
      echo "loop_closing: --report gives '$reported', the log '$label $accepted $right'" >&2
      status=1
    fi
  fi
  if [ -z "$line" ] || [ "$accepted" -lt 5 ] || [ "$accepted" -ne "$right" ]; then
    echo "loop_closing: $label accepted ${accepted:-0} loops, ${right:-0} right (want >= 5, all right)" >&2
    status=1
  else
    echo "loop_closing: $label accepted $accepted loops, all right"
  fi
done
# --report without --gt is refused before anything is read or written.
if "$bin/loop_detect" -d "$seq" --poses "$gt" -o "$out/refused.h5" --report "$out/refused.json" \
    --quiet > "$out/refused.log" 2>&1 || ! grep -q -- "--report needs --gt" "$out/refused.log" ||
    [ -e "$out/refused.h5" ] || [ -e "$out/refused.json" ]; then
  echo "loop_closing: --report without --gt was not refused as expected:" >&2
  cat "$out/refused.log" >&2
  status=1
fi
# The default run closes exactly the queries the detectors close alone: a later detector skips
# only the queries closed already, and its open queries come out as when it runs alone.
accepted_queries() { awk -F, 'NR > 1 && $4 == 0 { print $1 }' "$@" | sort -un; }
union=$(accepted_queries "$out/loops_visual.csv" "$out/loops_LiDAR.csv" "$out/loops_proximity.csv")
combined=$(accepted_queries "$out/loops_combined.csv")
if [ "$union" != "$combined" ]; then
  echo "loop_closing: the default run closed other queries than the detectors alone:" >&2
  diff <(echo "$union") <(echo "$combined") >&2 || true
  status=1
else
  echo "loop_closing: the default run closes the $(echo "$combined" | wc -l) queries the detectors close alone"
fi
exit $status
