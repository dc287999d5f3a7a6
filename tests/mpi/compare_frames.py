#!/usr/bin/python3
"""Compares the frames of two `piola run` output folders (docs/mpi.md).

usage: compare_frames.py DIR_A DIR_B TOLERANCE

Both folders must hold the same frame files. For every frames/*.vtu, the positions of B
must equal A's to TOLERANCE relative: max |x_B - x_A| <= TOLERANCE * max |x_A| (the
largest coordinate of the frame sets the scale), and the cell fields det_f and
energy_density to 1e-6 relative to their largest magnitude. Prints the largest relative difference
and how many frames were bit-identical. stats.csv must have the same rows (frame, time,
substeps) and the same kinetic and elastic energies and smallest det F to 1e-6 relative;
the self-collision contacts of both are printed.
Exits 1 on a difference or a missing frame."""
import csv
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
        # the per-tet fields come from every process's tets (gathered to process 0)
        for key in ("det_f", "energy_density"):
            ca, cb = ma.cell_data.get(key), mb.cell_data.get(key)
            if ca is None or cb is None:
                continue
            ca, cb = np.concatenate(ca), np.concatenate(cb)
            cscale = max(np.abs(ca).max(), 1e-12)
            if ca.shape != cb.shape or not np.abs(cb - ca).max() <= max(1e-6, 1000 * tol) * cscale:
                print(f"{name}: cell field {key} differs")
                return 1
    # stats.csv (written by process 0 alone): the same rows, and the global energies and
    # the smallest det F within the tolerance scaled up to 1e-6 (energies are sums over
    # every node and tet; a difference of positions at rounding shows in them amplified)
    rows_a = list(csv.DictReader(open(os.path.join(a, "stats.csv"))))
    rows_b = list(csv.DictReader(open(os.path.join(b, "stats.csv"))))
    if len(rows_a) != len(rows_b) or (rows_a and rows_a[0].keys() != rows_b[0].keys()):
        print(f"stats.csv: {len(rows_a)} rows against {len(rows_b)}, or other columns")
        return 1
    contacts = [0, 0]
    for ra, rb in zip(rows_a, rows_b):
        for key in ("frame", "time", "substeps"):
            if ra[key] != rb[key]:
                print(f"stats.csv frame {ra['frame']}: {key} {ra[key]} against {rb[key]}")
                return 1
        # self-collision's counts (a rounding-level difference of positions can move a pair
        # across the repulsion thickness): reported, not compared
        contacts[0] += int(ra.get("contacts") or 0)
        contacts[1] += int(rb.get("contacts") or 0)
        for key in ("kinetic_energy", "elastic_energy", "min_det_f"):
            va, vb = float(ra[key]), float(rb[key])
            if abs(va - vb) > max(1e-6, 1000 * tol) * max(abs(va), 1e-12):
                print(f"stats.csv frame {ra['frame']}: {key} {va!r} against {vb!r}")
                return 1
    print(f"{len(names)} frames, largest relative difference {worst:.3g}, "
          f"{identical} bit-identical; stats.csv agrees (self-collision contacts "
          f"{contacts[0]} and {contacts[1]})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
