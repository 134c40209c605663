#!/usr/bin/env bash
# Every stage on a short synthetic sequence, the way pipelines/demo chains them plus lidar_odom,
# with a fixed thread count: the fixture of the determinism test and of the sim golden files.
# Paths inside OUT are relative, so that the provenance (options and input paths) of two runs in
# different folders is the same and the artifacts compare as equal.
#
#   tests/robustness/pipeline.sh BIN_DIR OUT_DIR THREADS [FRAMES] [LAYOUT] [CAMERA]
#
# LAYOUT: kitti (default), kitti360 or oxford (the same drive written in the KITTI-360 or the
# Oxford RobotCar layout; the ground truth comes from dataset_info --write-gt).
# CAMERA: the camera rendered and used by the image stages (default 0; kitti layout: 2 is the
# left colour camera, 6 cm beside camera 0).
set -euo pipefail

bin=$(cd "$1" && pwd)
out=$2
threads=$3
frames=${4:-40}
layout=${5:-kitti}
camera=${6:-0}
cam=() render=()
[[ $camera == 0 ]] || cam=(--camera "$camera") render=(--cameras "$camera")

rm -rf "$out"
mkdir -p "$out"
cd "$out"
common=(--threads "$threads" --log-level warn)
"$bin/sim_sequence" -o data --sequence 00 --seed 1 --frames "$frames" --layout "$layout" --quiet \
  "${render[@]}" "${common[@]}"
if [[ $layout != kitti ]]; then
  if [[ $layout == kitti360 ]]; then seq=data/data_3d_raw/sim_drive_0000_sync; else seq=data/sim-oxford-00; fi
  gt=gt.txt
  "$bin/dataset_info" --dataset "$seq" --write-gt "$gt" --quiet "${common[@]}" > /dev/null
else
  seq=data/sequences/00
  gt=data/poses/00.txt
fi
"$bin/make_prior" -g "$gt" -o prior.h5 --preset lidar-n1 --seed 1 "${common[@]}"
"$bin/lidar_odom" --dataset "$seq" -o odom.h5 --kitti-poses odom.txt --quiet "${common[@]}"
"$bin/vp_detect" --dataset "$seq" -o vps.h5 --csv vps.csv --quiet "${cam[@]}" "${common[@]}"
"$bin/direction_cluster" --vps vps.h5 --prior prior.h5 -o directions.h5 --csv directions.csv \
  "${common[@]}"
"$bin/visual_assoc" --dataset "$seq" --prior prior.h5 --directions directions.h5 -o visual.h5 \
  --quiet "${cam[@]}" "${common[@]}" > /dev/null
# Distances of the map points to the simulated surfaces (checks that the tool accepts the
# stages' artifacts of a simulated sequence; the prior's pose errors are part of the figures).
"$bin/sim_map_check" --sequence "$seq" --visual visual.h5 --json map_check.json \
  "${common[@]}" > /dev/null
# The same with the ground truth as the prior: the map's accuracy without the prior's errors
# (where a camera's offset from camera 0 would show).
"$bin/visual_assoc" --dataset "$seq" --prior "$gt" -o visual_gt.h5 --quiet "${cam[@]}" \
  "${common[@]}" > /dev/null
"$bin/sim_map_check" --sequence "$seq" --visual visual_gt.h5 --json map_check_gt.json \
  "${common[@]}" > /dev/null
"$bin/local_map" --visual visual.h5 --dataset "$seq" -o local.h5 --kitti-poses local.txt --quiet \
  "${common[@]}" > /dev/null
"$bin/global_opt" --local local.h5 --visual visual.h5 --directions directions.h5 --vps vps.h5 -o global.h5 \
  --kitti-poses global.txt --map map.ply "${common[@]}"
"$bin/global_opt" --local local.h5 --visual visual.h5 --directions directions.h5 --no-direction \
  -o global_nodir.h5 "${common[@]}"
"$bin/evaluate" --gt "$gt" --est prior.h5 --est odom.h5 --est global_nodir.h5 \
  --est global.h5 --align se3 --json metrics.json --markdown metrics.md "${common[@]}" > /dev/null
