"""Scenes: the JSON files of docs/scene-format.md, loaded from a file or a dict, and run."""
import json
import os
import time as _time

from . import _piola
from ._convert import integer
from .world import World


class Scene:
    """A scene, validated and built (meshes read or generated) when it is made.

        scene = piola.Scene.from_file("examples/torus_puddle.json")
        scene = piola.Scene({"solids": [...], "obstacles": [...]}, base_dir=".")

    An invalid scene raises SceneError with the same message as `piola run`, naming the key
    path (e.g. "scene: solids[0].material.poisson_ratio: must be in (-1, 0.5), got 0.7").
    Relative mesh paths of a dict scene are taken from base_dir (default: the current
    folder)."""

    def __init__(self, scene, base_dir=None, label="scene"):
        if not isinstance(scene, dict):
            raise TypeError("Scene(dict); use Scene.from_file(path) for a file")
        try:
            text = json.dumps(scene, allow_nan=False)
        except (TypeError, ValueError) as e:
            raise SceneError(f"{label}: not representable as JSON: {e}") from None
        base = os.fspath(base_dir) if base_dir is not None else os.getcwd()
        self._init(_piola.Scene("", text, base, label), None)
        self._source, self._folder = json.loads(text), os.path.abspath(base)

    @classmethod
    def from_file(cls, path):
        """Loads a scene file; mesh paths are relative to its folder."""
        self = cls.__new__(cls)
        path = os.fspath(path)
        self._init(_piola.Scene(path, None, None, None), path)
        self._source = self._folder = None  # the C library copies files itself
        return self

    def _init(self, core, path):
        self._core = core
        self.path = path
        self._world = None

    fps = property(lambda self: self._core.info()["fps"], doc="frames per second of output, 1/s")
    frames = property(lambda self: self._core.info()["frames"], doc="frames after frame 0")
    closed = property(lambda self: self._core.closed)

    @property
    def world(self):
        """The scene's World (one object; it keeps the scene alive)."""
        if self._world is None or self._world._core.closed:
            core = self._core.world()
            self._world = World(_core=core, _owner=self)
        return self._world

    def run(self, out_dir, frames=None, force=False, progress=None):
        """Runs the scene from t = 0 and writes what `piola run` writes (docs/cli.md):
        out_dir/frames/frame_NNNN.vtu, surface/frame_NNNN.obj, stats.csv, sim.pvd, and
        scene.json (the scene with absolute mesh paths, for `piola render out_dir`).

        frames: frames after frame 0 (default: the scene's). force: reuse a non-empty folder,
        removing piola's earlier results there. progress(frame, frames, time_s, stats) is
        called after each frame is written (stats: that frame's step stats); returning False
        stops the run after that frame. Stepping releases the GIL. A non-finite state writes
        failure_report.txt, keeps the frames so far and raises SimulationError.
        Returns {"frames", "steps", "cg_iterations", "wall_seconds"}."""
        world = self.world
        if world.time != 0:
            raise _piola.Error("run() starts at t = 0 but this scene's world has been advanced; "
                               "load the scene again")
        n = self.frames if frames is None else integer(frames, "frames")
        if not 0 <= n <= 1000000:
            raise ValueError(f"frames must be in [0, 1000000], got {n}")
        if progress is not None and not callable(progress):
            raise TypeError("progress must be callable")
        fps = self.fps
        start = _time.perf_counter()
        out = _piola.Output(os.fspath(out_dir), bool(force), world._core)
        steps = cg = written = 0
        try:
            self._write_copy(os.path.join(os.fspath(out_dir), "scene.json"))
            out.write_frame(0, 0.0, None)
            for frame in range(1, n + 1):
                t0 = _time.perf_counter()
                try:
                    st = world.advance_to(frame / fps)
                except _piola.SimulationError as e:
                    out.write_failure_report(str(e))
                    raise
                out.write_frame(frame, _time.perf_counter() - t0, st)
                written = frame
                steps += st["substeps"]
                cg += st["cg_iterations"]
                if progress is not None and progress(frame, n, world.time, st) is False:
                    break
        finally:
            out.close()
        return {"frames": written, "steps": steps, "cg_iterations": cg,
                "wall_seconds": _time.perf_counter() - start}

    def _write_copy(self, path):
        """The scene with the mesh paths of solids, shells, obstacles, bones and plastic goals
        made absolute (as piola_scene_copy_resolved does for a file), written whole or not at
        all."""
        if self.path is not None:
            _piola.Scene.copy_resolved(self.path, path)
            return
        scene = json.loads(json.dumps(self._source))

        def resolve(item, key):
            if isinstance(item, dict) and isinstance(item.get(key), str) and item[key]:
                item[key] = os.path.join(self._folder, item[key])

        for section, key in (("solids", "mesh"), ("shells", "mesh"), ("obstacles", "path"),
                             ("bones", "path")):
            for item in scene.get(section, []):
                resolve(item, key)
        for solid in scene.get("solids", []):
            control = solid.get("plasticity", {}).get("control", {}) if isinstance(solid, dict) else {}
            resolve(control.get("goal") if isinstance(control, dict) else None, "mesh")
        tmp = path + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(scene, f, indent=2)
            f.write("\n")
        os.replace(tmp, path)

    def close(self):
        """Ends the scene and its world: later calls raise ClosedError."""
        self._core.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


SceneError = _piola.SceneError
