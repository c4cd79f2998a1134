#!/usr/bin/env bash
# Runs each libFuzzer target of fuzz/ for a set time: run-fuzzers.sh BUILD_DIR SECONDS.
# Each starts from the committed seed corpus (fuzz/corpus/TARGET, read only) plus what earlier runs
# collected in BUILD_DIR/corpus/TARGET; a failing input is written to BUILD_DIR/artifacts/ and the
# script exits non-zero. The last lines of each run (executions, coverage) are printed.
set -euo pipefail
build="$1"
seconds="$2"
root="$(cd "$(dirname "$0")/.." && pwd)"
status=0
for target in fuzz_query fuzz_proximity; do
  corpus="$build/corpus/$target"
  artifacts="$build/artifacts/$target/"
  mkdir -p "$corpus" "$artifacts"
  log="$build/$target.log"
  echo "fuzz: $target for ${seconds}s"
  if ! "$build/fuzz/$target" -max_total_time="$seconds" -timeout=60 -rss_limit_mb=4096 \
      -max_len=4096 -print_final_stats=1 -artifact_prefix="$artifacts" \
      "$corpus" "$root/fuzz/corpus/$target" > "$log" 2>&1; then
    echo "fuzz: $target FAILED; input saved in $artifacts, log $log:"
    tail -n 60 "$log"
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb|Done [0-9]+ runs" "$log" || true
  fi
done
exit "$status"
