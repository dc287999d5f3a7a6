"""Mesh files and the built-in mesher (docs/file-formats.md, docs/mesher.md)."""
import os

import numpy as np

from . import _piola
from ._convert import check_keys, float_array, index_array, int32_array, integer, number, vec3

TET_READ = (".node", ".ele", ".msh", ".mesh", ".veg", ".vtu")
TET_WRITE = (".msh", ".vtu", ".obj", ".node", ".mesh")
SURFACE_READ = (".obj", ".off", ".stl")
SURFACE_WRITE = (".obj", ".off", ".stl")


class Mesh:
    """A tetrahedral mesh (tets set) or a triangle surface (triangles set).

    points (n, 3) float64 in m; tets (m, 4) or triangles (k, 3) int32 point indices;
    regions (m,) int32 region ids and fibers (m, 3) per-tet fibre directions when the file has
    them, else None. Unpacks as (points, cells)."""

    def __init__(self, points, tets=None, triangles=None, regions=None, fibers=None):
        if (tets is None) == (triangles is None):
            raise ValueError("a Mesh has either tets or triangles")
        self.points = float_array(points, "points", (-1, 3))
        n = len(self.points)
        self.tets = None if tets is None else _cells(tets, "tets", 4, n)
        self.triangles = None if triangles is None else _cells(triangles, "triangles", 3, n)
        m = len(self.cells)
        self.regions = None if regions is None else int32_array(regions, "regions", (m,))
        self.fibers = None if fibers is None else float_array(fibers, "fibers", (m, 3))

    @property
    def cells(self):
        """tets or triangles, whichever the mesh has."""
        return self.tets if self.tets is not None else self.triangles

    def __iter__(self):
        return iter((self.points, self.cells))

    def __repr__(self):
        kind = "tets" if self.tets is not None else "triangles"
        return f"Mesh({len(self.points)} points, {len(self.cells)} {kind})"


def _cells(value, what, width, n):
    cells = index_array(value, what, (-1, width))
    if cells.size and cells.max() >= n:
        raise ValueError(f"{what} refer to point {int(cells.max())}, but there are {n} points")
    return cells


def _extension(path):
    path = os.fspath(path)
    return path, os.path.splitext(path)[1].lower()


def read_mesh(path):
    """Reads a tetrahedral mesh (.node/.ele, .msh, .mesh, .veg, .vtu) or a triangle surface
    (.obj, .off, .stl), chosen by extension. Raises MeshError naming the file and line."""
    path, ext = _extension(path)
    if ext in SURFACE_READ:
        points, triangles = _piola.read_tri_mesh(path)
        return Mesh(points, triangles=triangles)
    if ext in TET_READ:
        points, tets, regions, fibers = _piola.read_tet_mesh(path)
        return Mesh(points, tets=tets, regions=regions, fibers=fibers)
    raise ValueError(f"{path}: unknown mesh extension {ext!r} (tets: {', '.join(TET_READ)}; "
                     f"surfaces: {', '.join(SURFACE_READ)})")


def write_mesh(path, points, cells=None, regions=None, fibers=None):
    """Writes points (n, 3) and cells: tets (m, 4) to .msh (Gmsh 4.1), .vtu, .node (+ .ele),
    .mesh (Medit) or .obj (the boundary surface); triangles (k, 3) to .obj, .off or .stl.
    write_mesh(path, mesh) writes a Mesh. The file is written whole or not at all."""
    if isinstance(points, Mesh):
        mesh = points
        points, cells = mesh.points, mesh.cells
        regions = mesh.regions if regions is None else regions
        fibers = mesh.fibers if fibers is None else fibers
    path, ext = _extension(path)
    points = float_array(points, "points", (-1, 3))
    if cells is None:
        raise TypeError("write_mesh needs cells (tets or triangles)")
    width = np.shape(cells)[-1] if np.ndim(cells) == 2 else None
    if width == 4:
        tets = _cells(cells, "tets", 4, len(points))
        if ext in TET_WRITE:
            r = None if regions is None else int32_array(regions, "regions", (len(tets),))
            f = None if fibers is None else float_array(fibers, "fibers", (len(tets), 3))
            _piola.write_tet_mesh(path, points, tets, r, f)
            return
        if ext in SURFACE_WRITE:
            _piola.write_tri_mesh(path, points, _piola.tet_mesh_boundary(points, tets))
            return
    elif width == 3:
        if ext in SURFACE_WRITE:
            _piola.write_tri_mesh(path, points, _cells(cells, "triangles", 3, len(points)))
            return
        raise ValueError(f"{path}: triangles are written to {', '.join(SURFACE_WRITE)}")
    else:
        raise ValueError(f"cells must have shape (m, 4) (tets) or (k, 3) (triangles), got "
                         f"{np.shape(cells)}")
    raise ValueError(f"{path}: unknown mesh extension {ext!r} (tets: {', '.join(TET_WRITE)}; "
                     f"surfaces: {', '.join(SURFACE_WRITE)})")


def read_vtu(path):
    """Reads a VTK UnstructuredGrid file with its fields, e.g. a frame that Scene.run or
    `piola run` wrote (frames/frame_NNNN.vtu; its fields are listed in docs/cli.md). Returns a
    dict: points (n, 3) m, tets (m, 4), triangles (k, 3), point_data and cell_data
    ({name: (count,) or (count, components) float64}), and tet_cells, triangle_cells: each
    element's index among all cells, which cell_data is indexed by. Raises MeshError."""
    points, tets, triangles, point_data, cell_data, tet_cells, triangle_cells = \
        _piola.read_vtu(os.fspath(path))
    return {"points": points, "tets": tets, "triangles": triangles, "point_data": point_data,
            "cell_data": cell_data, "tet_cells": tet_cells, "triangle_cells": triangle_cells}


def boundary_surface(points, tets):
    """The boundary triangles (k, 3) of a tet mesh, wound outward, same point numbering."""
    points = float_array(points, "points", (-1, 3))
    return _piola.tet_mesh_boundary(points, _cells(tets, "tets", 4, len(points)))


_SHAPE_KEYS = {
    "sphere": ("radius",),
    "box": ("half_extents",),
    "torus": ("radius", "minor_radius"),
    "cylinder": ("radius", "half_length"),
    "capsule": ("radius", "half_length"),
    "surface": ("surface",),
}


def _shape_tuple(d, what):
    if not isinstance(d, dict):
        raise TypeError(f"{what} must be a dict, got {type(d).__name__}")
    shape = d.get("shape")
    if shape not in _SHAPE_KEYS:
        raise ValueError(f"{what}.shape must be one of {', '.join(_SHAPE_KEYS)}, got {shape!r}")
    required = _SHAPE_KEYS[shape]
    check_keys(d, ("shape", "center", "axis") + required, what)
    for k in required:
        if k not in d:
            raise ValueError(f"{what}: {shape} needs {k!r}")
    center = vec3(d.get("center", (0, 0, 0)), f"{what}.center")
    axis = np.asarray(vec3(d.get("axis", (0, 0, 1)), f"{what}.axis"))
    norm = float(np.linalg.norm(axis))
    if norm == 0:
        raise ValueError(f"{what}.axis must be nonzero")
    axis = tuple(float(a) for a in axis / norm)
    pts = tris = None
    if shape == "surface":
        surface = d["surface"]
        if isinstance(surface, (str, os.PathLike)):
            surface = read_mesh(surface)
        pts, tris = surface
        pts = float_array(pts, f"{what}.surface points", (-1, 3))
        tris = _cells(tris, f"{what}.surface triangles", 3, len(pts))
    he = d.get("half_extents", (0, 0, 0))
    return (_piola.SHAPE_TYPES[shape], center, axis,
            number(d.get("radius", 0.0), f"{what}.radius"),
            number(d.get("minor_radius", 0.0), f"{what}.minor_radius"),
            number(d.get("half_length", 0.0), f"{what}.half_length"),
            vec3(he, f"{what}.half_extents"), pts, tris)


def generate_mesh(shape=None, *, cell_size, refinement_levels=0, shapes=None, **params):
    """Meshes a shape, or the union of several, with the BCC mesher; returns a tet Mesh.

        generate_mesh("sphere", radius=0.1, cell_size=0.02)
        generate_mesh(shapes=[{"shape": "box", "half_extents": [0.1, 0.1, 0.02]},
                              {"shape": "sphere", "center": [0, 0, 0.05], "radius": 0.05}],
                      cell_size=0.01, refinement_levels=1)
        generate_mesh("surface", surface="bunny.obj", cell_size=0.05)

    Shapes: sphere (radius), box (half_extents), torus (radius, minor_radius), cylinder and
    capsule (radius, half_length), surface (a closed surface: a Mesh, (points, triangles) or a
    path); all take center (m, default origin) and axis (default (0, 0, 1)). Lengths in m.
    cell_size (m, > 0): lattice spacing; refinement_levels (0..6): grading toward the
    surface. Raises MeshError (e.g. an open surface) or ValueError."""
    if (shape is None) == (shapes is None):
        raise TypeError("give one shape (with its parameters) or shapes=[...]")
    if shapes is None:
        shapes = [dict(params, shape=shape)]
    elif params:
        raise TypeError("shape parameters go inside each dict of shapes")
    if not isinstance(shapes, (list, tuple)):
        raise TypeError("shapes must be a list of dicts")
    levels = integer(refinement_levels, "refinement_levels")
    if not 0 <= levels <= 6:
        raise ValueError(f"refinement_levels must be in 0..6, got {levels}")
    tuples = [_shape_tuple(s, f"shapes[{i}]") for i, s in enumerate(shapes)]
    points, tets = _piola.generate_mesh(tuples, number(cell_size, "cell_size"), levels)
    return Mesh(points, tets=tets)
