#!/usr/bin/env bash
# OBJ frames Blender can use (docs/file-formats.md): `piola run` writes surface/frame_NNNN.obj
# with one `o <name>` object per body, in the scene's order (solids, then shells), and only
# surface vertices: every vertex is used by a face of its own object (no loose interior
# nodes), and each closed solid's surface satisfies Euler's V - E + F = 2 with E = 3F/2;
# the shell keeps all its vertices. The frame is also read back by `piola mesh info`. A name
# with a line break, a control character or '#' cannot start a record or a comment of its
# own: they become '_' as blanks do.
set -euo pipefail
: "${PIOLA:?path of the piola program}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/scene.json" <<'JSON'
{"fps": 30, "frames": 1,
 "solids": [
   {"name": "left box", "mesh": {"generate": "box", "center": [-0.3, 0, 0.2], "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.04},
    "material": {"youngs_modulus": 1e4, "poisson_ratio": 0.3}},
   {"name": "ball\nv\u000b9#x", "mesh": {"generate": "sphere", "center": [0.3, 0, 0.2], "radius": 0.1, "cell_size": 0.04},
    "material": {"youngs_modulus": 1e4, "poisson_ratio": 0.3}}],
 "shells": [{"name": "sheet", "mesh": {"generate": "rectangle", "size": [0.4, 0.4], "resolution": [4, 4]},
             "transform": {"translate": [0, 0, 0.6]}, "thickness": 0.001,
             "material": {"youngs_modulus": 1e5, "poisson_ratio": 0.3}}]}
JSON
"$PIOLA" run "$work/scene.json" -o "$work/out" >"$work/log" 2>&1 || { cat "$work/log"; exit 1; }
"$PIOLA" mesh info "$work/out/surface/frame_0001.obj" >/dev/null || { echo "FAIL: piola cannot read its OBJ"; exit 1; }
exec python3 - "$work/out/surface" <<'PY'
import sys
failed = []
def check(ok, msg):
    print(("ok   " if ok else "FAIL ") + msg)
    if not ok: failed.append(msg)
for frame in ("frame_0000.obj", "frame_0001.obj"):
    objects, current, vertex_owner = [], None, []
    for line in open(f"{sys.argv[1]}/{frame}"):
        w = line.split()
        if not w or w[0].startswith("#"): continue
        if w[0] == "o":
            current = {"name": " ".join(w[1:]), "v": 0, "faces": []}; objects.append(current)
        elif w[0] == "v":
            check(current is not None, f"{frame}: vertex before any object") if current is None else None
            current["v"] += 1; vertex_owner.append(len(objects) - 1)
        elif w[0] == "f":
            current["faces"].append([int(x.split("/")[0]) for x in w[1:]])
    check([o["name"] for o in objects] == ["left_box", "ball_v_9_x", "sheet"],
          f"{frame}: objects {[o['name'] for o in objects]} are the bodies in order")
    used = set()
    for k, o in enumerate(objects):
        own = all(vertex_owner[i - 1] == k for f in o["faces"] for i in f)
        check(own, f"{frame}: {o['name']}'s faces use only its own vertices")
        used |= {i for f in o["faces"] for i in f}
    check(used == set(range(1, len(vertex_owner) + 1)), f"{frame}: every vertex is used by a face (no loose nodes)")
    for o in objects[:2]:
        F = len(o["faces"])
        check(F > 0 and o["v"] - 3 * F // 2 + F == 2, f"{frame}: {o['name']}: V - E + F = 2 (V {o['v']}, F {F})")
    check(objects[2]["v"] == 25 and len(objects[2]["faces"]) == 32, f"{frame}: the sheet has its 25 vertices and 32 triangles")
print(f"{len(failed)} check(s) failed" if failed else "all checks passed")
sys.exit(1 if failed else 0)
PY
