"""Checks behind test_run_resume.sh: a run killed (SIGKILL) at any rename of its output, in the
middle of any file it writes (checkpoints included), or at a random moment, leaves a consistent folder, and `piola run --resume` then finishes it with
frames byte-identical to a run that was never stopped; checkpoints of another scene, another
format version or damaged ones are refused or skipped as docs/cli.md says."""
import csv
import filecmp
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import tempfile
import time

from script_checks import PIOLA, check, finish

SCALE = float(os.environ.get("PIOLA_TEST_SCALE", "1"))
FRAMES = 8
# A damped plastic bar bent by a moving cylinder (plastic state, the damping operator and its
# reused product) next to a shell with in-plane and bending plasticity pressed by a ball.
SCENE = """{
  "fps": 60, "frames": %d, "gravity": [0, 0, -9.81],
  "integrator": {"max_dt": 0.002, "cfl": 0.5},
  "solids": [{"name": "bar",
    "mesh": {"generate": "box", "center": [0.25, 0, 0], "half_extents": [0.25, 0.04, 0.04], "cell_size": 0.04},
    "density": 1000, "material": {"model": "rotated_linear", "youngs_modulus": 2e5, "poisson_ratio": 0.3},
    "damping": {"shear": 20, "bulk": 20},
    "fixed": [{"box": [[-0.1, -0.1, -0.1], [0.03, 0.1, 0.1]]}],
    "plasticity": {"yield": 0.005, "limit": 1.0, "hardening": 0.5}}],
  "shells": [{"name": "sheet",
    "mesh": {"generate": "torus", "radius": 0.2, "minor_radius": 0.06, "segments": [12, 8], "sweep_degrees": 180},
    "transform": {"translate": [0, 0.6, 0.06]}, "thickness": 0.004, "density": 500,
    "material": {"model": "corotated", "youngs_modulus": 1e5, "poisson_ratio": 0.3},
    "damping": {"shear": 1, "bulk": 1},
    "bending": {"stiffness": 5e-3, "damping": 5e-5, "plasticity": {"yield_angle_degrees": 2, "rate": 40}},
    "plasticity": {"yield_strain": 0.01, "rate": 40, "max_plastic_stretch": 2}}],
  "obstacles": [
    {"type": "plane", "point": [0, 0, -0.2], "normal": [0, 0, 1], "friction": 0.5},
    {"type": "cylinder", "center": [0.45, 0, 0.09], "axis": [0, 1, 0], "radius": 0.05, "half_length": 0.1,
     "motion": {"translation": [0, 0, {"keys": [[0, 0], [0.3, -0.2]]}]}},
    {"type": "sphere", "center": [0, 0.8, 0.19], "radius": 0.05,
     "motion": {"translation": [0, 0, {"keys": [[0, 0], [0.3, -0.08]]}]}}]
}"""

work = tempfile.mkdtemp()
scene = os.path.join(work, "scene.json")
with open(scene, "w") as f:
    f.write(SCENE % FRAMES)


def piola_run(out, *extra, env=None):
    return subprocess.run([PIOLA, "run", scene, "-o", out, "--threads", "1", "--checkpoint-every", "3", *extra],
                          capture_output=True, text=True, env=env)


def listed(out):
    """Frames listed by stats.csv and by sim.pvd."""
    rows, pvd = [], []
    if os.path.exists(f"{out}/stats.csv"):
        rows = [int(r["frame"]) for r in csv.DictReader(open(f"{out}/stats.csv"))]
    if os.path.exists(f"{out}/sim.pvd"):
        pvd = [int(m) for m in re.findall(r'file="frames/frame_(\d+)\.vtu"', open(f"{out}/sim.pvd").read())]
    return rows, pvd


def consistent(out):
    """Every listed frame has both files; the indexes list an unbroken run from 0, sim.pvd at
    most one frame behind stats.csv (the last rename of a commit)."""
    rows, pvd = listed(out)
    for k in set(rows) | set(pvd):
        if not (os.path.isfile(f"{out}/frames/frame_{k:04d}.vtu") and os.path.isfile(f"{out}/surface/frame_{k:04d}.obj")):
            return f"frame {k} is listed but its files are not all in place"
    if rows != list(range(len(rows))) or pvd != list(range(len(pvd))):
        return f"indexes do not list an unbroken run: {rows} {pvd}"
    if not (len(pvd) <= len(rows) <= len(pvd) + 1):
        return f"stats.csv lists {len(rows)} frames, sim.pvd {len(pvd)}"
    return None


def same_frames(ref, out):
    names = [f"frames/frame_{k:04d}.vtu" for k in range(FRAMES + 1)] + \
            [f"surface/frame_{k:04d}.obj" for k in range(FRAMES + 1)]
    return [n for n in names if not (os.path.exists(f"{out}/{n}") and filecmp.cmp(f"{ref}/{n}", f"{out}/{n}", shallow=False))]


def strays(out):
    found = []
    for folder in (out, f"{out}/frames", f"{out}/surface"):
        if os.path.isdir(folder):
            found += [n for n in os.listdir(folder) if ".tmp" in n or ".pending." in n]
    return found


ref = os.path.join(work, "ref")
r = piola_run(ref)
check(r.returncode == 0, "the uninterrupted run succeeds")
rows = list(csv.DictReader(open(f"{ref}/stats.csv")))
check(sum(int(x["plastic_yielded"]) for x in rows) > 0, "the bar yields (plastic state is exercised)")
check(sorted(n for n in os.listdir(ref) if n.startswith("checkpoint_")) == ["checkpoint_0006.bin", "checkpoint_0008.bin"],
      "checkpoints every 3 frames and at the end, the newest two kept: " + str(os.listdir(ref)))

# Kill at every rename (every PIOLA_TEST_SCALE-th one with a smaller scale), then resume.
stride = max(1, round(1 / max(SCALE, 1e-3)))
killed = 0
for k in range(1, 1000, stride):
    out = os.path.join(work, f"kill{k}")
    env = dict(os.environ, PIOLA_FAULT_KILL_AT_RENAME=str(k))
    r = piola_run(out, env=env)
    if r.returncode == 0:
        break  # the run had fewer renames than k
    killed += 1
    if r.returncode != -signal.SIGKILL:
        check(False, f"kill at rename {k}: exit {r.returncode}, expected SIGKILL: {r.stderr[-300:]}")
        continue
    problem = consistent(out)
    if problem:
        check(False, f"kill at rename {k}: {problem}")
    r = piola_run(out, "--resume")
    if r.returncode != 0:
        check(False, f"kill at rename {k}: resume failed: {r.stderr[-400:]}")
        continue
    differ = same_frames(ref, out)
    if differ or strays(out) or consistent(out) or listed(out)[0] != list(range(FRAMES + 1)):
        check(False, f"kill at rename {k}: after resume differ {differ}, strays {strays(out)}, {consistent(out)}")
    shutil.rmtree(out)
check(killed >= max(2, 40 // stride), f"killed at {killed} renames, each resumed to frames identical to the uninterrupted run")

# Kill in the middle of every write (every 1/PIOLA_TEST_SCALE-th one with a smaller scale):
# the file's temporary holds half its bytes, checkpoints' included; then resume.
killed, in_checkpoint = 0, 0
for k in range(1, 1000, stride):
    out = os.path.join(work, f"write{k}")
    r = piola_run(out, env=dict(os.environ, PIOLA_FAULT_KILL_IN_WRITE=str(k)))
    if r.returncode == 0:
        break  # the run wrote fewer files than k
    killed += 1
    partial = [n for n in strays(out) if n.startswith("checkpoint_")]
    in_checkpoint += bool(partial)
    problem = consistent(out) if r.returncode == -signal.SIGKILL else f"exit {r.returncode}: {r.stderr[-300:]}"
    if problem:
        check(False, f"kill in write {k}: {problem}")
        continue
    r = piola_run(out, "--resume")
    differ = same_frames(ref, out) if r.returncode == 0 else ["(resume failed)"]
    if differ or strays(out) or consistent(out) or listed(out)[0] != list(range(FRAMES + 1)):
        check(False, f"kill in write {k}: after resume differ {differ}, strays {strays(out)}, {consistent(out)} {r.stderr[-300:]}")
    shutil.rmtree(out)
check(killed >= max(2, 40 // stride) and in_checkpoint >= (4 if stride == 1 else 0),
      f"killed in {killed} writes ({in_checkpoint} of them checkpoints, left half written), "
      "each resumed to frames identical to the uninterrupted run")

# kill -9 from outside at random moments
rng = random.Random(18)
for trial in range(max(1, round(3 * SCALE))):
    out = os.path.join(work, f"random{trial}")
    p = subprocess.Popen([PIOLA, "run", scene, "-o", out, "--threads", "2", "--checkpoint-every", "2"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(rng.uniform(0.1, 0.6))
    p.send_signal(signal.SIGKILL)
    p.wait()
    check(consistent(out) is None if os.path.isdir(out) else True, f"kill -9 at random ({trial}): consistent folder")
    r = subprocess.run([PIOLA, "run", scene, "-o", out, "--threads", "1", "--resume"], capture_output=True, text=True)
    check(r.returncode == 0 and not same_frames(ref, out), f"kill -9 at random ({trial}): resumed frames identical {r.stderr[-300:]}")

# --force after a kill removes the strays and the checkpoints of the earlier run
out = os.path.join(work, "forced")
piola_run(out, env=dict(os.environ, PIOLA_FAULT_KILL_AT_RENAME="20"))
check(strays(out) != [], "a kill between a frame's renames leaves temporaries")
r = subprocess.run([PIOLA, "run", scene, "-o", out, "--force", "--frames", "1", "--checkpoint-every", "0"],
                   capture_output=True, text=True)
check(r.returncode == 0 and strays(out) == [] and not any(n.startswith("checkpoint_") for n in os.listdir(out)),
      "--force removes stray temporaries and old checkpoints")

# a write failure (a full disk) at several points: exit 1 with a message; every frame listed
# is intact and identical to the uninterrupted run's; nothing half-written stays behind
for k in (3, 10, 17, 30):
    out = os.path.join(work, f"full{k}")
    r = piola_run(out, env=dict(os.environ, PIOLA_FAULT_FAIL_WRITE_AT=str(k)))
    rows_listed, _ = listed(out)
    differ = [n for n in same_frames(ref, out) if int(n[-8:-4]) in rows_listed]
    check(r.returncode == 1 and "No space left on device" in r.stderr and consistent(out) is None
          and not differ and strays(out) == [] and (k < 10 or len(rows_listed) >= 1),
          f"write failure at write {k}: exit {r.returncode}, frames 0..{len(rows_listed) - 1} kept intact: "
          + r.stderr.strip().splitlines()[-2][:160])
    named = re.findall(r"Open (\S+) in ParaView|preview of the last frame: (\S+)", r.stderr)
    missing = [p for pair in named for p in pair if p and not os.path.exists(p)]
    check(not missing, f"write failure at write {k}: the summary names only files that exist {missing}")

# refusals: another scene, another format version; a damaged newest checkpoint is skipped
other = os.path.join(work, "other.json")
with open(other, "w") as f:
    f.write((SCENE % FRAMES).replace('"youngs_modulus": 2e5', '"youngs_modulus": 3e5'))
out = os.path.join(work, "refuse")
shutil.copytree(ref, out)
r = subprocess.run([PIOLA, "run", other, "-o", out, "--resume"], capture_output=True, text=True)
check(r.returncode == 2 and "another scene" in r.stderr, "a checkpoint of another scene is refused: " + r.stderr.strip())
newest = f"{out}/checkpoint_0008.bin"
data = bytearray(open(newest, "rb").read())
version = data[8]
data[8] = 99  # the format version
open(newest, "wb").write(bytes(data))
r = piola_run(out, "--resume")
check(r.returncode == 2 and "format version 99" in r.stderr, "another format version is refused: " + r.stderr.strip())
data[8] = version
data[len(data) // 2] ^= 0xFF  # damage the payload
open(newest, "wb").write(bytes(data))
r = piola_run(out, "--resume")
check(r.returncode == 0 and "damaged" in r.stderr and "after frame 6" in r.stderr and not same_frames(ref, out),
      "a damaged newest checkpoint is skipped, the older one resumes: " + r.stderr.strip()[:300])
# a checkpoint whose header names another frame than its file name (copied, renamed or
# forged) is skipped as damaged: resuming from it would rewrite the frames after the one it
# holds, with that frame's state
out = os.path.join(work, "misnamed")
shutil.copytree(ref, out)
data = bytearray(open(f"{out}/checkpoint_0008.bin", "rb").read())
struct.pack_into("<I", data, 24, 5)  # the frame (file-formats.md)
h = 0xCBF29CE484222325  # FNV-1a 64 over everything before the checksum
for byte in data[:-8]:
    h = ((h ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
struct.pack_into("<Q", data, len(data) - 8, h)
open(f"{out}/checkpoint_0008.bin", "wb").write(bytes(data))
r = piola_run(out, "--resume")
check(r.returncode == 0 and "holds frame 5, not the frame 8" in r.stderr and "after frame 6" in r.stderr
      and not same_frames(ref, out),
      "a checkpoint naming another frame than its file is skipped: " + r.stderr.strip()[:300])
# a mesh file that changed under the same scene text
mesh_dir = os.path.join(work, "mesh")
os.mkdir(mesh_dir)
data_dir = os.environ.get("PIOLA_DATA_DIR", os.path.join(os.environ["PIOLA_SOURCE_DIR"], "..", "shared", "data"))
for ext in ("node", "ele"):
    shutil.copy(f"{data_dir}/tetgen/octahedron.{ext}", f"{mesh_dir}/oct.{ext}")
mesh_scene = os.path.join(mesh_dir, "scene.json")
with open(mesh_scene, "w") as f:
    f.write('{"fps": 30, "frames": 2, "solids": [{"mesh": "oct.node"}]}')
out = os.path.join(work, "meshout")
r = subprocess.run([PIOLA, "run", mesh_scene, "-o", out], capture_output=True, text=True)
check(r.returncode == 0, "a run from a mesh file: " + r.stderr[-200:])
node = open(f"{mesh_dir}/oct.node").read().splitlines()
count = int(node[0].split()[0])
for i in range(1, count + 1):  # the same mesh, 1.5 times larger
    fields = node[i].split()
    node[i] = " ".join(fields[:1] + [repr(float(x) * 1.5) for x in fields[1:4]] + fields[4:])
open(f"{mesh_dir}/oct.node", "w").write("\n".join(node) + "\n")
r = subprocess.run([PIOLA, "run", mesh_scene, "-o", out, "--resume"], capture_output=True, text=True)
check(r.returncode == 2 and "another scene" in r.stderr, "a changed mesh file is refused: " + r.stderr.strip())

# a mesh obstacle's file edited under the same scene text: the solid's mesh is the same, so
# only the key of the files the scene names (piola_scene_inputs_key) tells the runs apart
shutil.copy(f"{data_dir}/surface/sphere.obj", f"{mesh_dir}/bowl.obj")
obstacle_scene = os.path.join(mesh_dir, "obstacle.json")
with open(obstacle_scene, "w") as f:
    f.write('{"fps": 30, "frames": 2, "solids": [{"mesh": "oct.node", "transform": {"translate": [0, 0, 5]}}], '
            '"obstacles": [{"type": "mesh", "path": "bowl.obj"}]}')
out = os.path.join(work, "obstacleout")
r = subprocess.run([PIOLA, "run", obstacle_scene, "-o", out], capture_output=True, text=True)
check(r.returncode == 0, "a run with a mesh obstacle: " + r.stderr[-200:])
r = subprocess.run([PIOLA, "run", obstacle_scene, "-o", out, "--resume", "--frames", "3"],
                   capture_output=True, text=True)
check(r.returncode == 0, "the unchanged scene and files resume: " + r.stderr[-200:])
with open(f"{mesh_dir}/bowl.obj") as f:
    lines = f.read().splitlines()
with open(f"{mesh_dir}/bowl.obj", "w") as f:  # the obstacle moved down by 1 mm
    for line in lines:
        fields = line.split()
        if fields and fields[0] == "v":
            line = "v %s %s %r" % (fields[1], fields[2], float(fields[3]) - 1e-3)
        f.write(line + "\n")
r = subprocess.run([PIOLA, "run", obstacle_scene, "-o", out, "--resume", "--frames", "4"],
                   capture_output=True, text=True)
check(r.returncode == 2 and "another scene" in r.stderr,
      "an edited obstacle mesh is refused: " + r.stderr.strip())

shutil.rmtree(work)
finish()
