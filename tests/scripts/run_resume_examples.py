"""Checks behind test_run_resume_examples.sh: examples whose state goes beyond what
run_resume.py's scene has (self-collision, whose collision trees carry history from step to
step; a shell in one-way contact with a solid), run a few frames into their contact phase (and a quasistatic bar and
plate strip, whose solver carries its regularization between steps; scenes with fracture, whose
meshes are cut during the run: examples/scripted_cut.json and a cut bar with self-collision)
and killed with SIGKILL at several renames of their output (frame files, indexes and the
checkpoint's own), resume to frames byte-identical to an uninterrupted run. One run is
killed, resumed, killed again and so on (each process counts its renames from 1), then
finished; stats.csv must match too, wall time aside.

Usage: run_resume_examples.py [EXAMPLE ...] checks the examples named (all of examples/ for
"all"; by hand, not in the suite) instead of the list below."""
import csv
import filecmp
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile

from script_checks import PIOLA, SOURCE, check, finish

SCALE = float(os.environ.get("PIOLA_TEST_SCALE", "1"))
# example: the frame from which its bodies are in contact (stats.csv: contacts > 0)
CONTACT_FROM = {"cloth_on_jelly": 2, "cloth_folds": 5, "solids_stack": 1, "squeezed_solid": 22,
                "cloth_cape_on_body": 4,
                # fracture: the knife cuts from frame 2 to frame 9 (0.05 s to 0.3 s), so the
                # runs resume in the middle of its sweep (its crack and last cut time are in
                # the checkpoint) and from cut states
                "scripted_cut": 4,
                # the stress criterion's crack starts at frame 4 and grows to frame 10 (its state:
                # the values and times at the vertices)
                "brittle_slab": 2}
EVERY = 2  # frames between checkpoints
# Renames of a run (src/output/frame_commit.c): scene.json, then per frame six (VTU and OBJ
# temporaries to pending names, both into place, stats.csv, sim.pvd), then the checkpoint
# when one is due. A resumed run first renames stats.csv, sim.pvd and scene.json. From a
# checkpoint after frame c, a resumed run's renames are therefore: 1-3 the indexes and the
# scene, 4-9 frame c+1, 10-15 frame c+2, 16 checkpoint c+2, 17-22 frame c+3, ...
# The first run dies at frame c+1's OBJ temporary (c the first checkpoint in contact); the
# resumed ones before the checkpoint's rename (no progress: the next resumes from the same
# checkpoint), the VTU's final rename, stats.csv and sim.pvd, each after a new checkpoint.
RESUMED_KILLS = [16, 19, 21, 28]
QUASISTATIC_BAR = """{
  "fps": 30, "frames": 6, "gravity": [0, {"keys": [[0, 0], [0.4, 15]]}, {"keys": [[0, -5], [0.4, -40]]}],
  "integrator": {"type": "quasistatic"},
  "solids": [{"name": "bar",
    "mesh": {"generate": "box", "center": [0.25, 0, 0], "half_extents": [0.25, 0.04, 0.04], "cell_size": 0.04},
    "density": 1000, "material": {"model": "neohookean", "youngs_modulus": 2e4, "poisson_ratio": 0.3},
    "fixed": [{"box": [[-0.1, -0.1, -0.1], [0.03, 0.1, 0.1]]}]}]
}"""

# a plate strip clamped at one end, bent by a gravity that turns and grows: a shell's
# quasistatic regularization is carried between steps too
QUASISTATIC_PLATE = """{
  "fps": 30, "frames": 10, "gravity": [0, {"keys": [[0, 0], [0.4, 5]]}, {"keys": [[0, -2], [0.4, -20]]}],
  "integrator": {"type": "quasistatic"},
  "shells": [{"name": "plate",
    "mesh": {"generate": "rectangle", "size": [0.3, 0.05], "resolution": [12, 2]},
    "thickness": 0.001, "density": 1000,
    "material": {"model": "neohookean", "youngs_modulus": 1e7, "poisson_ratio": 0.3},
    "bending": {"stiffness": 1.0},
    "fixed": [{"box": [[-1, -1, -1], [-0.124, 1, 1]]}]}]
}"""

# a bar cut by scripted planes with self-collision, so the fragments are in contact: cut at
# 0.1 s (frame 3) and 0.3 s (frame 9), resumed from cut states before the second cut
CUT_BAR_SELF_COLLISION = """{
  "fps": 30, "frames": 12, "gravity": [0, 0, -9.81],
  "solids": [{"name": "bar",
    "mesh": {"generate": "box", "center": [0.5, 0, 0.3], "half_extents": [0.5, 0.06, 0.06], "cell_size": 0.04},
    "density": 1000, "material": {"model": "neohookean", "youngs_modulus": 2e5, "poisson_ratio": 0.3},
    "damping": {"shear": 5, "bulk": 5},
    "self_collision": {"enabled": true, "thickness": 0.002},
    "fixed": [{"box": [[-0.1, -0.1, 0.2], [0.05, 0.1, 0.4]]}],
    "fracture": {"cuts": [
      {"time": 0.1, "plane": {"point": [0.23, 0, 0.3], "normal": [1, 0, 0.35]}},
      {"time": 0.3, "plane": {"point": [0.61, 0, 0.2], "normal": [1, 0.2, -0.3]}}]}}],
  "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "friction": 0.4}]
}"""
CONTACT_FROM["cut_bar_self_collision"] = 4


def frames_of(out):
    return sorted(n for sub in ("frames", "surface") if os.path.isdir(f"{out}/{sub}")
                  for n in (f"{sub}/{f}" for f in os.listdir(f"{out}/{sub}")))


def stats(out):
    rows = list(csv.DictReader(open(f"{out}/stats.csv")))
    for r in rows:
        del r["wall_seconds"]
    return rows


def run(scene, out, frames, *extra, kill=None, threads=1):
    env = dict(os.environ)
    if kill is not None:
        env["PIOLA_FAULT_KILL_AT_RENAME"] = str(kill)
    return subprocess.run([PIOLA, "run", scene, "-o", out, "--frames", str(frames), "--threads", str(threads),
                           "--checkpoint-every", str(EVERY), *extra], capture_output=True, text=True, env=env)


def check_example(name, work, scene=None):
    scene = scene or os.path.join(SOURCE, "examples", name + ".json")
    start = CONTACT_FROM.get(name, 1)
    c = start + start % EVERY  # the first checkpoint inside the contact phase
    kills = [1 + 6 * (c + 1) + c // EVERY + 1 + 2] + (RESUMED_KILLS if SCALE >= 1 else RESUMED_KILLS[:2])
    frames = c + (8 if SCALE >= 1 else 4)
    ref = os.path.join(work, name + "_ref")
    r = run(scene, ref, frames)
    check(r.returncode == 0, f"{name}: the uninterrupted run of {frames} frames succeeds {r.stderr[-300:] if r.returncode else ''}")
    if r.returncode != 0:
        return
    out = os.path.join(work, name)
    resumed_from, extra = [], []
    for i, k in enumerate(kills):
        r = run(scene, out, frames, *extra, kill=k, threads=1 + i % 2)
        resumed_from += [int(m) for m in re.findall(r"resuming after frame (\d+)", r.stderr)]
        if r.returncode == 0:
            break  # finished before its k-th rename
        if r.returncode != -signal.SIGKILL:
            check(False, f"{name}: killed at rename {k}: exit {r.returncode} {r.stderr[-300:]}")
            return
        extra = ["--resume"]
    r = run(scene, out, frames, "--resume")
    resumed_from += [int(m) for m in re.findall(r"resuming after frame (\d+)", r.stderr)]
    check(r.returncode == 0, f"{name}: the last --resume finishes {r.stderr[-300:] if r.returncode else ''}")
    # the run killed before the checkpoint's rename resumes from the same checkpoint again
    expected = [c, c] + [c + EVERY * k for k in range(1, len(kills) - 1)]
    check(resumed_from == expected,
          f"{name}: every run was killed where planned and resumed from the checkpoints after frames {expected} "
          f"(contact from frame {start}): {resumed_from}")
    names = frames_of(ref)
    differ = [n for n in names if not (os.path.exists(f"{out}/{n}") and filecmp.cmp(f"{ref}/{n}", f"{out}/{n}", shallow=False))]
    check(len(names) == 2 * (frames + 1) and not differ and frames_of(out) == names,
          f"{name}: after {len(kills)} kills the {len(names)} frame files equal the uninterrupted run's (differ: {differ})")
    check(stats(out) == stats(ref), f"{name}: stats.csv equals the uninterrupted run's (contacts and impacts included), wall time aside")


examples = [e for e in sys.argv[1:] if e != "cut_bar_self_collision"] if sys.argv[1:] else \
    ([e for e in CONTACT_FROM if e != "cut_bar_self_collision"] if SCALE >= 1 else ["cloth_on_jelly"])
if examples == ["all"]:
    examples = sorted(n[:-5] for n in os.listdir(os.path.join(SOURCE, "examples")) if n.endswith(".json"))
work = tempfile.mkdtemp()
for name in examples:
    check_example(name, work)
if not sys.argv[1:]:
    # quasistatics carries its regularization from step to step (implicit_step.c): a bar
    # under gravity that turns and grows, so every frame is a new equilibrium
    scene = os.path.join(work, "quasistatic_bar.json")
    with open(scene, "w") as f:
        f.write(QUASISTATIC_BAR)
    check_example("quasistatic_bar", work, scene)
    scene = os.path.join(work, "quasistatic_plate.json")
    with open(scene, "w") as f:
        f.write(QUASISTATIC_PLATE)
    check_example("quasistatic_plate", work, scene)
if not sys.argv[1:] or "cut_bar_self_collision" in sys.argv[1:]:
    scene = os.path.join(work, "cut_bar_self_collision.json")
    with open(scene, "w") as f:
        f.write(CUT_BAR_SELF_COLLISION)
    check_example("cut_bar_self_collision", work, scene)
shutil.rmtree(work)
finish()
