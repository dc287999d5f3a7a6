#!/usr/bin/env bash
# Frames of a body sliced by a moving blade (examples/scripted_cut.json: a knife moving down
# through a clamped bar from 0.05 s to 0.3 s, docs/fracture.md "A moving blade"), its first
# 10 frames read back by Debian's python3-meshio: every VTU frame has the cell fields
# `fragment` and `material_fraction` in (0, 1], with as many fragments as stats.csv says;
# stats.csv's cut_tets is 0 before the knife reaches the bar, grows over several frames
# (the knife cuts step by step) and never shrinks; the bar is one fragment until the knife
# is through and two by the end of the sweep; every OBJ frame has one closed, consistently
# oriented object per fragment enclosing a positive volume that adds up to the bar's.
# With the argument `backward_euler` (test_fracture_blade_frames_implicit.sh) the same scene
# is stepped by backward Euler at 5 ms instead of Newmark, with the same checks.
set -euo pipefail
: "${PIOLA:?path of the piola program}"
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene="$source_dir/examples/scripted_cut.json"
if [[ "${1:-}" == backward_euler ]]; then
  # the scene's blade file is found from the scene's folder: name it absolutely in the copy
  sed -e 's|"integrator": {[^}]*}|"integrator": {"type": "backward_euler", "dt": 0.005}|' \
      -e "s|\"meshes/|\"$source_dir/examples/meshes/|" "$scene" >"$work/scene.json"
  grep -q '"backward_euler"' "$work/scene.json" || { echo "scene copy lacks the integrator"; exit 1; }
  scene="$work/scene.json"
fi
"$PIOLA" run "$scene" -o "$work/out" --frames 10 >"$work/log" 2>&1 ||
  { cat "$work/log"; exit 1; }
syspy=python3
[[ -x /usr/bin/python3 ]] && syspy=/usr/bin/python3
"$syspy" - "$work/out" <<'PY'
import csv, sys
import numpy as np
import meshio
out = sys.argv[1]
rows = list(csv.DictReader(open(f"{out}/stats.csv")))
assert len(rows) == 11, len(rows)
cut = [int(r["cut_tets"]) for r in rows]
fragments = [int(r["fragments"]) for r in rows]
fps = 30
assert all(c == 0 for c, r in zip(cut, rows) if float(r["time"]) < 0.05 + 1e-9), cut
assert all(b >= a for a, b in zip(cut, cut[1:])), cut
assert sum(b > a for a, b in zip(cut, cut[1:])) >= 3, ("not step by step", cut)
assert fragments[0] == 1 and fragments[-1] == 2, fragments
assert all(f == 1 for f, c in zip(fragments, cut) if c == 0), (fragments, cut)
whole = None
for frame, row in enumerate(rows):
    m = meshio.read(f"{out}/frames/frame_{frame:04d}.vtu")
    frag = np.asarray(m.cell_data["fragment"][0]).ravel()
    frac = np.asarray(m.cell_data["material_fraction"][0]).ravel()
    assert len(set(frag.tolist())) == fragments[frame], (frame, set(frag.tolist()), fragments[frame])
    assert (frac > 0).all() and (frac <= 1).all(), (frame, frac.min(), frac.max())
    assert ((frac < 1).sum() > 0) == (cut[frame] > 0), frame
    objects, cur, verts = [], None, []
    for line in open(f"{out}/surface/frame_{frame:04d}.obj"):
        w = line.split()
        if not w or w[0].startswith("#"): continue
        if w[0] == "o": cur = {"name": w[1], "f": []}; objects.append(cur)
        elif w[0] == "v": verts.append([float(x) for x in w[1:4]])
        elif w[0] == "f": cur["f"].append([int(x) - 1 for x in w[1:4]])
    assert [o["name"] for o in objects] == [f"bar_{g}" for g in range(fragments[frame])], (frame, [o["name"] for o in objects])
    v = np.array(verts)
    total = 0.0
    for o in objects:
        f = np.array(o["f"])
        edges = {}
        for tri in f:
            for k in range(3):
                e = (tri[k], tri[(k + 1) % 3]); edges[e] = edges.get(e, 0) + 1
        assert all(edges.get((b, a), 0) == n for (a, b), n in edges.items()), f"frame {frame}: {o['name']} is not closed"
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        enclosed = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)
        assert enclosed > 0, (frame, o["name"], enclosed)
        total += enclosed
    whole = whole or total
    assert abs(total - whole) < 0.05 * whole, (frame, total, whole)  # cuts move no material; the bending changes the volume little
print("moving blade frames ok")
PY
