#!/usr/bin/env bash
# Fibre directions in mesh files: a per-cell "fiber" array written by meshio (.vtu ascii and
# base64, .msh 2.2 and 4.1, ASCII and binary, with the boundary's triangles among the cells)
# is read by `piola mesh convert` and written back to .vtu and .msh, where meshio finds every
# tet's fibre bit for bit; bad fibre data is refused naming the file and the array or line.
# The checks live in mesh_fibers.py (Debian's python3, which has meshio).
set -euo pipefail
exec /usr/bin/python3 "$(dirname "$0")/mesh_fibers.py"
