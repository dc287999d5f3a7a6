#!/usr/bin/env bash
# Fresh machine to first result: install what is missing, build piola, run the demo scene.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DPIOLA_BUILD_TESTS=OFF
cmake --build build/release -j "$(nproc)"

demo=examples/torus_puddle.json
out=out/torus_puddle
echo "setup: running the demo scene $demo -> $out"
build/release/piola run "$demo" -o "$out" --force
echo "setup: done. Open $out/sim.pvd in ParaView, or $out/surface/*.obj in Blender."
