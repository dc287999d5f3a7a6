"""Worlds of elastic solids and rigid obstacles, stepped from Python (docs/python.md).

A body's positions and velocities are NumPy views of the world's own memory, without a copy.
Views of a body's positions and velocities are writable: a write between steps is picked up
by the next step (the body's forces are recomputed from it). Rest positions, masses, cells and
constraint flags are read-only views. A view keeps the world's
memory alive: after World.close() every call raises ClosedError, and existing views keep
the last state until they are dropped."""
import numbers
import warnings as _warnings

import numpy as np

from . import _piola
from ._convert import (check_keys, finite_array, finite_number, float_array, index_array, integer,
                       number, track, tracks3, vec3)
from .material import Material
from .mesh import Mesh, read_mesh

_DEFAULTS = _piola.defaults()


class SimulationWarning(UserWarning):
    """A condition a run survives but its user should hear about (docs/cli.md, "Warnings"):
    issued through Python's warnings module by World.advance_to and World.step, once per
    kind and world."""
_AXIS_TYPES = ("cylinder", "capsule", "torus", "gear")


def _motion(m, what, default_pivot, default_axis):
    """The extension's motion tuple from a scene-style `motion` dict (or None: at rest)."""
    m = {} if m is None else m
    check_keys(m, ("velocity", "angular_speed", "translation", "angle", "axis", "pivot"), what)
    pose = "translation" in m or "angle" in m
    if pose and ("velocity" in m or "angular_speed" in m):
        raise ValueError(f"{what}: give velocity/angular_speed or translation/angle, not both")
    axis = np.asarray(vec3(m.get("axis", default_axis), f"{what}.axis"))
    if not np.linalg.norm(axis) > 0:
        raise ValueError(f"{what}.axis must be nonzero")
    axis = tuple(float(a) for a in axis / np.linalg.norm(axis))
    zero3 = (0.0, 0.0, 0.0)
    return (1 if pose else 0, vec3(m.get("pivot", default_pivot), f"{what}.pivot"), axis,
            tracks3(m.get("velocity", zero3), f"{what}.velocity"),
            track(m.get("angular_speed", 0.0), f"{what}.angular_speed"),
            tracks3(m.get("translation", zero3), f"{what}.translation"),
            track(m.get("angle", 0.0), f"{what}.angle"))


class Obstacle:
    """A rigid obstacle: a signed distance (negative inside) moving by a rigid motion.

        Obstacle("plane", point=[0, 0, 0], normal=[0, 0, 1], friction=0.5)
        Obstacle("sphere", center=[0, 0, 0.2], radius=0.1,
                 motion={"velocity": [0, 0, {"keys": [[0, 0], [1, -0.2]]}]})

    The keys are those of a scene's obstacle (docs/scene-format.md, Obstacles): type plane
    (point, normal), sphere (center, radius), box (center, half_extents), cylinder and
    capsule (center, axis, radius, half_length), torus (center, axis, radius, minor_radius),
    gear (center, axis, radius, half_length, teeth, tooth_depth), mesh (surface: a Mesh,
    (points, triangles) or a path; or path: a surface file); friction (Coulomb mu); motion (velocity, angular_speed or
    translation, angle, each keyframable; axis; pivot). Lengths in m, times in s, angles in
    rad. Invalid values raise ValueError."""

    def __init__(self, type, *, friction=0.0, motion=None, **shape):
        if type not in _piola.OBSTACLE_TYPES:
            raise ValueError(f"obstacle type must be one of {', '.join(_piola.OBSTACLE_TYPES)}, "
                             f"got {type!r}")
        allowed = {
            "plane": ("point", "normal"), "sphere": ("center", "radius"),
            "box": ("center", "half_extents"),
            "cylinder": ("center", "axis", "radius", "half_length"),
            "capsule": ("center", "axis", "radius", "half_length"),
            "torus": ("center", "axis", "radius", "minor_radius"),
            "gear": ("center", "axis", "radius", "half_length", "teeth", "tooth_depth"),
            "mesh": ("surface", "path"),
        }[type]
        check_keys(shape, allowed, f"{type} obstacle")
        if type == "mesh":
            if ("surface" in shape) == ("path" in shape):
                raise ValueError("mesh obstacle: give surface (a Mesh or (points, triangles)) "
                                 "or path (a surface file), not both")
            if "path" in shape:
                shape = {"surface": read_mesh(shape["path"])}
        required = {"plane": ("point", "normal"), "sphere": ("radius",), "box": ("half_extents",),
                    "cylinder": ("radius", "half_length"), "capsule": ("radius", "half_length"),
                    "torus": ("radius", "minor_radius"),
                    "gear": ("center", "axis", "radius", "half_length", "teeth"),
                    "mesh": ()}[type]
        for k in required:
            if k not in shape:
                raise ValueError(f"{type} obstacle: {k!r} is required")
        center = vec3(shape.get("point" if type == "plane" else "center", (0, 0, 0)),
                      "point" if type == "plane" else "center")
        axis = np.asarray(vec3(shape.get("normal" if type == "plane" else "axis", (0, 0, 1)),
                               "normal" if type == "plane" else "axis"))
        if not np.linalg.norm(axis) > 0:
            raise ValueError("the obstacle's axis (normal) must be nonzero")
        axis = tuple(float(a) for a in axis / np.linalg.norm(axis))
        radius = number(shape.get("radius", 0.0), "radius")
        points = triangles = None
        if type == "mesh":
            surface = shape["surface"]
            if not isinstance(surface, (Mesh, tuple, list)):
                surface = read_mesh(surface)
            points, triangles = surface
            points = float_array(points, "surface points", (-1, 3))
            triangles = index_array(triangles, "surface triangles", (-1, 3))
        teeth = integer(shape.get("teeth", 0), "teeth")
        depth = number(shape.get("tooth_depth", 0.2 * radius), "tooth_depth")
        default_axis = axis if type in _AXIS_TYPES else (0.0, 0.0, 1.0)
        self.type = type
        self.friction = number(friction, "friction")
        self._def = (_piola.OBSTACLE_TYPES[type], center, axis, radius,
                     number(shape.get("minor_radius", 0.0), "minor_radius"),
                     number(shape.get("half_length", 0.0), "half_length"),
                     vec3(shape.get("half_extents", (0, 0, 0)), "half_extents"),
                     teeth, depth, points, triangles, self.friction,
                     _motion(motion, "motion", center, default_axis))
        self._core = _piola.Obstacle(self._def)
        self.index = None  # set when added to a world

    def signed_distance(self, points, t=0.0):
        """(distance (n,) m, outward normal (n, 3), obstacle velocity (n, 3) m/s) at points
        (n, 3) m and time t (s)."""
        return self._core.signed_distance(finite_array(points, "points", (-1, 3)),
                                          finite_number(t, "t"))

    def pose(self, t):
        """(R (3, 3), translation (3,) m): the obstacle's points move as x(t) = R x0 + translation."""
        return self._core.pose(finite_number(t, "t"))

    def __repr__(self):
        return f"Obstacle({self.type!r}, index={self.index})"


def _selector(sel, what, driven):
    keys = ("box", "sphere", "indices") + (("motion",) if driven else ())
    check_keys(sel, keys, what)
    given = [k for k in ("box", "sphere", "indices") if k in sel]
    if len(given) != 1:
        raise ValueError(f"{what}: give exactly one of box, sphere, indices")
    zero = (0.0, 0.0, 0.0)
    box_min = box_max = center = zero
    radius, indices, kind = 0.0, None, given[0]
    if kind == "box":
        corners = float_array(sel["box"], f"{what}.box", (2, 3))
        box_min, box_max = tuple(map(float, corners[0])), tuple(map(float, corners[1]))
    elif kind == "sphere":
        check_keys(sel["sphere"], ("center", "radius"), f"{what}.sphere")
        center = vec3(sel["sphere"].get("center", zero), f"{what}.sphere.center")
        radius = number(sel["sphere"].get("radius", 0.0), f"{what}.sphere.radius")
    else:
        indices = index_array(sel["indices"], f"{what}.indices", (-1,))
    motion = None
    if driven:
        if "motion" not in sel:
            raise ValueError(f"{what}: a driven selector needs 'motion'")
        motion = _motion(sel["motion"], f"{what}.motion", zero, (0.0, 0.0, 1.0))
    kinds = {"box": 0, "sphere": 1, "indices": 2}
    return ((kinds[kind], box_min, box_max, center, radius, indices), driven, motion)


class Body:
    """A solid or a shell of a world. kind is "solid" or "shell"; index counts within its kind.

    positions, velocities: (n, 3) writable views in m and m/s;
    rest_positions (n, 3) m, masses (n,) kg, cells (tets (m, 4) or triangles (k, 3)),
    constraint_flags (n,) uint8 (0 free, 1 fixed, 2 driven): read-only views."""

    def __init__(self, world, kind, index):
        self._world = world
        self.kind = kind
        self.index = index
        self._k = 0 if kind == "solid" else 1

    def _array(self, name):
        return self._world._core.body_array(self._k, self.index, name)

    name = property(lambda self: self._world._core.body_name(self._k, self.index))
    positions = property(lambda self: self._array("positions"), doc="(n, 3) m, a view")
    velocities = property(lambda self: self._array("velocities"), doc="(n, 3) m/s, a view")
    rest_positions = property(lambda self: self._array("rest_positions"), doc="(n, 3) m, read-only")
    masses = property(lambda self: self._array("masses"), doc="(n,) kg, lumped, read-only")
    cells = property(lambda self: self._array("cells"), doc="tets (m, 4) or triangles (k, 3)")
    constraint_flags = property(lambda self: self._array("flags"), doc="(n,) 0 free, 1 fixed, 2 driven")

    @positions.setter
    def positions(self, value):
        self.set_state(positions=value)

    @velocities.setter
    def velocities(self, value):
        self.set_state(velocities=value)

    def set_state(self, positions=None, velocities=None):
        """Replaces positions (n, 3) m and/or velocities (n, 3) m/s (copied)."""
        n = len(self.masses)
        p = None if positions is None else float_array(positions, "positions", (n, 3))
        v = None if velocities is None else float_array(velocities, "velocities", (n, 3))
        self._world._core.set_body_state(self._k, self.index, p, v)

    def stats(self):
        """Solids: kinetic_energy (J), elastic_energy (J), inverted_count, min_det_f.
        Shells: kinetic_energy, membrane_energy, bending_energy (J), inverted_count,
        degenerate_count."""
        return self._world._core.body_stats(self._k, self.index)

    def momentum(self):
        """Linear momentum sum m_i v_i, kg m/s (3,)."""
        return self.masses @ self.velocities

    def center_of_mass(self):
        """Mass-weighted mean of the positions, m (3,)."""
        m = self.masses
        return m @ self.positions / m.sum()

    def __repr__(self):
        return f"Body({self.kind} {self.index} {self.name!r}, {len(self.masses)} nodes)"


class World:
    """A world: solids, (scene) shells and obstacles, advanced in time.

        World(gravity=(0, 0, -9.81), max_dt=1e-3, cfl=0.5, cg_tolerance=1e-4,
              cg_max_iterations=200, collision_interval=0.0)

    gravity m/s^2 (each component keyframable), max_dt s, cfl dimensionless, collision_interval
    s: the integrator keys of docs/scene-format.md. Use it as a context manager or call
    close()."""

    def __init__(self, gravity=None, max_dt=None, cfl=None, cg_tolerance=None,
                 cg_max_iterations=None, collision_interval=None, *, _core=None, _owner=None):
        self._obstacles = []
        self._owner = _owner
        self._issued = set()
        if _core is not None:
            self._core = _core
            return
        d = _DEFAULTS["world"]
        g = tracks3(d["gravity"] if gravity is None else gravity, "gravity")
        self._core = _piola.World(
            g, number(d["max_dt"] if max_dt is None else max_dt, "max_dt"),
            number(d["cfl"] if cfl is None else cfl, "cfl"),
            number(d["cg_tolerance"] if cg_tolerance is None else cg_tolerance, "cg_tolerance"),
            integer(d["cg_max_iterations"] if cg_max_iterations is None else cg_max_iterations,
                    "cg_max_iterations"),
            number(d["collision_interval"] if collision_interval is None else collision_interval,
                   "collision_interval"))

    # ---------------------------------------------------------------- state
    time = property(lambda self: self._core.info()["time"], doc="s")
    stable_dt = property(lambda self: self._core.info()["stable_dt"],
                         doc="s: the next step's size without a target, min(max_dt, CFL bound, the "
                         "CFL bounds of the last 16 steps' states)")
    closed = property(lambda self: self._core.closed)

    @property
    def solids(self):
        return [Body(self, "solid", i) for i in range(self._core.info()["solids"])]

    @property
    def shells(self):
        return [Body(self, "shell", i) for i in range(self._core.info()["shells"])]

    @property
    def bodies(self):
        """Solids, then shells."""
        return self.solids + self.shells

    @property
    def obstacles(self):
        """Obstacles added from Python (a scene's own obstacles are counted by obstacle_count)."""
        return list(self._obstacles)

    obstacle_count = property(lambda self: self._core.info()["obstacles"])

    def body(self, name):
        """The body with this name (solids first)."""
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(f"no body named {name!r}")

    # ---------------------------------------------------------------- stepping
    def advance_to(self, t):
        """Steps until the world time is t (s) exactly, with the GIL released. Returns the
        summed step stats: substeps, cg_iterations, colliding (last step), last_dt (s),
        contacts, impacts, impact_zones, collision_steps, newton_iterations,
        linear_iterations, newton_failures, step_retries, energy_redos. A non-finite state raises
        SimulationError and leaves the state before the failing step."""
        t = number(t, "t")
        try:
            return self._core.advance_to(t)
        finally:
            self._issue_warnings()

    def step(self, dt_limit=None):
        """One step of min(stable dt, dt_limit) s; returns its stats."""
        limit = None if dt_limit is None else number(dt_limit, "dt_limit")
        try:
            return self._core.step() if limit is None else self._core.step(limit)
        finally:
            self._issue_warnings()

    @property
    def warnings(self):
        """The messages of the warnings raised so far (while the world was built too), one
        per kind, in the order of docs/cli.md's kinds."""
        return self._core.warnings()

    def _issue_warnings(self):
        if self.closed:
            return
        for text in self._core.warnings():
            if text not in self._issued:
                self._issued.add(text)
                _warnings.warn(text, SimulationWarning, stacklevel=3)

    # ---------------------------------------------------------------- building
    def add_solid(self, mesh, *, material=None, name=None, density=None, damping=None,
                  velocity=(0.0, 0.0, 0.0), fixed=(), driven=(), stiffness_scale=None,
                  initial=None, self_collision=None, fibers=None, activation=None):
        """Adds a tetrahedral solid at the world's current time; returns its Body.

        mesh: a Mesh, (points (n, 3) m, tets (m, 4)) or a file path; the rest shape in world
        space. material: a Material or a scene `material` dict (default neo-Hookean,
        E = 1e5 Pa, nu = 0.3). density kg/m^3 (1000). damping {"shear": Pa s, "bulk": Pa s}
        (keyframable). velocity m/s. fixed: selectors ({"box": [[x0,y0,z0],[x1,y1,z1]]},
        {"sphere": {"center", "radius"}} or {"indices": [...]}, on rest positions); driven:
        selectors with a "motion". stiffness_scale and activation: keyframable. initial
        {"matrix", "scramble" m, "seed"}. self_collision {"enabled", "thickness" m,
        "friction"}. fibers (m, 3): per-tet fibre directions (muscle and hgo models)."""
        if isinstance(mesh, (str, bytes)) or hasattr(mesh, "__fspath__"):
            mesh = read_mesh(mesh)
        if isinstance(mesh, Mesh) and mesh.tets is None:
            raise ValueError("a solid needs a tetrahedral mesh (use generate_mesh for a surface)")
        points, tets = mesh
        points = float_array(points, "points", (-1, 3))
        tets = index_array(tets, "tets", (-1, 4))
        if material is None:
            material = Material()
        elif isinstance(material, dict):
            material = Material.from_dict(material)
        elif not isinstance(material, Material):
            raise TypeError("material must be a Material or a dict")
        d = _DEFAULTS["solid"]
        damping = {} if damping is None else damping
        check_keys(damping, ("shear", "bulk"), "damping")
        initial = {} if initial is None else initial
        check_keys(initial, ("matrix", "scramble", "seed"), "initial")
        matrix = float_array(initial.get("matrix", np.eye(3)), "initial.matrix", (3, 3))
        seed = integer(initial.get("seed", d["scramble_seed"]), "initial.seed")
        if seed < 0:
            raise ValueError("initial.seed must be >= 0")
        sc_enabled, sc_thickness, sc_friction = d["self_collision"]
        sc_enabled = bool(sc_enabled)
        if self_collision is not None:
            check_keys(self_collision, ("enabled", "thickness", "friction"), "self_collision")
            sc_enabled = bool(self_collision.get("enabled", True))
            sc_thickness = number(self_collision.get("thickness", sc_thickness), "self_collision.thickness")
            sc_friction = number(self_collision.get("friction", sc_friction), "self_collision.friction")
        if name is not None and not isinstance(name, str):
            raise TypeError("name must be a string")
        # as the scene format refuses them (docs/scene-format.md); an unnamed solid is named
        # "solid<index>" by the library, which may be a name given earlier
        given = name if name is not None else f"solid{len(self.solids)}"
        if any(b.name == given for b in self.solids):
            what = "" if name is not None else f" (the name an unnamed solid {len(self.solids)} gets)"
            raise ValueError(f"a solid named {given!r} exists already{what}; names are unique among solids")
        if fibers is not None and material.model not in ("muscle", "hgo"):
            raise ValueError(f"fibers need the muscle or hgo model, not {material.model!r}")
        if activation is not None and material.model != "muscle":
            raise ValueError(f"activation needs the muscle model, not {material.model!r}")
        cons = [_selector(s, f"fixed[{i}]", False) for i, s in enumerate(fixed)]
        cons += [_selector(s, f"driven[{i}]", True) for i, s in enumerate(driven)]
        fib = None if fibers is None else float_array(fibers, "fibers", (len(tets), 3))
        index = self._core.add_solid((
            name, points, tets, material._def,
            track(d["stiffness_scale"] if stiffness_scale is None else stiffness_scale, "stiffness_scale"),
            number(d["density"] if density is None else density, "density"),
            track(damping.get("shear", 0.0), "damping.shear"),
            track(damping.get("bulk", 0.0), "damping.bulk"),
            vec3(velocity, "velocity"), cons, tuple(float(x) for x in matrix.ravel()),
            number(initial.get("scramble", d["scramble_radius"]), "initial.scramble"), seed,
            (sc_enabled, sc_thickness, sc_friction), fib,
            track(d["activation"] if activation is None else activation, "activation")))
        return Body(self, "solid", index)

    def add_obstacle(self, obstacle, **params):
        """Adds an Obstacle, or builds one: add_obstacle("plane", point=..., normal=...).
        Returns the Obstacle, with its index in the world."""
        if not isinstance(obstacle, Obstacle):
            obstacle = Obstacle(obstacle, **params)
        elif params:
            raise TypeError("parameters go to Obstacle(...), not with an Obstacle")
        if obstacle.index is not None:
            raise ValueError("this Obstacle is already in a world")
        obstacle.index = self._core.add_obstacle(obstacle._core)
        self._obstacles.append(obstacle)
        return obstacle

    # ---------------------------------------------------------------- lifetime
    def close(self):
        """Ends the world: later calls raise ClosedError. Memory is freed once no view of it
        is left."""
        self._core.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __repr__(self):
        if self.closed:
            return "World(closed)"
        i = self._core.info()
        return (f"World(t={i['time']:g} s, {i['solids']} solids, {i['shells']} shells, "
                f"{i['obstacles']} obstacles)")
