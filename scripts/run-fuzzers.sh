#!/usr/bin/env bash
# Runs every built libFuzzer target for a fixed time over its seed corpus.
# usage: run-fuzzers.sh BUILD_DIR SECONDS
set -euo pipefail
build=$1; seconds=$2
root="$(cd "$(dirname "$0")/.." && pwd)"
status=0
for fuzzer in "$build"/fuzz_*; do
  [ -x "$fuzzer" ] || continue
  name=$(basename "$fuzzer")
  seeds="$root/fuzz/corpus/${name#fuzz_}"
  work=$(mktemp -d)
  [ -d "$seeds" ] && cp -r "$seeds"/. "$work"/ 2>/dev/null || true
  "$root/fuzz/seed_from_data.sh" "${name#fuzz_}" "$work" 2>/dev/null || true
  echo "fuzz: $name for ${seconds}s over $(ls "$work" | wc -l) seeds"
  if ! "$fuzzer" -max_total_time="$seconds" -rss_limit_mb=2048 -max_len=65536 \
       -print_final_stats=0 "$work" > "$build/$name.log" 2>&1; then
    echo "fuzz: $name FAILED, see $build/$name.log"; tail -40 "$build/$name.log"; status=1
  fi
  rm -rf "$work"
done
exit $status
