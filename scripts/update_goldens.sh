#!/usr/bin/env bash
# Regenerates every golden file (tests/golden/data) from the current code and prints which ones
# changed and by how much. Use it after a change that is meant to move a stage's output; commit
# the golden files with a message that says why they moved (tests/golden/README.md).
#
#   scripts/update_goldens.sh [BUILD_DIR]        default BUILD_DIR: build
#
# Runs the two fixtures with one thread (the synthetic chain, tests/robustness/pipeline.sh, and
# the KITTI excerpt chain, tests/golden/kitti_chain.sh; the latter is skipped without ../shared,
# leaving the KITTI goldens as they are).
set -euo pipefail
cd "$(dirname "$0")/.."

build=${1:-build}
[ -f "$build/CMakeCache.txt" ] || { echo "update_goldens: $build is not a build folder (cmake -S . -B $build first)" >&2; exit 1; }
cmake --build "$build" -j"$(nproc 2>/dev/null || echo 2)" --target golden sim_sequence sim_map_check make_prior \
  lidar_odom vp_detect direction_cluster visual_assoc local_map global_opt evaluate > /dev/null
bin=$(cd "$build/bin" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

run() {  # fixture, command...: its output is shown only if it fails
  local fixture=$1; shift
  echo "update_goldens: running the $fixture chain ..."
  "$@" > "$work/$fixture.log" 2>&1 || {
    cat "$work/$fixture.log" >&2
    echo "update_goldens: the $fixture chain failed" >&2
    exit 1
  }
}
run sim tests/robustness/pipeline.sh "$bin" "$work/sim" 1 40
run kitti tests/golden/kitti_chain.sh "$bin" "$work/kitti" 1

written=0
while read -r stage fixture artifact golden; do
  [[ -z "$stage" || "$stage" == \#* ]] && continue
  dir=$work/$fixture
  if [ -e "$dir/SKIPPED" ]; then
    echo "  skipped  $golden (no ../shared/data: kept as it is)"
    continue
  fi
  target=tests/golden/data/$golden
  mkdir -p "$(dirname "$target")"
  "$bin/golden" digest "$dir/$artifact" "$artifact" "$work/new.json"
  if [ -e "$target" ] && cmp -s "$target" "$work/new.json"; then
    echo "  same     $golden ($stage)"
    continue
  fi
  if [ -e "$target" ]; then
    moved=$("$bin/golden" diff "$target" "$work/new.json" tests/golden/tolerances.json)
    if [ -z "$moved" ]; then
      echo "  changed  $golden ($stage): within the tolerances"
    else
      echo "  changed  $golden ($stage), beyond the tolerances in:"
      echo "$moved"
    fi
  else
    echo "  new      $golden ($stage)"
  fi
  cp "$work/new.json" "$target"
  written=$((written + 1))
done < tests/golden/goldens.txt
echo "update_goldens: $written golden file(s) written$([ "$written" -gt 0 ] && echo "; say why in the commit message")"
