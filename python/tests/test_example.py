"""examples/python/sweep_stiffness.py runs at a tiny size and plots a PNG that says
something true: a softer ball squashes more."""
import csv
import os
import subprocess
import sys

from conftest import SOURCE_DIR


def test_sweep_stiffness_example(tmp_path):
    png, table = tmp_path / "sweep.png", tmp_path / "sweep.csv"
    script = os.path.join(SOURCE_DIR, "examples", "python", "sweep_stiffness.py")
    subprocess.run([sys.executable, script, "--out", str(png), "--csv", str(table),
                    "--values", "2e4,2e5", "--cell-size", "0.05", "--duration", "0.3",
                    "--fps", "50"], check=True, capture_output=True, timeout=600)
    with open(png, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    assert os.path.getsize(png) > 10000
    with open(table) as f:
        rows = list(csv.DictReader(f))
    soft, stiff = (float(r["min_height_ratio"]) for r in rows)
    assert soft < stiff < 1.0
