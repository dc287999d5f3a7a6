#!/usr/bin/env bash
# Fresh machine to first result: install what is missing, build piola, run the demo scene.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DPIOLA_BUILD_TESTS=OFF
cmake --build build/release -j "$(nproc)"

# `import piola` in Debian's /usr/bin/python3 (docs/python.md): a .pth file in its user
# site-packages names the package folder of this build.
if [ -d build/release/python/piola ]; then
  site=$(/usr/bin/python3 -c 'import site; print(site.getusersitepackages() if site.ENABLE_USER_SITE else "")')
  if [ -n "$site" ]; then
    mkdir -p "$site"
    echo "$PWD/build/release/python" > "$site/piola-build.pth"
    /usr/bin/python3 -c 'import piola' && echo "setup: import piola works in /usr/bin/python3 ($site/piola-build.pth)"
  else
    echo "setup: user site-packages are off; use PYTHONPATH=$PWD/build/release/python /usr/bin/python3"
  fi
fi

demo=examples/torus_puddle.json
out=out/torus_puddle
echo "setup: running the demo scene $demo -> $out"
build/release/piola run "$demo" -o "$out" --force
echo "setup: done. Open $out/sim.pvd in ParaView, or $out/surface/*.obj in Blender."
