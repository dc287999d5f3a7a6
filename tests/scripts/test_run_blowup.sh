#!/usr/bin/env bash
# A run whose state blows up stops with a clear message and exit code 1, keeps every good
# frame (stats.csv and sim.pvd list exactly those), and writes a report of the worst elements
# of every body (a solid and a shell).
# The blow-up is forced by gravity keyframed from 0 to -1e307 m/s^2 during the second frame.
set -euo pipefail
: "${PIOLA:?path of the piola program}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/blowup.json" <<'JSON'
{"fps": 10, "frames": 5, "gravity": [0, 0, {"keys": [[0, 0], [0.15, 0], [0.16, -1e307]]}],
 "solids": [{"mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}}],
 "shells": [{"name": "sheet", "mesh": {"generate": "torus", "radius": 0.2, "minor_radius": 0.06, "segments": [12, 8]},
   "thickness": 0.004, "density": 500, "material": {"model": "corotated", "youngs_modulus": 1e5, "poisson_ratio": 0.3}}]}
JSON
set +e
"$PIOLA" run "$work/blowup.json" -o "$work/out" --threads 1 >"$work/log" 2>&1
rc=$?
set -e
cat "$work/log"
[[ $rc -eq 1 ]] || { echo "exit code $rc, expected 1"; exit 1; }
grep -q "non-finite" "$work/log" || { echo "no clear message"; exit 1; }
[[ -s "$work/out/frames/frame_0000.vtu" && -s "$work/out/frames/frame_0001.vtu" ]] || { echo "good frames lost"; exit 1; }
[[ ! -e "$work/out/frames/frame_0002.vtu" ]] || { echo "wrote a frame of the blown-up state"; exit 1; }
[[ $(wc -l <"$work/out/stats.csv") -eq 3 ]] || { echo "stats.csv should hold frames 0 and 1"; cat "$work/out/stats.csv"; exit 1; }
[[ $(grep -c "<DataSet" "$work/out/sim.pvd") -eq 2 ]] || { echo "sim.pvd should list frames 0 and 1"; exit 1; }
grep -q "worst by smallest det F" "$work/out/failure_report.txt" || { echo "no report of the worst elements"; exit 1; }
grep -q "non-finite" "$work/out/failure_report.txt" || { echo "report lacks the message"; exit 1; }
grep -q "^shell 'sheet': 192 triangles" "$work/out/failure_report.txt" || { echo "no report of the shell"; exit 1; }
grep -q "worst by smallest area ratio" "$work/out/failure_report.txt" || { echo "no report of the shell's worst triangles"; exit 1; }
echo "blow-up stopped cleanly"
