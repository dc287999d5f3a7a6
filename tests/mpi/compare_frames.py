#!/usr/bin/python3
"""Compares the frames of two `piola run` output folders (docs/mpi.md).

usage: compare_frames.py DIR_A DIR_B TOLERANCE

Both folders must hold the same frame files. For every frames/*.vtu, the positions of B
must equal A's to TOLERANCE relative: max |x_B - x_A| <= TOLERANCE * max |x_A| (the
largest coordinate of the frame sets the scale). Prints the largest relative difference
and how many frames were bit-identical; exits 1 on a difference or a missing frame."""
import os
import sys

import meshio
import numpy as np


def main():
    a, b, tol = sys.argv[1], sys.argv[2], float(sys.argv[3])
    names = sorted(f for f in os.listdir(os.path.join(a, "frames")) if f.endswith(".vtu"))
    others = sorted(f for f in os.listdir(os.path.join(b, "frames")) if f.endswith(".vtu"))
    if not names or names != others:
        print(f"frame files differ: {len(names)} in {a}, {len(others)} in {b}")
        return 1
    worst, identical = 0.0, 0
    for name in names:
        ma = meshio.read(os.path.join(a, "frames", name))
        mb = meshio.read(os.path.join(b, "frames", name))
        if ma.points.shape != mb.points.shape:
            print(f"{name}: {ma.points.shape} points against {mb.points.shape}")
            return 1
        scale = np.abs(ma.points).max()
        rel = np.abs(mb.points - ma.points).max() / scale if scale > 0 else 0.0
        worst = max(worst, rel)
        identical += bool(np.array_equal(ma.points, mb.points))
        if not rel <= tol:
            print(f"{name}: positions differ by {rel:.3g} relative (> {tol:g})")
            return 1
    print(f"{len(names)} frames, largest relative difference {worst:.3g}, "
          f"{identical} bit-identical")
    return 0


if __name__ == "__main__":
    sys.exit(main())
