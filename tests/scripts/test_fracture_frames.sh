#!/usr/bin/env bash
# Frames of a cut solid (docs/fracture.md, docs/cli.md "Output"): a 0.2 m box cut at t = 0
# by a slanted plane through its tets. Read back by Debian's python3-meshio, every VTU frame
# holds that frame's tets with the cell fields `fragment` (two values) and
# `material_fraction` in (0, 1]; the material volumes per fragment and the volumes enclosed
# by the OBJ objects box_0 and box_1 (each closed: every directed edge has its opposite) are
# the analytic 0.0048 and 0.0032 m^3 within 0.5%; stats.csv's last columns are `fragments`
# and `cut_tets`. Next to a ball and a sheet, a box cut at 0.05 s is one object before the
# cut and two after, each object using exactly its own vertices. A bar pulled at one end
# with the stress criterion breaks, and a threshold without criterion is refused. A fracture
# key with the plastic_strain criterion is refused naming its key path; with self_collision
# the scene runs, and --checkpoint-every writes checkpoints for a scene with fracture.
set -euo pipefail
: "${PIOLA:?path of the piola program}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# the box [-0.1, 0.1]^3 as 5^3 cubes of 6 tets each (a medit file), exactly its volume
python3 - "$work/box.mesh" <<'PY'
import itertools, sys
n, h = 5, 0.04
idx = lambda i, j, k: 1 + i + (n + 1) * (j + (n + 1) * k)
lines = ["MeshVersionFormatted 1", "Dimension 3", "Vertices", str((n + 1) ** 3)]
for k in range(n + 1):
    for j in range(n + 1):
        for i in range(n + 1):
            lines.append(f"{-0.1 + h * i!r} {-0.1 + h * j!r} {-0.1 + h * k!r} 0")
tets = []
for i, j, k in itertools.product(range(n), repeat=3):
    for perm in itertools.permutations(range(3)):
        c = [i, j, k]; path = [idx(*c)]
        for axis in perm:
            c[axis] += 1; path.append(idx(*c))
        tets.append(path)
lines += ["Tetrahedra", str(len(tets))] + [" ".join(map(str, t)) + " 0" for t in tets] + ["End"]
open(sys.argv[1], "w").write("\n".join(lines) + "\n")
PY
cat >"$work/scene.json" <<'JSON'
{"fps": 20, "frames": 2, "gravity": [0, 0, 0],
 "solids": [
   {"name": "box", "mesh": "box.mesh",
    "material": {"youngs_modulus": 1e4, "poisson_ratio": 0.3},
    "fracture": {"cuts": [{"time": 0, "plane": {"point": [0.02, 0, 0], "normal": [1, 0.2, 0.1]}}]}}]}
JSON
"$PIOLA" run "$work/scene.json" -o "$work/out" >"$work/log" 2>&1 || { cat "$work/log"; exit 1; }
syspy=python3
[[ -x /usr/bin/python3 ]] && syspy=/usr/bin/python3
"$syspy" - "$work/out" <<'PY'
import csv, sys
import numpy as np
import meshio
out = sys.argv[1]
analytic = sorted([0.0048, 0.0032])
def tet_volumes(m):
    t = [c for c in m.cells if c.type == "tetra"][0].data
    p = m.points
    a, b, c, d = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]], p[t[:, 3]]
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6.0
for frame in (0, 1, 2):
    m = meshio.read(f"{out}/frames/frame_{frame:04d}.vtu")
    frag = np.asarray(m.cell_data["fragment"][0]).ravel()
    frac = np.asarray(m.cell_data["material_fraction"][0]).ravel()
    assert sorted(set(frag.tolist())) == [0, 1], set(frag.tolist())
    assert (frac > 0).all() and (frac <= 1).all(), (frac.min(), frac.max())
    assert (frac < 1).sum() > 0, "no cut tets"
    if frame == 0:
        rest = tet_volumes(m)
        vols = sorted(float((rest * frac)[frag == g].sum()) for g in (0, 1))
        for v, a in zip(vols, analytic):
            assert abs(v - a) < 0.005 * a, (vols, analytic)
    # the OBJ: one closed object per fragment
    objects, cur, verts = [], None, []
    for line in open(f"{out}/surface/frame_{frame:04d}.obj"):
        w = line.split()
        if not w or w[0].startswith("#"): continue
        if w[0] == "o": cur = {"name": w[1], "f": []}; objects.append(cur)
        elif w[0] == "v": verts.append([float(x) for x in w[1:4]])
        elif w[0] == "f": cur["f"].append([int(x) - 1 for x in w[1:4]])
    assert [o["name"] for o in objects] == ["box_0", "box_1"], [o["name"] for o in objects]
    v = np.array(verts)
    enclosed = []
    for o in objects:
        f = np.array(o["f"])
        edges = {}
        for tri in f:
            for k in range(3):
                e = (tri[k], tri[(k + 1) % 3]); edges[e] = edges.get(e, 0) + 1
        assert all(edges.get((b, a), 0) == n for (a, b), n in edges.items()), o["name"] + " is not closed"
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        enclosed.append(float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0))
    if frame == 0:
        for e, a in zip(sorted(enclosed), analytic):
            assert abs(e - a) < 0.005 * a, (enclosed, analytic)
    else:
        assert all(e > 0 for e in enclosed), enclosed
rows = list(csv.DictReader(open(f"{out}/stats.csv")))
header = open(f"{out}/stats.csv").readline().strip().split(",")
assert header[-2:] == ["fragments", "cut_tets"], header[-2:]
assert all(r["fragments"] == "2" and int(r["cut_tets"]) > 0 for r in rows), rows
print("fracture frames ok")
PY
# with other bodies: a ball before and a sheet after the cut box, cut at t = 0.05 s (frame 1):
# frame 0 has one box object, frame 2 two, each object's faces use exactly its own vertices
cat >"$work/two.json" <<'JSON'
{"fps": 20, "frames": 2, "gravity": [0, 0, 0],
 "solids": [
   {"name": "ball", "mesh": {"generate": "sphere", "center": [0.5, 0, 0], "radius": 0.1, "cell_size": 0.04},
    "material": {"youngs_modulus": 1e4, "poisson_ratio": 0.3}},
   {"name": "box", "mesh": "box.mesh", "material": {"youngs_modulus": 1e4, "poisson_ratio": 0.3},
    "fracture": {"cuts": [{"time": 0.05, "plane": {"point": [0.02, 0, 0], "normal": [1, 0.2, 0.1]}}]}}],
 "shells": [{"name": "sheet", "mesh": {"generate": "rectangle", "size": [0.4, 0.4], "resolution": [4, 4]},
             "transform": {"translate": [0, 0, 0.6]}, "thickness": 0.001,
             "material": {"youngs_modulus": 1e5, "poisson_ratio": 0.3}}]}
JSON
"$PIOLA" run "$work/two.json" -o "$work/two" >"$work/log" 2>&1 || { cat "$work/log"; exit 1; }
python3 - "$work/two/surface" <<'PY'
import sys
for frame, names in ((0, ["ball", "box_0", "sheet"]), (2, ["ball", "box_0", "box_1", "sheet"])):
    objs, nv, owner = [], 0, []
    for line in open(f"{sys.argv[1]}/frame_{frame:04d}.obj"):
        w = line.split()
        if not w or w[0] == "#": continue
        if w[0] == "o": objs.append({"n": w[1], "f": []})
        elif w[0] == "v": nv += 1; owner.append(len(objs) - 1)
        elif w[0] == "f": objs[-1]["f"].append([int(x) for x in w[1:]])
    assert [o["n"] for o in objs] == names, (frame, [o["n"] for o in objs])
    for k, o in enumerate(objs):
        used = {i for f in o["f"] for i in f}
        assert used == {i + 1 for i in range(nv) if owner[i] == k}, (frame, o["n"])
print("fracture frames with other bodies ok")
PY
# the stress criterion from a scene: a bar pulled at one end breaks (fragments in stats.csv),
# its crack running below the bar's Rayleigh wave speed (about 5.7 m/s; without a speed
# limit the crack that starts at the clamp's corner runs on slanted and leaves it joined);
# threshold without criterion is refused
cat >"$work/pull.json" <<'JSON'
{"fps": 50, "frames": 6, "gravity": [0, 0, 0],
 "solids": [{"name": "bar", "mesh": {"generate": "box", "center": [0.15, 0, 0], "half_extents": [0.15, 0.025, 0.025], "cell_size": 0.02},
   "material": {"youngs_modulus": 1e5, "poisson_ratio": 0.3}, "damping": {"shear": 5, "bulk": 5},
   "fixed": [{"box": [[-0.1, -1, -1], [0.001, 1, 1]]}],
   "driven": [{"box": [[0.299, -1, -1], [0.4, 1, 1]], "motion": {"velocity": [0.5, 0, 0]}}],
   "fracture": {"criterion": "stress", "max_crack_speed": 5, "threshold": 1.5e4}}]}
JSON
"$PIOLA" run "$work/pull.json" -o "$work/pull" >"$work/log" 2>&1 || { cat "$work/log"; exit 1; }
awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "fragments") c = i }
         NR == 2 && $c != 1 { exit 1 } END { if ($c < 2) exit 1 }' "$work/pull/stats.csv" ||
  { echo "FAIL: the pulled bar did not break (or was broken at frame 0)"; cat "$work/pull/stats.csv"; exit 1; }
sed 's/"threshold": 1.5e4}/"threshold": 1.5e4, "max_tets_per_step": 4}/' "$work/pull.json" >"$work/most.json"
"$PIOLA" run "$work/most.json" -o "$work/most" --frames 1 >"$work/log" 2>&1 || { echo "FAIL: max_tets_per_step refused"; cat "$work/log"; exit 1; }
sed 's/"criterion": "stress", //' "$work/most.json" >"$work/most_alone.json"
if "$PIOLA" run "$work/most_alone.json" -o "$work/ma" >"$work/log" 2>&1; then echo "FAIL: max_tets_per_step without criterion accepted"; exit 1; fi
grep -q "solids\[0\].fracture.threshold" "$work/log" || { echo "FAIL: max_tets_per_step message:"; cat "$work/log"; exit 1; }
# growth_threshold and max_crack_speed: accepted with a criterion, refused without one or
# when not positive, naming the key
sed 's/"threshold": 1.5e4}/"threshold": 1.5e4, "growth_threshold": 5e3}/' "$work/pull.json" >"$work/grow.json"
"$PIOLA" run "$work/grow.json" -o "$work/grow" --frames 1 >"$work/log" 2>&1 || { echo "FAIL: growth_threshold, max_crack_speed refused"; cat "$work/log"; exit 1; }
for key in growth_threshold max_crack_speed; do
  sed "s/\"criterion\": \"stress\", \"max_crack_speed\": 5, \"threshold\": 1.5e4}/\"$key\": 5}/" "$work/pull.json" >"$work/alone.json"
  if "$PIOLA" run "$work/alone.json" -o "$work/alone" >"$work/log" 2>&1; then echo "FAIL: $key without criterion accepted"; exit 1; fi
  grep -q "solids\[0\].fracture.$key" "$work/log" || { echo "FAIL: $key message:"; cat "$work/log"; exit 1; }
  sed "s/\"max_crack_speed\": 5, \"threshold\": 1.5e4}/\"threshold\": 1.5e4, \"$key\": -1}/" "$work/pull.json" >"$work/neg.json"
  if "$PIOLA" run "$work/neg.json" -o "$work/neg" >"$work/log" 2>&1; then echo "FAIL: negative $key accepted"; exit 1; fi
  grep -q "solids\[0\].fracture.$key" "$work/log" || { echo "FAIL: negative $key message:"; cat "$work/log"; exit 1; }
done
sed 's/"criterion": "stress", //' "$work/pull.json" >"$work/threshold.json"
if "$PIOLA" run "$work/threshold.json" -o "$work/t" >"$work/log" 2>&1; then echo "FAIL: threshold alone accepted"; exit 1; fi
grep -q "solids\[0\].fracture.threshold" "$work/log" || { echo "FAIL: threshold message:"; cat "$work/log"; exit 1; }
# refusals: the plastic_strain criterion without plasticity
sed 's/"fracture": {/"fracture": {"criterion": "plastic_strain", "threshold": 0.5, /' "$work/scene.json" >"$work/criterion.json"
if "$PIOLA" run "$work/criterion.json" -o "$work/c" >"$work/log" 2>&1; then echo "FAIL: criterion accepted"; exit 1; fi
grep -q "solids\[0\].fracture.criterion" "$work/log" || { echo "FAIL: criterion message:"; cat "$work/log"; exit 1; }
[[ ! -e "$work/c/stats.csv" ]] || { echo "FAIL: partial output"; exit 1; }
# self_collision with fracture runs (the fragments' contact: tests/test_fracture_contact.c)
sed 's/"fracture": {/"self_collision": {"enabled": true}, "fracture": {/' "$work/scene.json" >"$work/self.json"
"$PIOLA" run "$work/self.json" -o "$work/s" >"$work/log" 2>&1 ||
  { echo "FAIL: self_collision with fracture refused"; cat "$work/log"; exit 1; }
# checkpoints cover the cut state (resume checks: run_resume_examples.py)
"$PIOLA" run "$work/scene.json" -o "$work/k" --checkpoint-every 1 >"$work/log" 2>&1 ||
  { echo "FAIL: --checkpoint-every refused with fracture"; cat "$work/log"; exit 1; }
ls "$work/k"/checkpoint_*.bin >/dev/null 2>&1 || { echo "FAIL: no checkpoint written"; exit 1; }
# a cut by a triangle surface (path relative to the scene) splits the box in two; a blade
# file that does not parse, or is missing, is refused naming the key path and the file's line
cat >"$work/blade.obj" <<'OBJ'
v 0.02 -1 -1
v 0.02 1 -1
v 0.02 1 1
v 0.02 -1 1
f 1 2 3
f 1 3 4
OBJ
sed 's/"plane": {"point": \[0.02, 0, 0\], "normal": \[1, 0.2, 0.1\]}/"mesh": "blade.obj"/' "$work/scene.json" >"$work/blade.json"
grep -q '"mesh": "blade.obj"' "$work/blade.json" || { echo "FAIL: blade scene not made"; exit 1; }
"$PIOLA" run "$work/blade.json" -o "$work/b" --frames 1 >"$work/log" 2>&1 || { cat "$work/log"; exit 1; }
awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "fragments") c = i } NR == 2 { exit $c != 2 }' "$work/b/stats.csv" ||
  { echo "FAIL: the blade did not split the box"; cat "$work/b/stats.csv"; exit 1; }
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' >"$work/blade.obj"
if "$PIOLA" run "$work/blade.json" -o "$work/bb" >"$work/log" 2>&1; then echo "FAIL: bad blade accepted"; exit 1; fi
grep -q "solids\[0\].fracture.cuts\[0\].mesh: .*blade.obj.*4" "$work/log" || { echo "FAIL: bad blade message:"; cat "$work/log"; exit 1; }
[[ ! -e "$work/bb/stats.csv" ]] || { echo "FAIL: partial output"; exit 1; }
rm "$work/blade.obj"
if "$PIOLA" run "$work/blade.json" -o "$work/bm" >"$work/log" 2>&1; then echo "FAIL: missing blade accepted"; exit 1; fi
grep -q "solids\[0\].fracture.cuts\[0\].mesh: .*blade.obj" "$work/log" || { echo "FAIL: missing blade message:"; cat "$work/log"; exit 1; }
sed 's/"mesh": "blade.obj"/"mesh": "blade.obj", "plane": {"point": [0, 0, 0], "normal": [1, 0, 0]}/' "$work/blade.json" >"$work/both.json"
if "$PIOLA" run "$work/both.json" -o "$work/both" >"$work/log" 2>&1; then echo "FAIL: plane and mesh accepted"; exit 1; fi
grep -q "solids\[0\].fracture.cuts\[0\]" "$work/log" || { echo "FAIL: plane and mesh message:"; cat "$work/log"; exit 1; }
echo "ok   fracture frames and refusals"
