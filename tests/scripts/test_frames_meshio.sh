#!/usr/bin/env bash
# Every array of piola's VTU frames reads the same through meshio as through VTK, bit for bit.
# meshio 5 turns raw appended data into base64 block by block and matches each block to the
# first DataArray whose offset attribute equals the block's offset; with blocks stored in the
# headers' order some array sizes made it hand one array another's data or fail (a single tet
# did: "The size of the data array 'Points' is 4"). docs/file-formats.md says how the writer
# orders the blocks so that it cannot happen; this checks it on such sizes.
set -euo pipefail
: "${PIOLA:?path of the piola program}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/tet.mesh" <<'MESH'
MeshVersionFormatted 2
Dimension 3
Vertices
4
0 0 0 0
0.1 0 0 0
0 0.1 0 0
0 0 0.1 0
Tetrahedra
1
1 2 3 4 0
End
MESH
cat >"$work/tet.json" <<'JSON'
{"fps": 30, "frames": 2, "gravity": [0, 0, -9.81],
 "solids": [{"name": "tet", "mesh": "tet.mesh", "density": 1000,
             "material": {"model": "neohookean", "youngs_modulus": 1e5, "poisson_ratio": 0.3}}]}
JSON
cat >"$work/box.json" <<'JSON'
{"fps": 30, "frames": 1, "gravity": [0, 0, -9.81],
 "solids": [{"name": "box", "mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.05], "cell_size": 0.05},
             "velocity": [0.1, 0, 0]}]}
JSON
for scene in tet box; do
  "$PIOLA" run "$work/$scene.json" -o "$work/$scene" --threads 1 >"$work/$scene.log" 2>&1 || { cat "$work/$scene.log"; exit 1; }
done
# Debian's meshio and VTK live with the system Python, which may not be the first python3 on PATH
syspy=python3
[[ -x /usr/bin/python3 ]] && syspy=/usr/bin/python3
"$syspy" - "$work"/tet/frames/*.vtu "$work"/box/frames/*.vtu <<'PY'
import sys
import numpy as np
import meshio
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

for path in sys.argv[1:]:
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    m = meshio.read(path)
    n = grid.GetNumberOfPoints()
    assert n > 0 and np.array_equal(vtk_to_numpy(grid.GetPoints().GetData()), m.points), path
    conn = vtk_to_numpy(grid.GetCells().GetConnectivityArray()).reshape(-1, 4)
    tets = np.concatenate([c.data for c in m.cells if c.type == "tetra"])
    assert np.array_equal(conn, tets), path
    pd, cd = grid.GetPointData(), grid.GetCellData()
    assert pd.GetNumberOfArrays() == len(m.point_data) and cd.GetNumberOfArrays() == len(m.cell_data), path
    for i in range(pd.GetNumberOfArrays()):
        name = pd.GetArrayName(i)
        assert np.array_equal(vtk_to_numpy(pd.GetArray(i)).reshape(n, -1), m.point_data[name].reshape(n, -1)), (path, name)
    for i in range(cd.GetNumberOfArrays()):
        name = cd.GetArrayName(i)
        assert np.array_equal(vtk_to_numpy(cd.GetArray(i)).reshape(-1),
                              np.concatenate(m.cell_data[name]).reshape(-1)), (path, name)
print(f"meshio and VTK read the same arrays from {len(sys.argv) - 1} frames")
PY
