"""What the Python checks behind the script tests share: where piola and the test data are,
a check that records failures instead of stopping at the first, and running a command."""
import os
import subprocess
import sys

PIOLA = os.environ["PIOLA"]
SOURCE = os.environ["PIOLA_SOURCE_DIR"]
DATA = os.path.join(SOURCE, "tests", "data")
failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def run(*args):
    return subprocess.run(args, check=True, capture_output=True, text=True)


def finish():
    """Exits non-zero if any check failed."""
    print(f"{len(failures)} check(s) failed" if failures else "all checks passed")
    sys.exit(1 if failures else 0)
