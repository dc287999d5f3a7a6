#!/usr/bin/env bash
# `piola run` writes the documented folder: a VTU and an OBJ per frame, stats.csv with one
# row per frame and the required columns, and sim.pvd listing every frame at its time.
# The VTU frames are then read back by an independent reader (Debian's python3-meshio)
# which must find the same point and cell counts and the documented fields.
set -euo pipefail
: "${PIOLA:?path of the piola program}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/drop.json" <<'JSON'
{"fps": 20, "frames": 4, "gravity": [0, 0, -9.81],
 "solids": [{"name": "cube", "mesh": {"generate": "box", "center": [0, 0, 0.2], "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.05},
             "material": {"youngs_modulus": 5e4, "poisson_ratio": 0.3}, "damping": {"shear": 5, "bulk": 5}},
            {"name": "ball", "mesh": {"generate": "sphere", "center": [0.5, 0, 0.3], "radius": 0.1, "cell_size": 0.05},
             "velocity": [0, 0, -1]}],
 "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "friction": 0.3}]}
JSON
"$PIOLA" run "$work/drop.json" -o "$work/out" --threads 1 >"$work/log" 2>&1 || { cat "$work/log"; exit 1; }
for f in 0 1 2 3 4; do
  n=$(printf '%04d' $f)
  [[ -s "$work/out/frames/frame_$n.vtu" ]] || { echo "missing frames/frame_$n.vtu"; exit 1; }
  [[ -s "$work/out/surface/frame_$n.obj" ]] || { echo "missing surface/frame_$n.obj"; exit 1; }
  grep -q "frames/frame_$n.vtu" "$work/out/sim.pvd" || { echo "sim.pvd lacks frame $n"; exit 1; }
done
[[ ! -e "$work/out/frames/frame_0005.vtu" ]] || { echo "wrote more frames than asked"; exit 1; }
[[ -z "$(find "$work/out" -name '*.tmp*')" ]] || { echo "temporary files left behind"; exit 1; }
python3 - "$work/out" <<'PY'
import csv, sys, xml.etree.ElementTree as ET
out = sys.argv[1]
rows = list(csv.DictReader(open(f"{out}/stats.csv")))
need = ["frame", "time", "substeps", "cg_iterations", "kinetic_energy", "elastic_energy",
        "inverted", "min_det_f", "wall_seconds"]
assert all(k in rows[0] for k in need), rows[0].keys()
assert [int(r["frame"]) for r in rows] == [0, 1, 2, 3, 4], [r["frame"] for r in rows]
for r in rows:
    assert abs(float(r["time"]) - int(r["frame"]) / 20) < 1e-12, r
    if int(r["frame"]) > 0:
        assert int(r["substeps"]) >= 1
# falling: kinetic energy grows from rest for the cube, the ball starts moving
assert float(rows[0]["kinetic_energy"]) > 0 and float(rows[2]["kinetic_energy"]) > float(rows[0]["kinetic_energy"])
pvd = ET.parse(f"{out}/sim.pvd").getroot()
times = [float(d.get("timestep")) for d in pvd.iter("DataSet")]
assert times == sorted(times) and len(times) == 5 and abs(times[-1] - 0.2) < 1e-12, times
print("stats.csv and sim.pvd ok")
PY
# Debian's meshio lives with the system Python, which may not be the first python3 on PATH
syspy=python3
[[ -x /usr/bin/python3 ]] && syspy=/usr/bin/python3
"$syspy" - "$work/out" <<'PY'
import sys
import numpy as np
import meshio
out = sys.argv[1]
m0 = meshio.read(f"{out}/frames/frame_0000.vtu")
m4 = meshio.read(f"{out}/frames/frame_0004.vtu")
tets = [c for c in m4.cells if c.type == "tetra"]
assert len(tets) == 1, [c.type for c in m4.cells]
nt = len(tets[0].data)
npnt = len(m4.points)
assert nt > 10 and npnt > 10, (nt, npnt)
assert len(m0.points) == npnt
for name in ["velocity", "displacement"]:
    assert m4.point_data[name].shape == (npnt, 3), (name, m4.point_data[name].shape)
for name in ["det_f", "inverted", "energy_density"]:
    v = np.asarray(m4.cell_data[name][0]).reshape(-1)
    assert v.shape == (nt,), (name, v.shape)
assert tets[0].data.max() < npnt and tets[0].data.min() >= 0
# displacement is position minus rest position; frame 0 of the resting cube has none
disp = m4.point_data["displacement"]
assert np.allclose(m4.points - disp, m0.points - m0.point_data["displacement"], atol=1e-9)
# the cube fell: its points moved down, and nothing went below the ground
assert disp[:, 2].min() < -1e-3 and m4.points[:, 2].min() >= -1e-9
inv = np.asarray(m4.cell_data["inverted"][0]).reshape(-1)
det = np.asarray(m4.cell_data["det_f"][0]).reshape(-1)
assert np.array_equal(inv > 0.5, det < 0)
print(f"meshio read {npnt} points, {nt} tets with all fields")
PY
# a second run into the same folder is refused, and allowed with --force
set +e
"$PIOLA" run "$work/drop.json" -o "$work/out" >/dev/null 2>&1
rc=$?
set -e
[[ $rc -eq 2 ]] || { echo "rerun without --force: exit code $rc"; exit 1; }
"$PIOLA" run "$work/drop.json" -o "$work/out" --force --frames 2 >/dev/null 2>&1
[[ ! -e "$work/out/frames/frame_0003.vtu" ]] || { echo "--force kept stale frames of the earlier run"; exit 1; }
[[ $(wc -l <"$work/out/stats.csv") -eq 4 ]] || { echo "stats.csv after --force --frames 2"; cat "$work/out/stats.csv"; exit 1; }
echo "piola run output ok"
