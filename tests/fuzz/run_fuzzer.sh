#!/usr/bin/env bash
# Fuzzes one target for a fixed time from its committed seed corpus; new inputs go to a scratch
# corpus under WORK_DIR (cleared first), crashes to WORK_DIR/crash-*. Prints libFuzzer's summary.
#
#   run_fuzzer.sh FUZZER SEED_CORPUS WORK_DIR SECONDS [LIBFUZZER_FLAGS...]
set -euo pipefail
fuzzer=$1 seeds=$2 work=$3 seconds=$4
shift 4
rm -rf "$work"
mkdir -p "$work/corpus"
# -seed=1: the same mutations on every run; -timeout: a single input taking 10 s is a hang.
"$fuzzer" -seed=1 -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$work/" "$@" "$work/corpus" "$seeds" 2> "$work/log.txt" || {
  tail -n 60 "$work/log.txt"
  exit 1
}
grep -E "^(Done|stat::average_exec_per_sec|stat::peak_rss_mb|#[0-9]+ +DONE)" "$work/log.txt" || true
echo "corpus: $(ls "$seeds" | wc -l) seeds, $(ls "$work/corpus" | wc -l) new inputs"
