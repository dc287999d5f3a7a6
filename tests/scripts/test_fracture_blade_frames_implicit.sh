#!/usr/bin/env bash
# The moving blade's frames (test_fracture_blade_frames.sh) with the scene stepped by
# backward Euler (5 ms steps): the cut state carries over to the Newton steps, and every
# frame's fragment surfaces are closed and consistently oriented (docs/fracture.md,
# "Implicit integrators").
set -euo pipefail
exec bash "$(dirname "$0")/test_fracture_blade_frames.sh" backward_euler
