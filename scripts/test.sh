#!/usr/bin/env bash
# Installs dependencies (if missing), builds with warnings as errors and runs every test.
# This is the README's test command and what CI runs (.ci/run). Two builds:
#   1. BUILD_DIR (Release, GCC): everything, every CTest entry.
#   2. SANITIZE_BUILD_DIR (Clang 14, AddressSanitizer + UndefinedBehaviorSanitizer, libFuzzer
#      instrumentation): the unit tests of the libraries that parse input and do not need Ceres
#      (core, geometry, io, app, eval, direction), then every fuzz target for JVL_FUZZ_SECONDS
#      from its committed seed corpus. See docs/robustness.md for the choice and the timings.
# Environment:
#   BUILD_DIR           build folder (default: build)
#   SANITIZE_BUILD_DIR  sanitizer + fuzz build folder (default: build-sanitize)
#   JVL_WERROR          ON/OFF (default: ON)
#   JVL_SANITIZE_CI     ON/OFF: run the second build (default: ON)
#   JVL_FUZZ_SECONDS    seconds per fuzz target (default: 15)
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install_deps.sh

build_dir=${BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DJVL_BUILD_TESTS=ON \
  -DJVL_WERROR="${JVL_WERROR:-ON}"
cmake --build "$build_dir" -j"$jobs"
ctest --test-dir "$build_dir" --output-on-failure -j"$jobs"
echo "test.sh: release build and tests took $(( $(date +%s) - start )) s"
# A build without the tests (-DJVL_BUILD_TESTS=OFF) must configure as well (no build: same code).
cmake -S . -B "$build_dir-notests" -DCMAKE_BUILD_TYPE=Release -DJVL_BUILD_TESTS=OFF >/dev/null
echo "test.sh: configuration with JVL_BUILD_TESTS=OFF passed"

if [ "${JVL_SANITIZE_CI:-ON}" = ON ]; then
  start=$(date +%s)
  san_dir=${SANITIZE_BUILD_DIR:-build-sanitize}
  san_tests=(core_test geometry_test io_test app_test eval_test direction_test)
  fuzzers=(calib_fuzzer times_fuzzer trajectory_fuzzer velodyne_fuzzer artifact_fuzzer)
  # -O1 and line tables only: sanitizer reports with file:line at a fraction of -g's build time.
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$san_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DJVL_SANITIZE=ON -DJVL_FUZZ=ON -DJVL_FUZZ_SECONDS="${JVL_FUZZ_SECONDS:-15}" \
    -DJVL_WERROR="${JVL_WERROR:-ON}"
  cmake --build "$san_dir" -j"$jobs" --target "${san_tests[@]}" "${fuzzers[@]}"
  regex="^($(IFS='|'; echo "${san_tests[*]}"))\$"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir "$san_dir" --output-on-failure -j"$jobs" -R "$regex"
  ctest --test-dir "$san_dir" --output-on-failure -j"$jobs" -L fuzz
  echo "test.sh: sanitizer build, unit tests and fuzzing took $(( $(date +%s) - start )) s"
fi
