#!/usr/bin/env bash
# Times the whole chain on one drive, stage by stage, in the paper's configuration (this
# project's lidar_odom with N = 1 as the prior): lidar_odom -> vp_detect -> direction_cluster ->
# visual_assoc -> local_map -> global_opt -> evaluate. Writes OUT/bench.md and OUT/bench.json
# with each stage's wall and CPU time, peak memory (RSS) and throughput (frames or keyframes per
# second, milliseconds per item), the total, and the drive's sensor time (its timestamps).
#
#   scripts/bench_chain.sh DATASET OUT [GT]
#
# DATASET: a sequence folder the tools read (KITTI odometry, raw, KITTI-360, Oxford, a
# sim_sequence drive: OUT_SIM/sequences/00). GT: ground truth for evaluate (default: the
# dataset's own, written by dataset_info --write-gt; none: evaluation skipped).
# Environment: JVL_BIN (default build/bin), THREADS (default 2), FRAMES (A:B, default all),
# PYTHON (default python3).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
bin=${JVL_BIN:-$root/build/bin}
threads=${THREADS:-2}
frames=${FRAMES:-}
python=${PYTHON:-python3}
if [ $# -lt 2 ]; then
  sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
dataset=$1
out=$2
gt=${3:-}
[ -d "$dataset" ] || { echo "bench_chain: $dataset is not a folder" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "bench_chain: /usr/bin/time (GNU time) is needed" >&2; exit 1; }
for tool in dataset_info lidar_odom vp_detect direction_cluster visual_assoc local_map global_opt evaluate; do
  [ -x "$bin/$tool" ] || { echo "bench_chain: $bin/$tool not found: build first" >&2; exit 1; }
done
mkdir -p "$out"
out=$(cd "$out" && pwd)
range=()
[ -z "$frames" ] || range=(--frames "$frames")
common=(--threads "$threads" --log-level warn)
: > "$out/bench_times.txt"

# run NAME CMD...: one stage under GNU time (wall s, user s, system s, peak RSS KiB).
run() {
  local name=$1; shift
  echo "== $name" >&2
  /usr/bin/time -f "$name %e %U %S %M" -a -o "$out/bench_times.txt" "$@" "${common[@]}" \
    > "$out/$name.log"
  tail -n 1 "$out/bench_times.txt" | awk '{printf "   %s s wall, %.1f s CPU, %.0f MiB\n", $2, $3 + $4, $5 / 1024}' >&2
}

if [ -z "$gt" ]; then
  "$bin/dataset_info" --dataset "$dataset" "${range[@]}" --write-gt "$out/gt.txt" --quiet \
    "${common[@]}" > "$out/dataset_info.txt" 2>&1 || true
  [ -s "$out/gt.txt" ] && gt=$out/gt.txt
elif [ "$gt" = none ]; then
  gt=
fi
"$bin/dataset_info" --dataset "$dataset" "${range[@]}" --quiet "${common[@]}" \
  > "$out/dataset_info.txt"

run lidar_odom "$bin/lidar_odom" --dataset "$dataset" "${range[@]}" --scan-map-size 1 \
  -o "$out/prior.h5" --kitti-poses "$out/prior.txt" --quiet
run vp_detect "$bin/vp_detect" --dataset "$dataset" "${range[@]}" -o "$out/vps.h5" --quiet
run direction_cluster "$bin/direction_cluster" --vps "$out/vps.h5" --prior "$out/prior.h5" \
  -o "$out/directions.h5"
run visual_assoc "$bin/visual_assoc" --dataset "$dataset" "${range[@]}" --prior "$out/prior.h5" \
  --directions "$out/directions.h5" -o "$out/visual.h5" --quiet
run local_map "$bin/local_map" --visual "$out/visual.h5" --dataset "$dataset" \
  -o "$out/local.h5" --kitti-poses "$out/local.txt" --quiet
run global_opt "$bin/global_opt" --local "$out/local.h5" --visual "$out/visual.h5" \
  --directions "$out/directions.h5" --vps "$out/vps.h5" -o "$out/global.h5" \
  --kitti-poses "$out/global.txt"
if [ -n "$gt" ]; then
  run evaluate "$bin/evaluate" --gt "$gt" --est "$out/prior.h5" "$out/global.h5" \
    --label prior global --align se3 --json "$out/metrics.json" --markdown "$out/metrics.md"
fi

"$python" - "$out" "$dataset" "$threads" <<'EOF'
import json, os, re, sys

out, dataset, threads = sys.argv[1], sys.argv[2], int(sys.argv[3])
frames = sum(1 for line in open(os.path.join(out, "prior.txt")) if line.strip())
keyframes = sum(1 for line in open(os.path.join(out, "local.txt")) if line.strip())
info = open(os.path.join(out, "dataset_info.txt")).read()
m = re.search(r"frames\s+\d+ \(\d+\.\.\d+\), ([0-9.]+) s", info)
span = float(m.group(1)) if m else None
# Sensor time: the timestamps' span plus one frame period.
sensor_s = span * frames / (frames - 1) if span and frames > 1 else None
per = {"lidar_odom": ("frames", frames), "vp_detect": ("frames", frames),
       "direction_cluster": ("frames", frames), "visual_assoc": ("frames", frames),
       "local_map": ("keyframes", keyframes), "global_opt": ("keyframes", keyframes),
       "evaluate": ("frames", frames)}
stages = []
for line in open(os.path.join(out, "bench_times.txt")):
    name, wall, user, system, rss = line.split()
    unit, n = per[name]
    wall, cpu = float(wall), float(user) + float(system)
    stages.append({"stage": name, "wall_s": wall, "cpu_s": round(cpu, 2),
                   "peak_rss_mib": round(int(rss) / 1024.0, 1), "unit": unit, "items": n,
                   "items_per_s": round(n / wall, 2) if wall > 0 else None,
                   "ms_per_item": round(1e3 * wall / n, 2) if n else None})
total = {"wall_s": round(sum(s["wall_s"] for s in stages), 2),
         "cpu_s": round(sum(s["cpu_s"] for s in stages), 2),
         "peak_rss_mib": max(s["peak_rss_mib"] for s in stages)}
result = {"dataset": dataset, "threads": threads, "frames": frames, "keyframes": keyframes,
          "sensor_time_s": round(sensor_s, 2) if sensor_s else None, "stages": stages,
          "total": total,
          "times_sensor_time": round(total["wall_s"] / sensor_s, 3) if sensor_s else None}
metrics = os.path.join(out, "metrics.json")
if os.path.exists(metrics):
    m = json.load(open(metrics))
    result["ape_m"] = {e["label"]: e["ape"]["translation_m"]["rmse"] for e in m["estimates"]}
with open(os.path.join(out, "bench.json.tmp"), "w") as f:
    json.dump(result, f, indent=2)
    f.write("\n")
os.replace(os.path.join(out, "bench.json.tmp"), os.path.join(out, "bench.json"))
rows = ["| stage | wall (s) | CPU (s) | peak RSS (MiB) | items | per s | ms per item |",
        "|---|---:|---:|---:|---:|---:|---:|"]
for s in stages:
    rows.append("| {} | {:.2f} | {:.2f} | {:.0f} | {} {} | {:.1f} | {:.1f} |".format(
        s["stage"], s["wall_s"], s["cpu_s"], s["peak_rss_mib"], s["items"], s["unit"],
        s["items_per_s"] or 0, s["ms_per_item"] or 0))
rows.append("| **total** | **{:.2f}** | {:.2f} | {:.0f} | | | |".format(
    total["wall_s"], total["cpu_s"], total["peak_rss_mib"]))
text = "# Chain timing\n\n{}: {} frames, {} keyframes, {} threads".format(
    dataset, frames, keyframes, threads)
if sensor_s:
    text += "; sensor time {:.1f} s, chain {:.2f}x sensor time".format(
        sensor_s, result["times_sensor_time"])
text += "\n\n" + "\n".join(rows) + "\n"
if "ape_m" in result:
    text += "\nAPE (SE(3)-aligned, m): " + ", ".join(
        "{} {:.4f}".format(k, v) for k, v in result["ape_m"].items()) + "\n"
with open(os.path.join(out, "bench.md.tmp"), "w") as f:
    f.write(text)
os.replace(os.path.join(out, "bench.md.tmp"), os.path.join(out, "bench.md"))
print(text, end="")
EOF
