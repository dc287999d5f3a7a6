"""Checks behind test_mesh_fibers.sh (see there)."""
import json
import os
import shutil
import subprocess
import tempfile

import meshio
import numpy as np

from script_checks import DATA, PIOLA, check, finish, run


def tets_and_fibers(path):
    """The tets of a file as meshio reads them, and their 'fiber' (or 'fibers') cell data."""
    m = meshio.read(path)
    tets, fibers = [], []
    for block, cell in enumerate(m.cells):
        if cell.type != "tetra":
            continue
        tets.append(cell.data)
        data = m.cell_data.get("fiber", m.cell_data.get("fibers"))
        fibers.append(None if data is None else np.asarray(data[block]).reshape(len(cell.data), -1))
    tets = np.concatenate(tets)
    fibers = None if any(f is None for f in fibers) else np.concatenate(fibers)
    return m, tets, fibers


def expect_failure(path, *parts):
    r = subprocess.run([PIOLA, "mesh", "info", path], capture_output=True, text=True)
    message = r.stderr.strip()
    check(r.returncode != 0 and all(p in message for p in parts),
          f"{os.path.basename(path)} is refused naming {parts}: '{message}'")


work = tempfile.mkdtemp(prefix="piola_mesh_fibers_")
try:
    # a real gmsh mesh (tets plus its boundary triangles and lines) with a fibre per cell
    base = os.path.join(work, "box.msh")
    run("gmsh", "-3", os.path.join(DATA, "box.geo"), "-format", "msh22", "-o", base)
    src = meshio.read(base)
    rng = np.random.default_rng(8)
    cell_fibers = []
    for cell in src.cells:
        f = rng.normal(size=(len(cell.data), 3))
        if cell.type == "tetra":  # unit directions, and a few of other lengths (kept as given)
            f /= np.linalg.norm(f, axis=1)[:, None]
            f[::7] *= 2.5
            f[3] = 0.0
        cell_fibers.append(f)
    expected_tets = np.concatenate([c.data for c in src.cells if c.type == "tetra"])
    tet_fibers = np.concatenate([f for c, f in zip(src.cells, cell_fibers) if c.type == "tetra"])
    mixed = meshio.Mesh(src.points, src.cells, cell_data={"fiber": cell_fibers})
    tet_only = meshio.Mesh(src.points, [c for c in src.cells if c.type == "tetra"],
                           cell_data={"fibers": [tet_fibers]})
    inputs = {
        "meshio.vtu": (mixed, dict(file_format="vtu", binary=False)),
        "meshio_base64.vtu": (mixed, dict(file_format="vtu", compression=None)),
        "meshio_v22.msh": (mixed, dict(file_format="gmsh22", binary=False)),
        "meshio_v22_bin.msh": (mixed, dict(file_format="gmsh22", binary=True)),
        "meshio_v41.msh": (tet_only, dict(file_format="gmsh", binary=False)),
        "meshio_v41_bin.msh": (tet_only, dict(file_format="gmsh", binary=True)),
    }
    for name, (mesh, kwargs) in inputs.items():
        path = os.path.join(work, name)
        mesh.write(path, **kwargs)
        # what the file holds (meshio's ASCII .vtu rounds to 11 digits): piola must keep it exactly
        _, _, expected = tets_and_fibers(path)
        for ext in ["vtu", "msh"]:
            out = os.path.join(work, f"{name}.piola.{ext}")
            run(PIOLA, "mesh", "convert", path, out)
            info = json.loads(run(PIOLA, "mesh", "info", "--json", out).stdout)
            check(info["fibers"] is True, f"{name} -> piola .{ext}: `piola mesh info` reports fibres")
            m, tets, fibers = tets_and_fibers(out)
            same_tets = tets.shape == expected_tets.shape and np.array_equal(
                np.sort(tets, axis=1), np.sort(expected_tets, axis=1))
            check(same_tets, f"{name} -> piola .{ext} -> meshio: the same {len(expected_tets)} tets in order")
            check(fibers is not None and fibers.shape == expected.shape and np.array_equal(fibers, expected),
                  f"{name} -> piola .{ext} -> meshio: every tet's fibre, bit for bit")
    # piola's own files read back by piola: .vtu -> .msh -> .vtu keeps them too
    _, _, expected = tets_and_fibers(os.path.join(work, "meshio_v22.msh"))
    first = os.path.join(work, "meshio_v22.msh.piola.msh")
    again = os.path.join(work, "again.vtu")
    run(PIOLA, "mesh", "convert", first, again)
    _, _, fibers = tets_and_fibers(again)
    check(fibers is not None and np.array_equal(fibers, expected), "piola .msh -> piola .vtu: fibres kept")

    plain = os.path.join(work, "plain.vtu")
    run(PIOLA, "mesh", "convert", base, plain)
    check(json.loads(run(PIOLA, "mesh", "info", "--json", plain).stdout)["fibers"] is False,
          "a mesh without fibres: `piola mesh info` reports none, and none are written")
    check(tets_and_fibers(plain)[2] is None, "a mesh without fibres gets no fiber array")

    # ---- bad data is refused with the file and the array or line named
    two = meshio.Mesh(src.points, [c for c in src.cells if c.type == "tetra"],
                      cell_data={"fiber": [tet_fibers[:, :2].copy()]})
    bad_vtu = os.path.join(work, "two_components.vtu")
    two.write(bad_vtu, binary=False)
    expect_failure(bad_vtu, "two_components.vtu", "'fiber'", "2 components, expected 3")
    text = open(os.path.join(work, "meshio_v22.msh")).read()
    head, rest = text.split("$ElementData\n", 1)
    lines = rest.split("\n")
    # header: 1, "fiber", 1, 0.0, 3, 0, 3, count; then the entries
    count = int(lines[7])
    short = lines[:7] + [str(count - 5)] + lines[8:8 + count - 5] + lines[8 + count:]
    bad_count = os.path.join(work, "missing_fibres.msh")
    open(bad_count, "w").write(head + "$ElementData\n" + "\n".join(short))
    section_line = head.count("\n") + 1
    expect_failure(bad_count, f"missing_fibres.msh:{section_line}:", "$ElementData \"fiber\"", "tets have no fibre")
    wrong = lines[:6] + ["2"] + lines[7:]
    bad_components = os.path.join(work, "two_component_view.msh")
    open(bad_components, "w").write(head + "$ElementData\n" + "\n".join(wrong))
    expect_failure(bad_components, "two_component_view.msh:", "has 2 components, expected 3")
    extra = lines[:8] + [lines[8] + " 1.0"] + lines[9:]
    bad_extra = os.path.join(work, "four_values.msh")
    open(bad_extra, "w").write(head + "$ElementData\n" + "\n".join(extra))
    expect_failure(bad_extra, f"four_values.msh:{section_line + 9}:", "more than 3 values")
finally:
    shutil.rmtree(work, ignore_errors=True)

finish()
