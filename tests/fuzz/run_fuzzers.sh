#!/usr/bin/env bash
# Fuzzes every reader for a bounded time (tests/fuzz/README.md).
#   tests/fuzz/run_fuzzers.sh FUZZER SEEDS_DIR SECONDS_PER_READER [CORPUS_DIR]
# FUZZER: the sanitized reader_fuzzer; SEEDS_DIR: `uwscan bench robustness --write-seeds DIR`.
# A crash, a leak or a hang (a single input running past 10 s) fails the run; libFuzzer keeps
# the input as crash-*/leak-*/timeout-* in the corpus folder: copy it into
# tests/fuzz/regressions/READER/ so that it stays a test.
set -euo pipefail
fuzzer=$1 seeds=$2 seconds=$3
corpus=${4:-$(mktemp -d)}
readers=$(ls "$seeds")
status=0
skipped=$(grep -v '^#' "$(dirname "$0")/fuzz_skip.txt" | grep -v '^$' || true)
for reader in $readers; do
  if grep -qx "$reader" <<<"$skipped"; then
    echo "fuzz: $reader skipped (tests/fuzz/fuzz_skip.txt)" >&2
    continue
  fi
  mkdir -p "$corpus/$reader"
  regressions="$(dirname "$0")/regressions/$reader"
  extra=()
  [ -d "$regressions" ] && extra+=("$regressions")
  echo "fuzz: $reader for ${seconds}s" >&2
  if ! UWSCAN_FUZZ_READER=$reader "$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -seed=1 \
        -artifact_prefix="$corpus/$reader/" -print_final_stats=1 \
        "$corpus/$reader" "$seeds/$reader" "${extra[@]}" >"$corpus/$reader.log" 2>&1; then
    echo "fuzz: $reader FAILED (log: $corpus/$reader.log)" >&2
    tail -40 "$corpus/$reader.log" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$corpus/$reader.log" | tail -2 | tr '\n' ' ' >&2
    echo >&2
  fi
done
exit $status
