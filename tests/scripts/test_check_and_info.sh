#!/usr/bin/env bash
# `piola mesh info` and `piola check` against numbers computed here from the mesh file
# (read by meshio, an independent reader): bounding box, size, smallest altitude, the
# explicit step of --material, and check's bodies, counts, step and steps per frame.
# Checks in check_and_info.py (Debian's python3, which has meshio and numpy).
set -euo pipefail
exec /usr/bin/python3 "$(dirname "$0")/check_and_info.py"
