#!/usr/bin/env bash
# Checkpoints of a split run (docs/mpi.md, "Checkpoints"): `mpirun -np 2 piola run` killed
# (SIGKILL, PIOLA_FAULT_KILL_AT_RENAME) at a rename of a piece, a frame's index, a
# process's checkpoint file or the manifest, then continued with --resume on 2 processes,
# must write frames (every .pvtu, piece and OBJ), sim.pvd and stats.csv (but its
# wall_seconds column) byte-identical to the run that was never stopped. A resume on another
# process count, or without mpirun, is refused with exit code 2 and a message naming the
# count to use; a split resume of a single process's folder likewise.
# Fracture (scripted_cut, first cut in frame 4): a run stopped after frame 6 resumes from
# its set written after the cut, and one whose newest set has a damaged file on either
# process resumes from the older set (after the cut, or before it), all of them to frame 8
# byte-identical to the uninterrupted 8-frame run.
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
run() { # run OUT [ARGS...]: the split run under test (mpirun passes PIOLA_FAULT_* with -x;
  # guard: a command that runs it, such as a time limit)
  local out=$1
  shift
  ${guard:-} "$mpirun" --oversubscribe ${PIOLA_FAULT_KILL_AT_RENAME:+-x PIOLA_FAULT_KILL_AT_RENAME} -np 2 "$piola" run "$scene" -o "$out" --frames $frames \
    --checkpoint-every 1 --threads 1 "$@"
}
same_as_reference() { # same_as_reference DIR [REF]: byte-identical to the uninterrupted run
  local dir=$1 ref=${2:-$work/ref} bad=0 f
  for f in $(cd "$ref" && find frames surface -type f | sort) sim.pvd; do
    cmp -s "$ref/$f" "$dir/$f" || { echo "  $f differs"; bad=1; }
  done
  [ "$(cd "$dir" && find frames surface -type f | wc -l)" = "$(cd "$ref" && find frames surface -type f | wc -l)" ] ||
    { echo "  other frame files than the reference"; bad=1; }
  # stats.csv: every column but wall_seconds (the 9th)
  cmp -s <(cut -d, -f1-8,10- "$ref/stats.csv") <(cut -d, -f1-8,10- "$dir/stats.csv") ||
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

# fracture: resumes from sets written after the cut (docs/mpi.md, "Checkpoints")
scene=$examples/scripted_cut.json
frames=8
run "$work/cut_ref" >/dev/null 2>"$work/log" || { cat "$work/log"; echo "FAIL: the fracture reference run"; exit 1; }
[ "$(awk -F, 'NR == 5 {print $NF} NR == 6 {print ($NF > 0)}' "$work/cut_ref/stats.csv" | tr '\n' ' ')" = "0 1 " ] ||
  { echo "FAIL: scripted_cut's first cut is not in frame 4 (stats.csv cut_tets): this test needs it there"; fail=1; }
cut_resume() { # cut_resume STOP DAMAGED_FILE EXPECTED_FRAME: stopped after STOP, resumed to 8
  local stop=$1 damaged=$2 expected=$3 out=$work/cut_$1_${2:-intact}
  frames=$stop
  run "$out" >/dev/null 2>&1 || { echo "FAIL: the fracture run to frame $stop"; fail=1; return; }
  frames=8
  if [ -n "$damaged" ]; then # one byte changed: its checksum no longer matches
    printf 'X' | dd of="$out/$damaged" bs=1 seek=5000 conv=notrunc 2>/dev/null
  fi
  # a process left waiting for another would hang: the time limit turns that into a failure
  if ! guard="timeout 300" run "$out" --resume >/dev/null 2>"$work/log"; then
    cat "$work/log"; echo "FAIL fracture: stopped after frame $stop, ${damaged:-no file} damaged: --resume"; fail=1; return
  fi
  local from
  from=$(grep -o "resuming after frame [0-9]*" "$work/log" || echo "starting over")
  if [ "$from" != "resuming after frame $expected" ]; then
    echo "FAIL fracture: stopped after frame $stop, ${damaged:-no file} damaged: $from, expected frame $expected"; fail=1
  elif same_as_reference "$out" "$work/cut_ref"; then
    echo "ok fracture: stopped after frame $stop, ${damaged:-no file} damaged, $from: frames, sim.pvd and stats.csv byte-identical"
  else
    echo "FAIL fracture: stopped after frame $stop, ${damaged:-no file} damaged ($from): the resumed run differs"; fail=1
  fi
}
cut_resume 6 "" 6
cut_resume 6 checkpoint_0006_p1.bin 5
cut_resume 4 checkpoint_0004_p0.bin 3
exit $fail
