"""piola: invertible finite elements for large-deformation solids, from Python.

See docs/python.md. Units are SI throughout: m, s, kg, Pa, J.
"""
from ._piola import (ClosedError, Error, MeshError, SceneError, SimulationError)
from .material import Material, diagonalize
from .mesh import Mesh, read_mesh, write_mesh, generate_mesh, boundary_surface, read_vtu
from .world import World, Body, Obstacle, SimulationWarning
from .scene import Scene
from ._piola import set_thread_count, __version__

__all__ = [
    "Error", "SceneError", "MeshError", "SimulationError", "ClosedError", "SimulationWarning",
    "Material", "diagonalize",
    "Mesh", "read_mesh", "write_mesh", "generate_mesh", "boundary_surface", "read_vtu",
    "World", "Body", "Obstacle", "Scene", "set_thread_count", "__version__",
]
