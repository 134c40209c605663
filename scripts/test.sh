#!/usr/bin/env bash
# Installs dependencies (if missing), builds with warnings as errors and runs every test.
# This is the README's test command and what CI runs (.ci/run).
#   BUILD_DIR   build folder (default: build)
#   JVL_WERROR  ON/OFF (default: ON)
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install_deps.sh

build_dir=${BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DJVL_BUILD_TESTS=ON \
  -DJVL_WERROR="${JVL_WERROR:-ON}"
cmake --build "$build_dir" -j"$jobs"
ctest --test-dir "$build_dir" --output-on-failure -j"$jobs"
