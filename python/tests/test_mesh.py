"""Mesh files through Python, checked against meshio, and the mesher."""
import os

import meshio
import numpy as np
import pytest

import piola
from conftest import data


def meshio_cells(m, kind):
    blocks = [c.data for c in m.cells if c.type == kind]
    return np.concatenate(blocks) if blocks else np.zeros((0, 4 if kind == "tetra" else 3), int)


def volume(points, tets):
    a, b, c, d = (points[tets[:, k]] for k in range(4))
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6


@pytest.fixture(scope="module")
def ball():
    return piola.generate_mesh("sphere", radius=0.1, cell_size=0.025)


def test_generated_sphere_is_a_ball(ball):
    assert ball.tets.dtype == np.int32 and ball.points.dtype == np.float64
    vol = volume(ball.points, ball.tets)
    assert np.all(vol > 0)
    assert vol.sum() == pytest.approx(4 / 3 * np.pi * 0.1**3, rel=0.05)
    assert np.linalg.norm(ball.points, axis=1).max() == pytest.approx(0.1, rel=1e-6)
    union = piola.generate_mesh(shapes=[{"shape": "box", "half_extents": [0.1, 0.1, 0.02]},
                                        {"shape": "sphere", "center": [0, 0, 0.05], "radius": 0.05}],
                                cell_size=0.02, refinement_levels=1)
    assert volume(union.points, union.tets).sum() > 0.2 * 0.2 * 0.04


@pytest.mark.parametrize("ext", [".msh", ".vtu", ".mesh", ".node"])
def test_tet_round_trip_against_meshio(tmp_path, ball, ext):
    path = str(tmp_path / f"ball{ext}")
    piola.write_mesh(path, ball.points, ball.tets)
    m = meshio.read(path)
    assert np.allclose(m.points, ball.points, rtol=0, atol=1e-12 * 0.1)
    assert np.array_equal(meshio_cells(m, "tetra"), ball.tets)
    back = piola.read_mesh(path)
    assert np.allclose(back.points, ball.points, atol=1e-15)
    assert np.array_equal(back.tets, ball.tets)


@pytest.mark.parametrize("fmt,ext", [("gmsh22", ".msh"), ("vtu", ".vtu"), ("medit", ".mesh")])
def test_reads_what_meshio_writes(tmp_path, ball, fmt, ext):
    path = str(tmp_path / f"m{ext}")
    meshio.write(path, meshio.Mesh(ball.points, [("tetra", ball.tets.astype(np.int64))]),
                 file_format=fmt, **{"gmsh22": {"binary": False}, "vtu": {"compression": None}}.get(fmt, {}))
    back = piola.read_mesh(path)
    assert np.allclose(back.points, ball.points, atol=1e-12)
    assert np.array_equal(back.tets, ball.tets)


@pytest.mark.parametrize("ext", [".obj", ".off", ".stl"])
def test_surfaces_round_trip(tmp_path, ball, ext):
    tris = piola.boundary_surface(ball.points, ball.tets)
    used = np.unique(tris)
    path = str(tmp_path / f"s{ext}")
    piola.write_mesh(path, ball.points, ball.tets)  # tets to a surface format: the boundary
    back = piola.read_mesh(path)
    assert back.tets is None and len(back.triangles) == len(tris)
    m = meshio.read(path)
    assert len(meshio_cells(m, "triangle")) == len(tris)
    # the same set of triangle corner positions, whatever the vertex numbering
    key = lambda p, t: np.sort(np.round(p[t].reshape(len(t), 9), 9), axis=0)
    assert np.allclose(key(back.points, back.triangles), key(ball.points, tris), atol=1e-6)
    assert len(back.points) >= len(used)  # .obj keeps unused points, STL welds them away
    piola.write_mesh(str(tmp_path / f"again{ext}"), back)
    again = piola.read_mesh(str(tmp_path / f"again{ext}"))
    assert np.array_equal(again.triangles, back.triangles)


def test_shared_meshes_agree_with_meshio():
    for parts in [("gmsh", "bunny.msh"), ("medit", "unit_ball.mesh"), ("tetgen", "octahedron.node")]:
        path = data(*parts)
        mine = piola.read_mesh(path)
        theirs = meshio.read(path)
        assert len(mine.points) == len(theirs.points) and len(mine.tets) == len(meshio_cells(theirs, "tetra"))
        assert np.all(volume(mine.points, mine.tets) > 0)  # oriented on load
    veg = piola.read_mesh(data("vega", "beam3_tet.veg"))
    assert len(veg.tets) > 0


@pytest.mark.parametrize("ext", [".msh", ".vtu", ".mesh", ".node"])
def test_regions_and_fibers_survive(tmp_path, ball, ext):
    m = len(ball.tets)
    regions = (np.arange(m) % 3 + 1).astype(np.int32)
    fibers = np.tile([0.0, 0.6, 0.8], (m, 1))
    path = str(tmp_path / f"f{ext}")
    piola.write_mesh(path, ball.points, ball.tets, regions=regions, fibers=fibers)
    back = piola.read_mesh(path)
    assert np.array_equal(back.regions, regions)
    if ext in (".msh", ".vtu"):
        assert np.allclose(back.fibers, fibers)


def test_uncovered_tets_keep_region_minus_one(tmp_path):
    # Vega: a tet no *REGION covers is region -1 (file-formats.md); it reads, and adds
    veg = tmp_path / "uncovered.veg"
    veg.write_text("*VERTICES\n5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n"
                   "*ELEMENTS\nTET\n2 4 0\n1 1 2 3 4\n2 2 3 4 5\n"
                   "*MATERIAL hard\nENU, 2000, 1e7, 0.45\n*SET s1\n1,\n*REGION\ns1, hard\n")
    mesh = piola.read_mesh(str(veg))
    assert list(mesh.regions) == [0, -1]
    world = piola.World()
    world.add_solid(str(veg))
    # and a VTU with a negative region round-trips it
    path = str(tmp_path / "back.vtu")
    piola.write_mesh(path, mesh)
    assert list(piola.read_mesh(path).regions) == [0, -1]


def test_bad_files_and_arguments(tmp_path, ball):
    bad = tmp_path / "bad.msh"
    bad.write_text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nnonsense\n")
    with pytest.raises(piola.MeshError, match="bad.msh"):
        piola.read_mesh(str(bad))
    with pytest.raises(piola.MeshError):
        piola.read_mesh(str(tmp_path / "missing.vtu"))
    with pytest.raises(ValueError, match="extension"):
        piola.read_mesh("mesh.xyz")
    with pytest.raises(ValueError, match="extension"):
        piola.write_mesh(str(tmp_path / "m.ply"), ball.points, ball.tets)
    with pytest.raises(ValueError, match="refer to point"):
        piola.write_mesh(str(tmp_path / "m.vtu"), ball.points[:4], ball.tets)
    with pytest.raises(TypeError, match="integers"):
        piola.write_mesh(str(tmp_path / "m.vtu"), ball.points, ball.tets.astype(float) + 0.5)
    with pytest.raises(ValueError, match="triangles are written"):
        piola.write_mesh(str(tmp_path / "m.vtu"), ball.points, ball.tets[:, :3])
    assert not os.path.exists(tmp_path / "m.vtu")
    with pytest.raises(piola.MeshError, match="cell_size"):
        piola.generate_mesh("sphere", radius=0.1, cell_size=0)
    with pytest.raises(ValueError, match="needs 'radius'"):
        piola.generate_mesh("sphere", cell_size=0.1)
    with pytest.raises(ValueError, match="unknown key"):
        piola.generate_mesh("sphere", radius=0.1, radious=0.2, cell_size=0.1)
    # the mesher's range (mesher.md), refused before the mesher runs
    with pytest.raises(ValueError, match=r"refinement_levels must be in 0\.\.6, got 7"):
        piola.generate_mesh("sphere", radius=0.1, cell_size=0.1, refinement_levels=7)
    # an open surface is refused by the mesher, naming an edge
    tris = piola.boundary_surface(ball.points, ball.tets)[1:]
    with pytest.raises(piola.MeshError):
        piola.generate_mesh("surface", surface=(ball.points, tris), cell_size=0.05)
    # the extension refuses what the package would have converted
    with pytest.raises(TypeError, match="dtype"):
        piola._piola.write_tet_mesh(str(tmp_path / "x.vtu"), ball.points, ball.tets.astype(np.int64), None, None)


def test_mesh_a_closed_surface(ball):
    tris = piola.boundary_surface(ball.points, ball.tets)
    m = piola.generate_mesh("surface", surface=piola.Mesh(ball.points, triangles=tris), cell_size=0.02)
    assert volume(m.points, m.tets).sum() == pytest.approx(volume(ball.points, ball.tets).sum(), rel=0.1)
