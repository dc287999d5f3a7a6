#!/usr/bin/env bash
# Runs every benchmark program in sequence on a Release build and keeps the raw output in
# out/bench/<name>.txt. BENCHMARKS.md quotes these files. Run it on an otherwise idle machine:
# the numbers are wall-clock medians. usage: scripts/bench.sh [name ...] (default: all)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DPIOLA_BUILD_TESTS=OFF >/dev/null
cmake --build build/release -j "$(nproc)" >/dev/null
mkdir -p out/bench
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(diagonalize material forces step step_phases damping collisions mesh_io mesher render shells contact collision_step plasticity muscle)
for name in "${names[@]}"; do
  exe=build/release/bench_$name
  [ -x "$exe" ] || { echo "bench: no $exe, skipped"; continue; }
  echo "== bench_$name"
  { echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) CPUs";
    "$exe"; } 2>&1 | tee "out/bench/$name.txt"
done
