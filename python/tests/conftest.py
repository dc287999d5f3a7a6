"""Shared paths for the Python tests (run by ctest as script_python, or by hand:
PYTHONPATH=build/test/python /usr/bin/python3 -m pytest python/tests)."""
import os

import pytest

SOURCE_DIR = os.environ.get("PIOLA_SOURCE_DIR",
                            os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
DATA_DIR = os.environ.get("PIOLA_DATA_DIR", os.path.join(SOURCE_DIR, "..", "shared", "data"))
CLI = os.environ.get("PIOLA")


def data(*parts):
    path = os.path.join(DATA_DIR, *parts)
    if not os.path.exists(path):
        pytest.skip(f"shared data missing: {path}")
    return path
