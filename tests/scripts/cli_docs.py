"""Checks behind test_cli_docs.sh: help texts against docs/cli.md, and the docs' JSON
snippets through `piola check`."""
import glob
import json
import math
import os
import re
import subprocess
import tempfile

from script_checks import PIOLA, SOURCE, check, finish

COMMANDS = ["run", "check", "render", "mesh"]
HELPS = [["--help"], ["-h"], ["help"], ["run", "--help"], ["check", "--help"], ["render", "--help"],
         ["mesh", "--help"], ["mesh", "info", "--help"], ["mesh", "convert", "--help"],
         ["mesh", "generate", "--help"]]


def flags(text):
    """Long options (--name) in a text."""
    return set(re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", text))


def cli_section(doc, title):
    """The text of docs/cli.md from the heading `title` to the next heading of its level."""
    level = title.split(" ")[0]
    start = doc.index(title + "\n")
    rest = doc[start + len(title) + 1:]
    m = re.search(r"^#{1,%d} " % len(level), rest, re.M)
    return rest[:m.start()] if m else rest


def main():
    for args in HELPS:
        p = subprocess.run([PIOLA, *args], capture_output=True, text=True)
        check(p.returncode == 0 and p.stdout.lstrip().startswith("usage"),
              f"piola {' '.join(args)} exits 0 with its usage on stdout (rc {p.returncode})")
    top = subprocess.run([PIOLA, "--help"], capture_output=True, text=True).stdout
    for c in COMMANDS:
        check(re.search(r"^\s+%s\b" % c, top, re.M) is not None, f"piola --help lists `{c}`")

    mesher = open(os.path.join(SOURCE, "docs", "mesher.md")).read()
    helped = flags(subprocess.run([PIOLA, "mesh", "generate", "--help"], capture_output=True,
                                  text=True).stdout) - {"--help"}
    documented = flags(cli_section(mesher, "## Command line"))
    check(helped == documented, f"piola mesh generate: --help and mesher.md's command line give "
          f"the same flags (only in --help: {sorted(helped - documented)}, only in the doc: "
          f"{sorted(documented - helped)})")

    doc = open(os.path.join(SOURCE, "docs", "cli.md")).read()
    for args, title in [(["run"], "## piola run"), (["check"], "## piola check"),
                        (["render"], "## piola render"),
                        (["mesh", "info"], "### piola mesh info FILE [--json] [--material E,NU,RHO [--viscosity BETA[,ALPHA]]]")]:
        helped = flags(subprocess.run([PIOLA, *args, "--help"], capture_output=True,
                                      text=True).stdout) - {"--help"}
        documented = flags(cli_section(doc, title)) - {"--help"}
        check(helped <= documented, f"piola {' '.join(args)}: every flag of --help is in "
              f"docs/cli.md (missing: {sorted(helped - documented)})")
        check(documented <= helped, f"piola {' '.join(args)}: every flag docs/cli.md gives is "
              f"in --help (missing: {sorted(documented - helped)})")

    # --viscosity: the settling estimate of time-stepping.md "Recovery", its parts consistent
    ball = os.path.join(SOURCE, "..", "shared", "data", "medit", "unit_ball.mesh")
    p = subprocess.run([PIOLA, "mesh", "info", ball, "--json", "--material", "2e4,0.3,1000",
                        "--viscosity", "1000,500"], capture_output=True, text=True)
    check(p.returncode == 0, f"mesh info --viscosity runs (rc {p.returncode}: {p.stderr.strip()})")
    if p.returncode == 0:
        st = json.loads(p.stdout)["settling"]
        mu, lam = 2e4 / 2.6, 2e4 * 0.3 / (1.3 * 0.4)
        w, c = st["lowest_frequency"], st["lowest_damping"]
        check(w > 0 and c > 0 and st["bulk_viscosity"] == 500, f"settling: omega_1 {w}, c_1 {c}")
        r1 = c / 2 if c < 2 * w else (c - math.sqrt(c * c - 4 * w * w)) / 2
        floor = min(mu / 1000, lam / 500)
        r = min(r1, floor)
        check(abs(st["lowest_decay_rate"] - r1) < 1e-9 * r1 and abs(st["relaxation_rate"] - floor) < 1e-9 * floor
              and abs(st["decay_rate"] - r) < 1e-9 * r, f"settling: decay rates {st}")
        lo, hi = json.loads(p.stdout)["bounding_box_min"], json.loads(p.stdout)["bounding_box_max"]
        d = math.dist(lo, hi)
        check(abs(st["crossing_time"] - d / math.sqrt((lam + 2 * mu) / 1000)) < 1e-9, "settling: D / c_p")
        t = 8 * max(st["crossing_time"], 1 / floor) + math.log(st["point_collapse_error"] / (0.01 * d)) / r
        check(abs(st["point_collapse_settling_time"] - t) < 1e-9 * t, f"settling: T {st} against {t}")
    for bad in (["--viscosity", "1000"], ["--material", "2e4,0.3,1000", "--viscosity", "-1"],
                ["--material", "2e4,0.3,1000", "--viscosity", "1000,"]):
        p = subprocess.run([PIOLA, "mesh", "info", ball, *bad], capture_output=True, text=True)
        check(p.returncode == 2 and "--viscosity" in p.stderr and not p.stdout,
              f"mesh info {' '.join(bad)} is refused naming --viscosity (rc {p.returncode})")

    # --refine and a scene's refinement_levels have one range, 0..6 (mesher.md)
    with tempfile.TemporaryDirectory() as work:
        p = subprocess.run([PIOLA, "mesh", "generate", "sphere", "--refine", "7", "-o",
                            os.path.join(work, "x.msh")], capture_output=True, text=True)
        check(p.returncode == 2, f"mesh generate --refine 7 is refused (rc {p.returncode})")
        scene = os.path.join(work, "refine.json")
        with open(scene, "w") as f:
            json.dump({"solids": [{"mesh": {"generate": "sphere", "radius": 0.1, "cell_size": 0.05,
                                            "refinement_levels": 7}}]}, f)
        p = subprocess.run([PIOLA, "check", scene, "--timing-seconds", "0"], capture_output=True,
                           text=True)
        check(p.returncode == 2 and "solids[0].mesh.refinement_levels" in p.stderr and "6" in p.stderr,
              f"a scene's refinement_levels 7 is refused naming the key and the range: {p.stderr.strip()}")

    # every ```json block of the docs is a whole scene that piola accepts
    sources = [os.path.join(SOURCE, "README.md")] + sorted(glob.glob(os.path.join(SOURCE, "docs", "*.md")))
    count = 0
    with tempfile.TemporaryDirectory() as work:
        for path in sources:
            text = open(path).read()
            for i, m in enumerate(re.finditer(r"^```json\n(.*?)^```", text, re.M | re.S)):
                name = f"{os.path.relpath(path, SOURCE)} snippet {i + 1} (line {text[:m.start()].count(chr(10)) + 1})"
                snippet = m.group(1)
                try:
                    json.loads(snippet)
                except ValueError as e:
                    check(False, f"{name}: is JSON ({e})")
                    continue
                scene = os.path.join(work, f"snippet_{count}.json")
                count += 1
                with open(scene, "w") as f:
                    f.write(snippet)
                p = subprocess.run([PIOLA, "check", scene, "--timing-seconds", "0"],
                                   capture_output=True, text=True)
                check(p.returncode == 0, f"{name}: piola check accepts it {p.stderr.strip()}")
    check(count >= 4, f"found the docs' JSON snippets ({count})")
    finish()


main()
