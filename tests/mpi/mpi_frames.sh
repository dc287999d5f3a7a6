#!/usr/bin/env bash
# Frames of `mpirun -np N piola run` against the single-process run (docs/mpi.md).
#
# usage: mpi_frames.sh PIOLA EXAMPLES_DIR EXAMPLE:FRAMES...
# For each example, runs FRAMES frames (at least 100 steps, checked from stats.csv) without
# mpirun, then with 1, 2 and 4 processes (oversubscribed: this machine has 2 cores). With
# 1 process the frames must be bit-identical (the world is not split); with 2 and 4 each
# frame is a .pvtu of one piece per process, which merged (compare_frames.py reads it with
# VTK and the pieces with meshio) must be the single process's frame with positions equal
# to 1e-9 relative; stats.csv must have the same columns and frames.
set -euo pipefail
piola=$1 examples=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
# OpenMPI refuses to run as root without these; --oversubscribe runs 4 ranks on 2 cores
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1
# in a sanitizer build: OpenMPI does not free its own allocations at exit
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
mpirun=${PIOLA_MPIEXEC:-mpirun}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
for item in "$@"; do
  ex=${item%%:*} frames=${item##*:}
  scene=$examples/$ex.json
  single=$work/$ex-single
  "$piola" run "$scene" -o "$single" --frames "$frames" --threads 1 >/dev/null 2>"$work/log" ||
    { cat "$work/log"; echo "FAIL $ex: single-process run"; fail=1; continue; }
  steps=$(awk -F, 'NR > 1 { s += $3 } END { print s }' "$single/stats.csv")
  if [ "$steps" -lt 100 ]; then
    echo "FAIL $ex: only $steps steps in $frames frames (the check needs >= 100)"; fail=1; continue
  fi
  for np in 1 2 4; do
    out=$work/$ex-np$np
    if ! "$mpirun" --oversubscribe -np "$np" "$piola" run "$scene" -o "$out" --frames "$frames" \
         --threads 1 >/dev/null 2>"$work/log"; then
      cat "$work/log"; echo "FAIL $ex: mpirun -np $np"; fail=1; continue
    fi
    if [ "$np" = 1 ]; then
      for f in $(cd "$single" && find frames surface -type f | sort); do
        cmp -s "$single/$f" "$out/$f" || { echo "FAIL $ex -np 1: $f differs"; fail=1; }
      done
      echo "ok $ex -np 1: $steps steps, frames bit-identical"
      continue
    fi
    # stats.csv: same header and rows (frame, time, substeps); numbers compared loosely
    if ! diff <(cut -d, -f1-3 "$single/stats.csv") <(cut -d, -f1-3 "$out/stats.csv") >/dev/null; then
      echo "FAIL $ex -np $np: stats.csv frames, times or substeps differ"; fail=1
    fi
    if result=$(/usr/bin/python3 "$here/compare_frames.py" "$single" "$out" 1e-9 "$np"); then
      echo "ok $ex -np $np: $steps steps, $result"
    else
      echo "FAIL $ex -np $np: $result"; fail=1
    fi
  done
done
exit $fail
