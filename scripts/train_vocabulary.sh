#!/usr/bin/env bash
# Regenerates the visual loop detector's vocabulary shipped in data/vocabulary (README there):
# renders four simulated training drives (seeds that no evaluation drive of the project uses:
# urban 101, suburban 102, highway 103, loop 104; 400 frames each, images only) and trains
# vocab_train on every 10th image of them (160 images).
#
#   scripts/train_vocabulary.sh [BUILD_DIR] [OUTPUT]
#       default BUILD_DIR: build, OUTPUT: data/vocabulary/orb_sim_k8_l4.h5
#
# The same build gives the same vocabulary bytes (apart from the provenance's time fields).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
output=${2:-data/vocabulary/orb_sim_k8_l4.h5}
[ -f "$build/CMakeCache.txt" ] || { echo "train_vocabulary: $build is not a build folder (cmake -S . -B $build first)" >&2; exit 1; }
cmake --build "$build" -j"$(nproc 2>/dev/null || echo 2)" --target sim_sequence vocab_train > /dev/null
bin=$(cd "$build/bin" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
drives=()
for spec in "urban 101" "suburban 102" "highway 103" "loop 104"; do
  set -- $spec
  echo "train_vocabulary: rendering the $1 drive of seed $2 ..."
  "$bin/sim_sequence" --scenario "$1" --seed "$2" --frames 400 --no-scans --quiet \
    -o "$work/$1$2" > "$work/sim.log" 2>&1 || { cat "$work/sim.log" >&2; exit 1; }
  drives+=(-d "$work/$1$2/sequences/00")
done
mkdir -p "$(dirname "$output")"
"$bin/vocab_train" "${drives[@]}" --every 10 --branching 8 --depth 4 --threads 1 --quiet -o "$output"
echo "train_vocabulary: wrote $output"
