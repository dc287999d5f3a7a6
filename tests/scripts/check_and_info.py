"""Checks behind test_check_and_info.sh."""
import json
import math
import os
import re
import subprocess
import tempfile

import meshio
import numpy as np

from script_checks import PIOLA, check, finish


def altitudes(points, tets):
    """3 |V| / largest face area of every tet."""
    p = points[tets]
    volume = np.abs(np.einsum("ij,ij->i", p[:, 1] - p[:, 0],
                              np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))) / 6
    faces = [(1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2)]
    area = np.max([np.linalg.norm(np.cross(p[:, b] - p[:, a], p[:, c] - p[:, a]), axis=1) / 2
                   for a, b, c in faces], axis=0)
    return 3 * volume / area


def wave_speed(e, nu, rho):
    lam, mu = e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))
    return math.sqrt((lam + 2 * mu) / rho)


def close(a, b, rel=1e-6):
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def main():
    with tempfile.TemporaryDirectory() as work:
        mesh = os.path.join(work, "box.msh")
        subprocess.run([PIOLA, "mesh", "generate", "box", "--half-extents", "0.5,0.25,0.1",
                        "--center", "1,2,3", "--cell-size", "0.05", "-o", mesh], check=True,
                       capture_output=True)
        m = meshio.read(mesh)
        points, tets = m.points, m.cells_dict["tetra"]
        lo, hi = points.min(axis=0), points.max(axis=0)
        h = altitudes(points, tets).min()
        e, nu, rho = 2e5, 0.35, 1100.0
        c = wave_speed(e, nu, rho)

        info = json.loads(subprocess.run([PIOLA, "mesh", "info", mesh, "--json", "--material",
                                          f"{e},{nu},{rho}"], check=True, capture_output=True,
                                         text=True).stdout)
        check(all(close(info["bounding_box_min"][k], lo[k]) and close(info["bounding_box_max"][k], hi[k])
                  for k in range(3)), f"bounding box {info['bounding_box_min']}..{info['bounding_box_max']} = {lo}..{hi}")
        check(np.allclose(info["size"], [1, 0.5, 0.2], rtol=1e-6), f"size {info['size']} is the box's 1 x 0.5 x 0.2 m")
        check(close(info["min_altitude"], h, 1e-9), f"min_altitude {info['min_altitude']} = {h}")
        mat = info["material"]
        check(close(mat["wave_speed"], c, 1e-12), f"wave speed {mat['wave_speed']} = {c}")
        check(close(mat["explicit_dt"], h / c, 1e-9), f"explicit_dt {mat['explicit_dt']} = h / c = {h / c}")
        check(close(mat["explicit_dt_default_cfl"], 0.5 * h / c, 1e-9), "explicit_dt_default_cfl = 0.5 h / c")
        text = subprocess.run([PIOLA, "mesh", "info", mesh], check=True, capture_output=True, text=True).stdout
        check("bounding box:" in text and "size:" in text and "min altitude:" in text,
              "the text form prints the bounding box, size and smallest altitude")
        # a TetGen pair without attributes has no region ids: "none", not a region 0
        with open(os.path.join(work, "one.node"), "w") as f:
            f.write("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n")
        with open(os.path.join(work, "one.ele"), "w") as f:
            f.write("1 4 0\n1 1 2 3 4\n")
        one = os.path.join(work, "one.ele")
        plain = subprocess.run([PIOLA, "mesh", "info", one], check=True, capture_output=True, text=True).stdout
        check("regions:          none" in plain, "a mesh without region ids lists none")
        one_json = json.loads(subprocess.run([PIOLA, "mesh", "info", one, "--json"], check=True,
                                             capture_output=True, text=True).stdout)
        check(one_json["regions"] == [], f"--json regions {one_json['regions']} is empty")
        surface = os.path.join(work, "box.obj")
        subprocess.run([PIOLA, "mesh", "convert", mesh, surface], check=True, capture_output=True)
        s = json.loads(subprocess.run([PIOLA, "mesh", "info", surface, "--json"], check=True,
                                      capture_output=True, text=True).stdout)
        check(np.allclose(s["size"], [1, 0.5, 0.2], rtol=1e-6), "a surface has its size too")
        p = subprocess.run([PIOLA, "mesh", "info", surface, "--material", "1e5,0.3,1000"],
                           capture_output=True, text=True)
        check(p.returncode == 2 and "piola mesh generate" in p.stderr,
              f"--material on a surface exits 2 pointing to the mesher ({p.returncode})")
        for bad in ["1e5,0.5,1000", "1e5,0.3", "-1,0.3,1000", "x"]:
            p = subprocess.run([PIOLA, "mesh", "info", mesh, "--material", bad], capture_output=True)
            check(p.returncode == 2, f"--material {bad} is refused")

        # piola check: the mesh as a solid of a scene
        fps, frames, max_dt, cfl = 50.0, 4, 0.01, 0.6
        scene = {"fps": fps, "frames": frames, "integrator": {"max_dt": max_dt, "cfl": cfl},
                 "solids": [{"name": "slab", "mesh": "box.msh", "density": rho,
                             "material": {"model": "neohookean", "youngs_modulus": e, "poisson_ratio": nu}}],
                 "shells": [{"name": "sheet", "mesh": {"generate": "rectangle", "size": [1, 1], "resolution": [3, 2]},
                             "transform": {"translate": [1, 2, 3.5]}, "thickness": 0.001,
                             "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3}}],
                 "obstacles": [{"type": "plane", "point": [0, 0, 2.8], "normal": [0, 0, 1]}]}
        path = os.path.join(work, "scene.json")
        with open(path, "w") as f:
            json.dump(scene, f)
        before = sorted(os.listdir(work))
        out = subprocess.run([PIOLA, "check", path, "--timing-seconds", "0.2", "--threads", "2"],
                             capture_output=True, text=True)
        check(out.returncode == 0, f"piola check exits 0 on a valid scene ({out.stderr.strip()})")
        check(sorted(os.listdir(work)) == before, "piola check writes nothing")
        t = out.stdout
        m_body = re.search(r'solid 0 "slab": (\d+) vertices, (\d+) tets; min rest altitude ([\d.e+-]+) m', t)
        check(m_body is not None and int(m_body.group(1)) == len(points) and int(m_body.group(2)) == len(tets),
              f"the solid's counts are the mesh's ({len(points)} vertices, {len(tets)} tets)")
        check(m_body is not None and close(float(m_body.group(3)), h, 1e-3), "its min rest altitude is the mesh's")
        check(re.search(r'shell 0 "sheet": 12 vertices, 12 triangles', t) is not None, "the shell and its counts")
        check(re.search(r"counts: +1 solids, 1 shells, 1 obstacles", t) is not None, "the counts line")
        # the world's shell bound can only lower the step: it is at most the solid's bound
        dt = float(re.search(r"step: +([\d.e+-]+) s", t).group(1))
        check(dt <= min(max_dt, cfl * h / c) * (1 + 1e-3), f"step {dt} <= min(max_dt, cfl h / c) = {min(max_dt, cfl * h / c)}")
        spf = int(re.search(r"estimate: +(\d+) steps per frame, (\d+) steps in all", t).group(1))
        check(spf == math.ceil((1 / fps) / dt - 1e-9), f"{spf} steps per frame = ceil(frame time / step)")
        tm = re.search(r"timing: +(\d+) steps, ([\d.e+-]+) s wall per step: about ([\d.e+-]+) s per frame", t)
        check(tm is not None and float(tm.group(2)) > 0 and close(float(tm.group(3)), float(tm.group(2)) * spf, 1e-2),
              "timing: the time per frame is the time per step times the steps per frame")
        quiet = subprocess.run([PIOLA, "check", path, "--timing-seconds", "0"], capture_output=True, text=True)
        check(quiet.returncode == 0 and "timing:" not in quiet.stdout, "--timing-seconds 0 times nothing")
        # an implicit integrator steps integrator.dt, whatever the mesh's CFL bound
        implicit = dict(scene, integrator={"type": "backward_euler", "dt": 0.007})
        with open(path, "w") as f:
            json.dump(implicit, f)
        t = subprocess.run([PIOLA, "check", path, "--timing-seconds", "0"], capture_output=True, text=True).stdout
        step = re.search(r"step: +([\d.e+-]+) s \((.*)\)", t)
        check(step is not None and close(float(step.group(1)), 0.007, 1e-3) and "integrator.dt" in step.group(2),
              f"backward_euler: the step is integrator.dt and says so ({step and step.group(0)})")
        spf = int(re.search(r"estimate: +(\d+) steps per frame", t).group(1))
        check(spf == math.ceil((1 / fps) / 0.007 - 1e-9), f"backward_euler: {spf} steps per frame of integrator.dt")
        # the timing stops at the scene's end (past it a body at rest costs an implicit step
        # nothing), and an implicit integrator's first step counts
        t = subprocess.run([PIOLA, "check", path, "--timing-seconds", "30", "--threads", "1"],
                           capture_output=True, text=True).stdout
        tm = re.search(r"timing: +(\d+) steps", t)
        check(tm is not None and int(tm.group(1)) == math.ceil(frames / fps / 0.007 - 1e-9),
              f"backward_euler: the timing takes the scene's {math.ceil(frames / fps / 0.007 - 1e-9)} steps, "
              f"all counted ({tm and tm.group(0)})")

        # the timing's steps are the run's first: their warnings are printed too
        inside = dict(scene, obstacles=[{"type": "plane", "point": [0, 0, 3], "normal": [0, 0, 1]}])
        with open(path, "w") as f:
            json.dump(inside, f)
        timed = subprocess.run([PIOLA, "check", path, "--timing-seconds", "0.1", "--threads", "1"],
                               capture_output=True, text=True)
        check(timed.returncode == 0 and "piola check: warning: solid 'slab':" in timed.stderr
              and "start inside obstacle 0" in timed.stderr,
              f"a solid half inside the plane is warned of after the timing's steps ({timed.stderr.strip()})")
        untimed = subprocess.run([PIOLA, "check", path, "--timing-seconds", "0"], capture_output=True,
                                 text=True)
        check(untimed.returncode == 0 and "start inside" not in untimed.stderr,
              "with --timing-seconds 0 no step is taken, and nothing is said of the start")

        scene["solids"][0]["material"]["poisson_ratio"] = 0.7
        with open(path, "w") as f:
            json.dump(scene, f)
        bad = subprocess.run([PIOLA, "check", path], capture_output=True, text=True)
        check(bad.returncode == 2 and "solids[0].material.poisson_ratio" in bad.stderr,
              f"a bad scene exits 2 naming the key path ({bad.stderr.strip()})")
        missing = subprocess.run([PIOLA, "check", os.path.join(work, "none.json")], capture_output=True)
        check(missing.returncode == 2, "a missing scene exits 2")
    finish()


main()
