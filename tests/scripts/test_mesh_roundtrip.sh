#!/usr/bin/env bash
# Round trips with external tools: meshes made by Debian's gmsh and tetgen are read by
# `piola mesh info/convert`; what piola writes is read back by piola, by meshio and by VTK.
# The checks live in mesh_roundtrip.py (Debian's python3, which has meshio and vtk).
set -euo pipefail
exec /usr/bin/python3 "$(dirname "$0")/mesh_roundtrip.py"
