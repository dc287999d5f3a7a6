#!/usr/bin/env bash
# What `mpirun -np 2 piola run` refuses (docs/mpi.md): shells run on one process only, the
# implicit integrators without PETSc. (Fracture runs split since 2026-12-02: mpi_frames.sh.) Each is refused before anything is written,
# with exit code 2 and a message naming what. (Checkpoints of split runs: mpi_checkpoints.sh.)
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
# refused SCENE EXPECTED_MESSAGE [ARGS...]
refused() {
  local scene=$1 expected=$2
  shift 2
  local out=$work/out
  rm -rf "$out"
  "$mpirun" --oversubscribe -np 2 "$piola" run "$scene" -o "$out" --frames 1 "$@" >"$work/log" 2>&1
  local rc=$?
  if [ $rc -ne 2 ] || ! grep -q -- "$expected" "$work/log" || [ -e "$out/stats.csv" ]; then
    echo "FAIL $(basename "$scene") $*: exit $rc, expected 2 and '$expected'"; cat "$work/log"; fail=1
  else
    echo "ok refused $(basename "$scene") $*: $(grep -m1 -- "$expected" "$work/log")"
  fi
}
refused "$examples/cloth_on_sphere.json" "shells run on one process only"
/usr/bin/python3 - "$examples/ball_recovers.json" "$work/implicit.json" <<'PY'
import json, os, sys
scene = json.load(open(sys.argv[1]))
scene.setdefault("integrator", {})["type"] = "backward_euler"
# mesh paths stay relative to the example's folder
base = os.path.dirname(os.path.abspath(sys.argv[1]))
def fix(o):
    if isinstance(o, dict):
        for k, v in o.items():
            if k in ("mesh", "path", "file") and isinstance(v, str) and not os.path.isabs(v):
                o[k] = os.path.join(base, v)
            else:
                fix(v)
    elif isinstance(o, list):
        for v in o:
            fix(v)
fix(scene)
json.dump(scene, open(sys.argv[2], "w"))
PY
# the implicit integrators: refused naming the missing PETSc in a build without it
# (PIOLA_PETSC=OFF, set by ctest); with it they run (mpi_implicit.sh), and a bad
# integrator.mpi_preconditioner is refused naming the key
if [ "${PIOLA_PETSC:-OFF}" = ON ]; then
  /usr/bin/python3 - "$work/implicit.json" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene["integrator"]["mpi_preconditioner"] = "hypre"
json.dump(scene, open(sys.argv[1], "w"))
PY
  refused "$work/implicit.json" 'integrator.mpi_preconditioner.*must be "gamg" or "block_jacobi_icc"'
else
  refused "$work/implicit.json" "implicit integrators.*only in a build with PETSc"
fi
exit $fail
