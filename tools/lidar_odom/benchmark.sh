#!/usr/bin/env bash
# Speed and memory of lidar_odom on real KITTI scans, default options.
#
#   tools/lidar_odom/benchmark.sh [BUILD_DIR] [THREADS] [DATASET_DIR]
#
# Prints lidar_odom's per-scan summary (median / p95 / max of diagnostics/time_ms: everything
# per scan except reading the file) and /usr/bin/time's wall time and peak resident memory.
# Run it on an otherwise idle machine: the figures are wall-clock.
set -euo pipefail
here="$(cd "$(dirname "$0")/../.." && pwd)"
build="${1:-$here/build}"
threads="${2:-2}"
dataset="${3:-$here/../shared/data/kitti_odometry_04_f0-50/sequences/04}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
if [[ ! -d "$dataset" ]]; then
  echo "benchmark.sh: dataset $dataset not found" >&2
  exit 1
fi
/usr/bin/time -v "$build/bin/lidar_odom" --dataset "$dataset" -o "$out/odom.h5" \
  --threads "$threads" --quiet 2> "$out/log" || { cat "$out/log" >&2; exit 1; }
grep -E "frames; per scan" "$out/log"
grep -E "Elapsed \(wall clock\)|Maximum resident set size|User time|Percent of CPU" "$out/log"
