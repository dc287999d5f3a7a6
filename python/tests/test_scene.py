"""Scenes through Python: the same results and errors as `piola run`."""
import csv
import json
import os
import subprocess

import numpy as np
import pytest

import piola
from conftest import CLI, SOURCE_DIR

TORUS = os.path.join(SOURCE_DIR, "examples", "torus_puddle.json")

SMALL = {
    "fps": 50, "frames": 3,
    "solids": [{"name": "ball", "mesh": {"generate": "sphere", "radius": 0.1, "cell_size": 0.04},
                "transform": {"translate": [0, 0, 0.15]},
                "material": {"model": "neohookean", "youngs_modulus": 1e5}}],
    "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "friction": 0.5}],
}


def test_run_writes_what_the_cli_writes(tmp_path):
    if not CLI:
        pytest.skip("PIOLA (the CLI) not given; ctest sets it")
    calls = []
    scene = piola.Scene.from_file(TORUS)
    assert scene.fps == 30 and scene.frames == 90
    result = scene.run(tmp_path / "py", frames=2, progress=lambda *a: calls.append(a))
    assert result["frames"] == 2 and result["steps"] > 0
    assert [c[:2] for c in calls] == [(1, 2), (2, 2)]
    assert calls[-1][2] == pytest.approx(2 / 30) and calls[-1][3]["substeps"] > 0
    subprocess.run([CLI, "run", TORUS, "-o", str(tmp_path / "cli"), "--frames", "2"], check=True,
                   capture_output=True)
    for rel in ["frames/frame_0002.vtu", "surface/frame_0002.obj", "sim.pvd"]:
        with open(tmp_path / "py" / rel, "rb") as a, open(tmp_path / "cli" / rel, "rb") as b:
            assert a.read() == b.read(), rel
    with open(tmp_path / "py" / "stats.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["frame"]) for r in rows] == [0, 1, 2]
    # piola render finds the scene (obstacles, materials) in the folder, as after piola run
    copy = piola.Scene.from_file(tmp_path / "py" / "scene.json")
    assert copy.frames == 90 and copy.world.obstacle_count == 1
    subprocess.run([CLI, "render", str(tmp_path / "py"), "--no-movie"], check=True,
                   capture_output=True)
    assert os.path.exists(tmp_path / "py" / "render" / "frame_0002.png")


def test_run_writes_the_cli_stats_rows(tmp_path):
    """Every stats.csv column but the wall time as piola run writes it, the implicit
    integrator's Newton counters included."""
    if not CLI:
        pytest.skip("PIOLA (the CLI) not given; ctest sets it")
    scene_path = tmp_path / "implicit.json"
    scene_path.write_text(json.dumps(dict(SMALL, frames=8, integrator={"type": "backward_euler"})))
    piola.Scene.from_file(scene_path).run(tmp_path / "py")
    subprocess.run([CLI, "run", str(scene_path), "-o", str(tmp_path / "cli")], check=True,
                   capture_output=True)
    rows = {}
    for side in ["py", "cli"]:
        with open(tmp_path / side / "stats.csv") as f:
            rows[side] = [{k: v for k, v in r.items() if k != "wall_seconds"}
                          for r in csv.DictReader(f)]
    assert rows["py"] == rows["cli"]
    # the ball lands in these frames: Newton and its linear solves have work to count
    assert sum(int(r["newton_iterations"]) for r in rows["py"]) > 0
    assert sum(int(r["linear_iterations"]) for r in rows["py"]) > 0


def test_dict_scene_and_progress_stop(tmp_path):
    scene = piola.Scene(SMALL)
    seen = []

    def progress(frame, frames, t, stats):
        seen.append(frame)
        return frame < 2  # stop after frame 2

    result = scene.run(str(tmp_path / "out"), progress=progress)
    assert seen == [1, 2] and result["frames"] == 2
    assert sorted(os.listdir(tmp_path / "out" / "frames")) == ["frame_0000.vtu", "frame_0001.vtu",
                                                              "frame_0002.vtu"]
    with pytest.raises(piola.Error, match="load the scene again"):
        scene.run(str(tmp_path / "again"))
    # the ball fell and rests above the floor
    ball = scene.world.body("ball")
    assert ball.positions[:, 2].min() > -1e-3
    # the last frame holds the world's state: positions, velocities, energy
    frame = piola.read_vtu(tmp_path / "out" / "frames" / "frame_0002.vtu")
    assert np.array_equal(frame["points"], ball.positions)
    assert np.array_equal(frame["point_data"]["velocity"], ball.velocities)
    assert np.array_equal(frame["tets"], ball.cells)
    X, t = ball.rest_positions, ball.cells
    vol = np.einsum("ij,ij->i", X[t[:, 1]] - X[t[:, 0]],
                    np.cross(X[t[:, 2]] - X[t[:, 0]], X[t[:, 3]] - X[t[:, 0]])) / 6
    energy = frame["cell_data"]["energy_density"][frame["tet_cells"]] @ vol
    assert energy == pytest.approx(ball.stats()["elastic_energy"], rel=1e-9)


def test_progress_exception_propagates_and_keeps_frames(tmp_path):
    def boom(frame, *_):
        raise KeyError("stop here")

    with pytest.raises(KeyError, match="stop here"):
        piola.Scene(SMALL).run(tmp_path / "out", progress=boom)
    assert os.path.exists(tmp_path / "out" / "frames" / "frame_0001.vtu")
    assert os.path.exists(tmp_path / "out" / "sim.pvd")


def test_scene_copy_has_absolute_mesh_paths(tmp_path):
    piola.write_mesh(tmp_path / "ball.msh", piola.generate_mesh("sphere", radius=0.1, cell_size=0.05))
    scene = piola.Scene(dict(SMALL, solids=[dict(SMALL["solids"][0], mesh="ball.msh")]),
                        base_dir=tmp_path)
    scene.run(tmp_path / "out", frames=1)
    with open(tmp_path / "out" / "scene.json") as f:
        copy = json.load(f)
    assert copy["solids"][0]["mesh"] == str(tmp_path / "ball.msh")
    assert piola.Scene(copy).world.solids[0].cells.shape == scene.world.solids[0].cells.shape


def test_scene_errors_name_the_key_path(tmp_path):
    bad = dict(SMALL, solids=[dict(SMALL["solids"][0], material={"poisson_ratio": 0.7})])
    with pytest.raises(piola.SceneError) as e:
        piola.Scene(bad)
    assert str(e.value) == "scene: solids[0].material.poisson_ratio: must be in (-1, 0.5), got 0.7"
    assert e.value.status == "invalid argument"
    with pytest.raises(piola.SceneError, match=r"solids\[0\]\.materiel: unknown key"):
        piola.Scene(dict(SMALL, solids=[dict(SMALL["solids"][0], materiel={})]))
    with pytest.raises(piola.SceneError, match="not representable as JSON"):
        piola.Scene(dict(SMALL, fps=float("nan")))
    path = tmp_path / "broken.json"
    path.write_text('{"fps": 30,\n "frames": }')
    with pytest.raises(piola.SceneError, match="broken.json: line 2"):
        piola.Scene.from_file(path)
    with pytest.raises(piola.SceneError, match="missing.obj|missing"):
        piola.Scene(dict(SMALL, solids=[dict(SMALL["solids"][0], mesh="missing.msh")]), base_dir=tmp_path)
    assert issubclass(piola.SceneError, ValueError) and issubclass(piola.SceneError, piola.Error)


def test_run_refuses_a_used_folder(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "notes.txt").write_text("mine")
    with pytest.raises(ValueError):
        piola.Scene(SMALL).run(tmp_path / "out", frames=1)
    assert os.listdir(tmp_path / "out") == ["notes.txt"]
    with pytest.raises(ValueError, match="frames"):
        piola.Scene(SMALL).run(tmp_path / "other", frames=-1)
    with pytest.raises(TypeError):
        piola.Scene("scene.json")


def test_fracture_scenes_are_refused():
    # a cut replaces a solid's arrays, which the views over the world's memory cannot follow
    cut = {"cuts": [{"time": 0.5, "plane": {"point": [0, 0, 0], "normal": [1, 0, 0]}}]}
    with pytest.raises(piola.SceneError, match=r"^scene: solids\[0\].*fracture.*piola run"):
        piola.Scene(dict(SMALL, solids=[dict(SMALL["solids"][0], fracture=cut)]))
