"""Worlds from Python: physics through the views (momentum, gravity, energy), zero-copy and
writable views, keyframed obstacles, driven nodes, the GIL, and misuse."""
import threading
import warnings

import numpy as np
import pytest

import piola


def ball(cell=0.03):
    return piola.generate_mesh("sphere", radius=0.1, cell_size=cell)


def tet_volumes_and_f(body):
    """Rest volumes and deformation gradients of every tet, from the views."""
    X, x, t = body.rest_positions, body.positions, body.cells
    Dm = np.stack([X[t[:, k]] - X[t[:, 0]] for k in (1, 2, 3)], axis=-1)
    Ds = np.stack([x[t[:, k]] - x[t[:, 0]] for k in (1, 2, 3)], axis=-1)
    return np.linalg.det(Dm) / 6, Ds @ np.linalg.inv(Dm)


def test_free_body_keeps_its_momentum():
    w = piola.World(gravity=(0, 0, 0))
    mat = piola.Material("neohookean", youngs_modulus=5e4)
    b = w.add_solid(ball(), material=mat, damping={"shear": 2, "bulk": 2}, velocity=(0.3, -0.2, 0.1))
    # spin it and squash it a little so elastic and damping forces are busy
    v = b.velocities
    c = b.center_of_mass()
    v += np.cross([0, 0, 4.0], b.positions - c)
    b.positions[:, 2] = c[2] + 0.8 * (b.positions[:, 2] - c[2])
    p0, c0, m = b.momentum(), b.center_of_mass(), b.masses.sum()
    w.advance_to(0.05)
    assert b.stats()["elastic_energy"] > 0
    assert np.allclose(b.momentum(), p0, rtol=0, atol=1e-9 * np.linalg.norm(p0))
    assert np.allclose(b.center_of_mass(), c0 + p0 / m * 0.05, atol=1e-9)
    assert w.time == 0.05


def test_gravity_changes_momentum_by_weight_times_time():
    w = piola.World()  # default gravity (0, 0, -9.81): z is up
    b = w.add_solid(ball(), density=500)
    M = b.masses.sum()
    assert M == pytest.approx(500 * 4 / 3 * np.pi * 0.1**3, rel=0.05)
    st = w.advance_to(0.1)
    assert st["substeps"] > 0
    assert b.momentum() == pytest.approx([0, 0, -M * 9.81 * 0.1], abs=1e-9 * M)
    assert b.stats()["kinetic_energy"] == pytest.approx(0.5 * M * (9.81 * 0.1) ** 2, rel=1e-9)


def test_world_energy_matches_material_energy():
    mat = piola.Material("stvk", youngs_modulus=1e5, poisson_ratio=0.3)
    w = piola.World(gravity=(0, 0, 0))
    b = w.add_solid(ball(0.04), material=mat)
    A = np.array([[1.2, 0.1, 0], [0, 0.9, 0.05], [0, 0, 1.1]])
    b.set_state(positions=b.rest_positions @ A.T)
    vol, F = tet_volumes_and_f(b)
    assert np.allclose(F, A, atol=1e-12)
    expected = np.sum(vol * mat.energy_density(F))
    assert b.stats()["elastic_energy"] == pytest.approx(expected, rel=1e-10)


def test_views_are_the_worlds_memory():
    w = piola.World()
    b = w.add_solid(ball(0.04))
    x, v = b.positions, b.velocities
    address = x.__array_interface__["data"][0]
    w.advance_to(0.01)
    assert b.positions.__array_interface__["data"][0] == address
    assert np.shares_memory(x, b.positions) and np.shares_memory(v, b.velocities)
    assert v[:, 2].mean() < 0  # the old view sees the new state
    assert x.flags.writeable and v.flags.writeable
    for ro in (b.rest_positions, b.masses, b.cells, b.constraint_flags):
        assert not ro.flags.writeable
        with pytest.raises(ValueError):
            ro[0] = 0


def test_world_keys_take_the_scene_ranges():
    """World's keys are refused outside scene-format.md's ranges, as in a scene file."""
    for key, bad in [("max_dt", 2.0), ("cg_tolerance", 1.0), ("collision_interval", 2.0),
                     ("cg_max_iterations", 1000001)]:
        with pytest.raises(ValueError, match=key):
            piola.World(**{key: bad})
    piola.World(max_dt=1.0, cg_tolerance=0.5, collision_interval=1.0)  # the ends allowed


def test_advance_to_the_past_is_refused_with_the_times():
    w = piola.World()
    w.add_solid(ball(0.04))
    w.advance_to(0.02)
    with pytest.raises(ValueError, match=r"t = 0.01 s is before the world's time 0.02 s"):
        w.advance_to(0.01)


def test_add_solid_refuses_what_the_scene_format_refuses():
    w = piola.World()
    w.add_solid(ball(0.04), name="x")
    with pytest.raises(ValueError, match="exists already"):
        w.add_solid(ball(0.04), name="x")
    with pytest.raises(ValueError, match="fibers need the muscle or hgo model"):
        w.add_solid(ball(0.04), material={"model": "neohookean"},
                    fibers=np.tile([1.0, 0, 0], (len(w.body("x").cells), 1)))
    with pytest.raises(ValueError, match="activation needs the muscle model"):
        w.add_solid(ball(0.04), material={"model": "neohookean"}, activation=0.5)
    assert len(w.bodies) == 1  # nothing half added
    # an unnamed solid takes "solid<index>", which a named one may already hold
    w.add_solid(ball(0.04), name="solid2")
    with pytest.raises(ValueError, match="'solid2' exists already"):
        w.add_solid(ball(0.04))
    assert [b.name for b in w.solids] == ["x", "solid2"]


def test_writes_through_views_reach_the_solver():
    w = piola.World(gravity=(0, 0, 0))
    b = w.add_solid(ball(0.04))
    b.velocities[:] = [0, 0, 2.0]          # in place through the view
    z0 = b.center_of_mass()[2]
    w.advance_to(0.1)
    assert b.center_of_mass()[2] == pytest.approx(z0 + 0.2, rel=1e-9)
    x0 = b.center_of_mass()[0]
    b.positions[:] += [1.0, 0, 0]          # a rigid shift stores no energy
    assert b.stats()["elastic_energy"] == pytest.approx(0, abs=1e-12)
    assert b.center_of_mass()[0] == pytest.approx(x0 + 1.0, abs=1e-12)
    b.positions[0, 0] = np.nan             # refused and undone
    with pytest.raises(ValueError, match="refused"):
        w.advance_to(0.2)
    assert np.all(np.isfinite(b.positions))
    b.velocities[3, 1] = np.inf
    with pytest.raises(ValueError, match="velocity is not finite"):
        b.stats()
    assert np.all(np.isfinite(b.velocities))
    with pytest.raises(ValueError, match="not finite"):
        b.set_state(velocities=np.full((len(b.masses), 3), np.nan))
    w.advance_to(0.2)
    b.velocities = np.zeros((len(b.masses), 3), dtype=np.float32)  # setter copies
    assert b.stats()["kinetic_energy"] == 0


def test_keyframed_obstacle_motion():
    keys = [[0, 0.0], [0.5, 0.1], [1.0, 0.1]]
    obs = piola.Obstacle("sphere", center=[0, 0, 0], radius=0.2,
                         motion={"translation": [0, 0, {"keys": keys}]})
    R, c = obs.pose(0.25)
    assert np.allclose(R, np.eye(3)) and np.allclose(c, [0, 0, 0.05])
    p = np.array([[0, 0, 1.0], [0.5, 0, 0.1]])
    d, n, vel = obs.signed_distance(p, 0.25)
    assert np.allclose(d, np.linalg.norm(p - [0, 0, 0.05], axis=1) - 0.2)
    assert np.allclose(n[0], [0, 0, 1]) and np.allclose(vel[0], [0, 0, 0.2])
    # a floor lifted by a keyframed velocity carries a resting block up with it
    w = piola.World()
    box = piola.generate_mesh("box", half_extents=[0.05, 0.05, 0.05], cell_size=0.025,
                              center=[0, 0, 0.0501])
    b = w.add_solid(box, material={"youngs_modulus": 1e5}, damping={"shear": 5, "bulk": 5})
    floor = w.add_obstacle("plane", point=[0, 0, 0], normal=[0, 0, 1], friction=0.5,
                           motion={"velocity": [0, 0, {"keys": [[0, 0], [0.2, 0], [0.21, 0.5], [0.4, 0.5]]}]})
    assert floor.index == 0 and w.obstacle_count == 1
    w.advance_to(0.4)
    lift = floor.pose(0.4)[1][2]
    assert lift == pytest.approx(0.5 * 0.19 + 0.5 * 0.01 * 0.5, rel=1e-9)
    assert b.positions[:, 2].min() >= lift - 2e-3


def test_mesh_obstacle_matches_the_sphere_it_samples(tmp_path):
    ball = piola.generate_mesh("sphere", radius=0.2, cell_size=0.02)
    surface = piola.Mesh(ball.points, triangles=piola.boundary_surface(ball.points, ball.tets))
    piola.write_mesh(tmp_path / "ball.obj", surface)
    p = np.array([[0, 0, 0.5], [0.3, 0.1, 0.0], [0.0, 0.0, 0.05]])
    exact = np.linalg.norm(p, axis=1) - 0.2
    for obs in (piola.Obstacle("mesh", surface=surface), piola.Obstacle("mesh", path=tmp_path / "ball.obj")):
        d, n, _ = obs.signed_distance(p)
        assert np.allclose(d, exact, atol=0.01)
        assert np.allclose(n[0], [0, 0, 1], atol=0.05)
    with pytest.raises(ValueError, match="not both"):
        piola.Obstacle("mesh")


def test_obstacle_queries_refuse_non_finite_input():
    # a box's clamps put a NaN point on its surface (distance 0) before this was refused
    box = piola.Obstacle("box", center=[0, 0, 0], half_extents=[1, 1, 1])
    with pytest.raises(ValueError, match="points must be finite"):
        box.signed_distance([[np.nan, 0, 0]])
    with pytest.raises(ValueError, match="t must be finite"):
        box.signed_distance([[0, 0, 2]], t=np.inf)
    with pytest.raises(ValueError, match="t must be finite"):
        box.pose(np.nan)
    d, _, _ = box.signed_distance([[0, 0, 2]])
    assert d[0] == pytest.approx(1.0)


def test_driven_and_fixed_nodes():
    mesh = piola.generate_mesh("box", half_extents=[0.1, 0.02, 0.02], cell_size=0.02)
    w = piola.World(gravity=(0, 0, -9.81))
    b = w.add_solid(mesh, fixed=[{"box": [[-1, -1, -1], [-0.09, 1, 1]]}],
                    driven=[{"box": [[0.09, -1, -1], [1, 1, 1]],
                             "motion": {"velocity": [0, 0, 0.1]}}])
    flags = b.constraint_flags
    fixed, driven = flags == 1, flags == 2
    assert fixed.any() and driven.any()
    w.advance_to(0.2)
    X, x = b.rest_positions, b.positions
    assert np.allclose(x[fixed], X[fixed])
    assert np.allclose(x[driven], X[driven] + [0, 0, 0.02], atol=1e-12)


def test_scene_world_and_bodies(tmp_path):
    scene = piola.Scene({
        "gravity": [0, 0, -9.81],
        "solids": [{"name": "ball", "mesh": {"generate": "sphere", "radius": 0.1, "cell_size": 0.04},
                    "transform": {"translate": [0, 0, 0.3]}}],
        "shells": [{"name": "sheet", "mesh": {"generate": "rectangle", "size": [0.4, 0.4],
                                              "resolution": [4, 4]}}],
        "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}]})
    w = scene.world
    assert scene.world is w
    assert [b.name for b in w.bodies] == ["ball", "sheet"]
    ball_body, sheet = w.body("ball"), w.body("sheet")
    assert sheet.kind == "shell" and sheet.cells.shape[1] == 3
    # a shell's views are writable too: a uniform velocity is pure kinetic energy
    sheet.velocities[:] = [1.0, 0, 0]
    assert sheet.stats()["kinetic_energy"] == pytest.approx(0.5 * sheet.masses.sum(), rel=1e-12)
    sheet.positions[:, 2] += 0.5
    assert sheet.stats()["membrane_energy"] == pytest.approx(0, abs=1e-12)
    x0 = sheet.center_of_mass()
    sheet.set_state(velocities=np.zeros((len(sheet.masses), 3)))
    assert ball_body.center_of_mass()[2] == pytest.approx(0.3, abs=1e-3)
    w.advance_to(0.05)
    assert set(sheet.stats()) >= {"kinetic_energy", "membrane_energy", "bending_energy"}
    # free fall from rest under gravity for 0.05 s
    assert sheet.center_of_mass()[2] == pytest.approx(x0[2] - 0.5 * 9.81 * 0.05**2, rel=1e-3)
    # a solid added after the shell: views and writes still reach the right bodies
    extra = w.add_solid(piola.generate_mesh("sphere", radius=0.05, cell_size=0.05, center=[1, 0, 0.5]))
    assert [b.name for b in w.bodies] == ["ball", "solid1", "sheet"] and extra.index == 1
    sheet.velocities[:] = [0, 2.0, 0]
    extra.velocities[:] = [0, 0, 3.0]
    assert sheet.stats()["kinetic_energy"] == pytest.approx(0.5 * sheet.masses.sum() * 4, rel=1e-12)
    assert extra.stats()["kinetic_energy"] == pytest.approx(0.5 * extra.masses.sum() * 9, rel=1e-12)


def test_warnings_are_issued_once_through_pythons_warnings():
    # a scene setting backward Euler's step without its type: read with a warning, run as Newmark
    scene = piola.Scene({"integrator": {"dt": 0.01},
                         "solids": [{"mesh": {"generate": "sphere", "radius": 0.1,
                                              "cell_size": 0.05}}]})
    w = scene.world
    assert len(w.warnings) == 1 and "integrator.dt applies to" in w.warnings[0]
    with pytest.warns(piola.SimulationWarning, match="integrator.dt applies to"):
        w.advance_to(0.001)
    # an undamped ball collapsed to a point: warned at its first step, and only once
    w = piola.World(gravity=(0, 0, 0))
    w.add_solid(ball(0.05), initial={"matrix": [[0, 0, 0], [0, 0, 0], [0, 0, 0]]})
    assert w.warnings == []
    with pytest.warns(piola.SimulationWarning, match="starts tangled .* with no damping") as got:
        w.step()
    assert len(got) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # raised before: not issued again
        w.step()
    assert len(w.warnings) == 1


def test_stepping_releases_the_gil():
    w = piola.World()
    w.add_solid(ball(0.015))
    ticks = 0
    seen_busy = False
    t = threading.Thread(target=w.advance_to, args=(0.1,))
    t.start()
    while t.is_alive():
        ticks += 1
        try:
            _ = w.time
        except RuntimeError as e:  # a second thread may not use a stepping world
            assert "another thread" in str(e)
            seen_busy = True
    t.join()
    assert ticks > 100 and seen_busy
    assert w.time == pytest.approx(0.1)


def test_closed_world_raises_and_views_survive():
    w = piola.World()
    b = w.add_solid(ball(0.04))
    x = b.positions
    before = x.copy()
    w.close()
    assert w.closed
    for call in (lambda: w.advance_to(0.1), lambda: b.stats(), lambda: b.positions,
                 lambda: w.add_obstacle("plane", point=[0, 0, 0], normal=[0, 0, 1]),
                 lambda: w.time):
        with pytest.raises(piola.ClosedError):
            call()
    del w, b
    assert np.array_equal(x, before)  # the view still holds the memory


def test_closed_scene_closes_its_world():
    scene = piola.Scene({"solids": [{"mesh": {"generate": "sphere", "radius": 0.1, "cell_size": 0.05}}]})
    w = scene.world
    scene.close()
    with pytest.raises(piola.ClosedError):
        w.advance_to(0.1)
    with pytest.raises(piola.ClosedError):
        scene.world


def test_misuse_raises():
    w = piola.World()
    mesh = ball(0.05)
    with pytest.raises(TypeError, match="dtype"):
        w.add_solid((mesh.points.astype(complex), mesh.tets))
    with pytest.raises(ValueError, match="out of range"):
        w.add_solid((mesh.points, mesh.tets + len(mesh.points)))
    with pytest.raises(ValueError, match="shape"):
        w.add_solid((mesh.points[:, :2], mesh.tets))
    with pytest.raises(ValueError, match="degenerate|volume"):
        w.add_solid((np.zeros((4, 3)), [[0, 1, 2, 3]]))
    with pytest.raises(ValueError, match="unknown key"):
        w.add_solid(mesh, damping={"sheer": 1})
    b = w.add_solid(mesh)
    with pytest.raises(ValueError, match="shape"):
        b.set_state(positions=np.zeros((3, 3)))
    with pytest.raises(ValueError, match="before"):
        w.advance_to(-1)
    with pytest.raises(TypeError):
        w.advance_to("soon")
    with pytest.raises(ValueError, match="obstacle type"):
        w.add_obstacle("cone")
    with pytest.raises(ValueError, match="required"):
        w.add_obstacle("sphere")
    with pytest.raises(ValueError, match="radius|positive|> 0"):
        w.add_obstacle("sphere", radius=-1)
    with pytest.raises(IndexError):
        w._core.body_array(0, 5, "positions")
    with pytest.raises(ValueError):
        w._core.body_array(0, 0, "secrets")
    # the extension checks dtype, shape and order itself
    n = len(b.masses)
    with pytest.raises(TypeError, match="dtype"):
        w._core.set_body_state(0, 0, np.zeros((n, 3), np.float32), None)
    with pytest.raises(ValueError, match="dimension"):
        w._core.set_body_state(0, 0, np.zeros((n + 1, 3)), None)
    with pytest.raises(ValueError, match="C-contiguous"):
        w._core.set_body_state(0, 0, np.zeros((3, n)).T, None)
    with pytest.raises(TypeError):
        w._core.add_solid(("x",))
    with pytest.raises(piola.ClosedError):
        piola._piola.World.__new__(piola._piola.World).info()  # never initialized
