#!/usr/bin/env bash
# Runs every built libFuzzer target for a fixed time over its seed corpus, JOBS at a time
# (default 1); each fuzzer gets the full time whatever JOBS is.
# usage: run-fuzzers.sh BUILD_DIR SECONDS [JOBS]
set -euo pipefail
build=$1; seconds=$2; jobs=${3:-1}
root="$(cd "$(dirname "$0")/.." && pwd)"

# fuzz_one FUZZER: fuzzes one target over a fresh copy of its seeds; non-zero on a finding
fuzz_one() {
  local fuzzer=$1 name work status=0
  name=$(basename "$fuzzer")
  work=$(mktemp -d)
  local seeds="$root/fuzz/corpus/${name#fuzz_}"
  [ -d "$seeds" ] && cp -r "$seeds"/. "$work"/ 2>/dev/null || true
  "$root/fuzz/seed_from_data.sh" "${name#fuzz_}" "$work" 2>/dev/null || true
  echo "fuzz: $name for ${seconds}s over $(ls "$work" | wc -l) seeds"
  if ! "$fuzzer" -max_total_time="$seconds" -rss_limit_mb=2048 -max_len=65536 \
       -print_final_stats=0 "$work" > "$build/$name.log" 2>&1; then
    echo "fuzz: $name FAILED, see $build/$name.log"; tail -40 "$build/$name.log"; status=1
  fi
  rm -rf "$work"
  return $status
}

status=0
running=()
for fuzzer in "$build"/fuzz_*; do
  [ -x "$fuzzer" ] || continue
  fuzz_one "$fuzzer" &
  running+=($!)
  if [ ${#running[@]} -ge "$jobs" ]; then
    for pid in "${running[@]}"; do wait "$pid" || status=1; done
    running=()
  fi
done
for pid in "${running[@]}"; do wait "$pid" || status=1; done
exit $status
