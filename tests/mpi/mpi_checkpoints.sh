#!/usr/bin/env bash
# Checkpoints of a split run (docs/mpi.md, "Checkpoints"): `mpirun -np 2 piola run` killed
# (SIGKILL, PIOLA_FAULT_KILL_AT_RENAME) at a rename of a piece, a frame's index, a
# process's checkpoint file or the manifest, then continued with --resume on 2 processes,
# must write frames (every .pvtu, piece and OBJ), sim.pvd and stats.csv (but its
# wall_seconds column) byte-identical to the run that was never stopped. A resume on another
# process count, or without mpirun, is refused with exit code 2 and a message naming the
# count to use; a split resume of a single process's folder likewise.
#
# usage: mpi_checkpoints.sh PIOLA EXAMPLES_DIR
set -uo pipefail
piola=$1 examples=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_mpi_yield_when_idle=1
# in a sanitizer build: OpenMPI does not free its own allocations at exit
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
mpirun=${PIOLA_MPIEXEC:-mpirun}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
scene=$examples/ball_recovers.json # 3 solids in the local mode, inverted starts
frames=4
run() { # run OUT [ARGS...]: the split run under test (mpirun passes PIOLA_FAULT_* with -x)
  local out=$1
  shift
  "$mpirun" --oversubscribe ${PIOLA_FAULT_KILL_AT_RENAME:+-x PIOLA_FAULT_KILL_AT_RENAME} -np 2 "$piola" run "$scene" -o "$out" --frames $frames \
    --checkpoint-every 1 --threads 1 "$@"
}
same_as_reference() { # same_as_reference DIR: byte-identical to the uninterrupted run
  local dir=$1 bad=0 f
  for f in $(cd "$work/ref" && find frames surface -type f | sort) sim.pvd; do
    cmp -s "$work/ref/$f" "$dir/$f" || { echo "  $f differs"; bad=1; }
  done
  [ "$(cd "$dir" && find frames surface -type f | wc -l)" = "$(cd "$work/ref" && find frames surface -type f | wc -l)" ] ||
    { echo "  other frame files than the reference"; bad=1; }
  # stats.csv: every column but wall_seconds (the 9th)
  cmp -s <(cut -d, -f1-8,10- "$work/ref/stats.csv") <(cut -d, -f1-8,10- "$dir/stats.csv") ||
    { echo "  stats.csv differs"; bad=1; }
  return $bad
}

run "$work/ref" >/dev/null 2>"$work/log" || { cat "$work/log"; echo "FAIL: the reference run"; exit 1; }
ls "$work/ref"/checkpoint_0004_p0.bin "$work/ref"/checkpoint_0004_p1.bin "$work/ref"/checkpoint_0004.manifest \
  >/dev/null || { echo "FAIL: the reference run left no checkpoint set at frame 4"; fail=1; }

# kills at two renames (of 2 processes' counts): in frame 1's files, with frame 0's
# checkpoint set in place, and in frame 2's files or checkpoint set
for kill_at in 16 27; do
  out=$work/kill$kill_at
  PIOLA_FAULT_KILL_AT_RENAME=$kill_at run "$out" >/dev/null 2>&1
  if [ $? -eq 0 ]; then
    echo "ok rename $kill_at: the run finished before it (nothing to resume)"; continue
  fi
  if ! run "$out" --resume >/dev/null 2>"$work/log"; then
    cat "$work/log"; echo "FAIL rename $kill_at: --resume"; fail=1; continue
  fi
  from=$(grep -o "resuming after frame [0-9]*" "$work/log" || echo "starting over")
  if same_as_reference "$out"; then
    echo "ok killed at rename $kill_at, $from: frames, sim.pvd and stats.csv byte-identical"
  else
    echo "FAIL rename $kill_at ($from): the resumed run differs"; fail=1
  fi
done

# refused resumes: exit 2, the count to use named, nothing written
refused() { # refused EXPECTED COMMAND...
  local expected=$1
  shift
  cp -r "$work/ref" "$work/copy"
  "$@" >"$work/log" 2>&1
  local rc=$?
  if [ $rc -ne 2 ] || ! grep -q -- "$expected" "$work/log" || ! same_as_reference "$work/copy" >/dev/null; then
    echo "FAIL refused resume ($*): exit $rc, expected 2 and '$expected', folder unchanged"; cat "$work/log"; fail=1
  else
    echo "ok refused: $(grep -m1 -- "$expected" "$work/log")"
  fi
  rm -rf "$work/copy"
}
refused "this run has 4; resume with mpirun -np 2" \
  "$mpirun" --oversubscribe -np 4 "$piola" run "$scene" -o "$work/copy" --frames $frames --threads 1 --resume
refused "resume it with mpirun -np 2" "$piola" run "$scene" -o "$work/copy" --frames $frames --threads 1 --resume
"$piola" run "$scene" -o "$work/single" --frames 1 --checkpoint-every 1 --threads 1 >/dev/null 2>&1 ||
  { echo "FAIL: single-process run"; fail=1; }
"$mpirun" --oversubscribe -np 2 "$piola" run "$scene" -o "$work/single" --frames 1 --threads 1 --resume \
  >"$work/log" 2>&1
if [ $? -eq 2 ] && grep -q "resume it without mpirun" "$work/log"; then
  echo "ok refused: $(grep -m1 "resume it without mpirun" "$work/log")"
else
  echo "FAIL: a split resume of a single process's folder"; cat "$work/log"; fail=1
fi
exit $fail
