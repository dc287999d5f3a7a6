"""Checks behind test_mesh_roundtrip.sh (see there)."""
import json
import math
import os
import shutil
import tempfile

import meshio
import numpy as np
import vtk

from script_checks import DATA, PIOLA, check, finish, run


def info(path):
    return json.loads(run(PIOLA, "mesh", "info", "--json", path).stdout)


def meshio_tets(path):
    m = meshio.read(path)
    tets = [c.data for c in m.cells if c.type == "tetra"]
    return m, (np.concatenate(tets) if tets else np.zeros((0, 4), int))


def vtk_read(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


work = tempfile.mkdtemp(prefix="piola_mesh_roundtrip_")
try:
    # ---- gmsh-made meshes, every format variant
    cases = [("box.geo", 1.0, 0.0), ("two_boxes.geo", 2.0, 0.0), ("cylinder.geo", math.pi / 2, 0.03)]
    for geo, volume, tolerance in cases:
        stem = os.path.splitext(geo)[0]
        variants = {}
        for fmt, binary in [("msh41", False), ("msh22", False), ("msh41", True), ("msh22", True)]:
            out = os.path.join(work, f"{stem}_{fmt}{'_bin' if binary else ''}.msh")
            run("gmsh", "-3", os.path.join(DATA, geo), "-format", fmt, *(["-bin"] if binary else []), "-o", out)
            variants[(fmt, binary)] = out
            j = info(out)
            m, tets = meshio_tets(out)
            check(j["tets"] == len(tets), f"{os.path.basename(out)}: {j['tets']} tets, meshio {len(tets)}")
            check(j["vertices"] == len(m.points), f"{os.path.basename(out)}: {j['vertices']} vertices, meshio {len(m.points)}")
            check(abs(j["volume"] - volume) <= tolerance * volume + 1e-9,
                  f"{os.path.basename(out)}: volume {j['volume']:.6f}, geometry {volume:.6f}")
            check(j["closed"] and j["manifold"], f"{os.path.basename(out)}: boundary closed and manifold")
            check(0 < j["min_dihedral_degrees"] < j["max_dihedral_degrees"] < 180, f"{os.path.basename(out)}: dihedral range")
        # all four variants are the same mesh
        infos = [info(p) for p in variants.values()]
        check(len({(i["vertices"], i["tets"], i["boundary_faces"]) for i in infos}) == 1,
              f"{stem}: the four msh variants agree")
        if stem == "two_boxes":
            regions = {r["id"]: r["tets"] for r in infos[0]["regions"]}
            check(set(regions) == {1, 2}, f"two_boxes: physical groups 1 and 2 -> regions {sorted(regions)}")
        # ---- piola writes, others read
        src = variants[("msh41", False)]
        src_mesh, src_tets = meshio_tets(src)
        for ext in ["msh", "vtu", "node", "mesh"]:
            out = os.path.join(work, f"{stem}_piola.{ext}")
            run(PIOLA, "mesh", "convert", src, out)
            j = info(out) if ext != "vtu" else None
            if j:
                check(j["tets"] == len(src_tets) and j["vertices"] == len(src_mesh.points),
                      f"{stem} -> .{ext} -> piola: counts kept")
            if ext in ("msh", "vtu", "mesh"):
                m, tets = meshio_tets(out)
                check(len(tets) == len(src_tets) and np.array_equal(m.points, src_mesh.points),
                      f"{stem} -> .{ext} -> meshio: same points ({len(m.points)}) and tet count ({len(tets)})")
                # same tets as vertex sets (piola orients tets, which may swap two corners)
                check(np.array_equal(np.sort(tets, axis=1), np.sort(src_tets, axis=1)),
                      f"{stem} -> .{ext} -> meshio: same tets")
            if ext == "msh":
                phys = src_mesh.cell_data_dict.get("gmsh:physical", {}).get("tetra")
                m = meshio.read(out)
                got = m.cell_data_dict.get("gmsh:physical", {}).get("tetra")
                if phys is not None:
                    check(got is not None and sorted(np.unique(got)) == sorted(np.unique(phys)),
                          f"{stem} -> .msh: physical groups kept for meshio")
                # gmsh itself reads piola's file
                again = os.path.join(work, f"{stem}_gmsh_again.msh")
                run("gmsh", "-0", out, "-format", "msh22", "-o", again)
                check(info(again)["tets"] == len(src_tets), f"{stem} -> .msh -> gmsh -> msh22: tets kept")
            if ext == "vtu":
                g = vtk_read(out)
                types = {g.GetCellType(i) for i in range(g.GetNumberOfCells())}
                check(g.GetNumberOfPoints() == len(src_mesh.points) and g.GetNumberOfCells() == len(src_tets)
                      and types == {10}, f"{stem} -> .vtu -> VTK: {g.GetNumberOfPoints()} points, "
                      f"{g.GetNumberOfCells()} cells of types {sorted(types)}")
                region = g.GetCellData().GetArray("region")
                check(region is not None and region.GetNumberOfTuples() == len(src_tets),
                      f"{stem} -> .vtu -> VTK: cell field 'region'")
        # boundary surface as OBJ/STL: closed, same volume
        for ext in ["obj", "stl", "off"]:
            out = os.path.join(work, f"{stem}_boundary.{ext}")
            run(PIOLA, "mesh", "convert", src, out)
            s = info(out)
            check(s["closed"] and s["manifold"] and s["oriented"] and abs(s["volume"] - infos[0]["volume"]) <= 1e-5 * volume,
                  f"{stem} -> boundary .{ext}: closed, outward, encloses the mesh volume")
            m = meshio.read(out)
            check(sum(len(c.data) for c in m.cells if c.type == "triangle") == infos[0]["boundary_faces"],
                  f"{stem} -> boundary .{ext} -> meshio: triangle count")

    # ---- second-order tets (Gmsh type 11): piola keeps the corners
    for fmt in ["msh41", "msh22"]:
        out = os.path.join(work, f"box_order2_{fmt}.msh")
        run("gmsh", "-3", "-order", "2", os.path.join(DATA, "box.geo"), "-format", fmt, "-o", out)
        m = meshio.read(out)
        tet10 = sum(len(c.data) for c in m.cells if c.type == "tetra10")
        j = info(out)
        check(tet10 > 0 and j["tets"] == tet10 and j["vertices"] == len(m.points),
              f"box order 2 {fmt}: {j['tets']} tets from {tet10} tetra10, {j['vertices']} vertices")
        check(abs(j["volume"] - 1.0) < 1e-9 and j["closed"], f"box order 2 {fmt}: corner tets fill the box")

    # ---- tetgen-made meshes, 1-based and 0-based (-z)
    for flags, label in [("-pqQ", "1-based"), ("-pqQz", "0-based")]:
        sub = os.path.join(work, label)
        os.makedirs(sub)
        shutil.copy(os.path.join(DATA, "cube.poly"), sub)
        run("tetgen", flags, "-a0.005", os.path.join(sub, "cube.poly"))
        node = os.path.join(sub, "cube.1.node")
        with open(node) as f:
            nv = int(f.readline().split()[0])
        with open(os.path.join(sub, "cube.1.ele")) as f:
            nt = int(f.readline().split()[0])
        j = info(node)
        check(j["vertices"] == nv and j["tets"] == nt, f"tetgen {label}: {j['vertices']} vertices, {j['tets']} tets (file: {nv}, {nt})")
        check(abs(j["volume"] - 1.0) < 1e-12, f"tetgen {label}: unit cube volume {j['volume']!r}")
        check(j["closed"] and j["manifold"] and j["euler_characteristic"] == 2, f"tetgen {label}: closed boundary")
        out = os.path.join(sub, "back.node")
        run(PIOLA, "mesh", "convert", node, out)
        j2 = info(out)
        check(j2["tets"] == nt and abs(j2["volume"] - 1.0) < 1e-12, f"tetgen {label} -> piola .node/.ele -> piola")
        # tetgen itself reads piola's .node (as a point set to re-mesh)
        run("tetgen", "-Q", out)
        check(os.path.exists(os.path.join(sub, "back.1.ele")), f"tetgen {label}: tetgen reads piola's .node")
    # a sliver mesh remeshed inside its boundary (the sliver warning's suggestion, docs/cli.md)
    bunny = os.path.join(os.environ["PIOLA_DATA_DIR"], "gmsh", "bunny.msh")
    remeshed = os.path.join(work, "bunny_remeshed.msh")
    run(PIOLA, "mesh", "generate", bunny, "-o", remeshed)
    before, after = info(bunny), info(remeshed)
    check(after["min_dihedral_degrees"] > 5 > before["min_dihedral_degrees"],
          f"bunny.msh remeshed: smallest dihedral {before['min_dihedral_degrees']} -> {after['min_dihedral_degrees']} degrees")
    check(abs(after["volume"] - before["volume"]) < 0.1 * before["volume"] and after["closed"],
          f"bunny.msh remeshed: volume {before['volume']} -> {after['volume']} m^3, closed boundary")
finally:
    shutil.rmtree(work, ignore_errors=True)

finish()
