#!/usr/bin/env python3
"""Parameter sweep, notebook style: drop a rubber ball on the floor for several Young's moduli
and plot how much it squashes and how its centre moves.

    /usr/bin/python3 examples/python/sweep_stiffness.py --out out/sweep_stiffness.png

Needs `import piola` to work (./scripts/setup.sh) and matplotlib (python3-matplotlib).
z is up; SI units."""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import piola  # noqa: E402


def drop(youngs_modulus, cell_size, duration, fps):
    """One run: a ball of radius 0.1 m dropped from 0.25 m onto a plane z = 0."""
    mesh = piola.generate_mesh("sphere", radius=0.1, cell_size=cell_size, center=[0, 0, 0.25])
    with piola.World(max_dt=2e-3) as world:
        ball = world.add_solid(mesh, material={"model": "neohookean", "youngs_modulus": youngs_modulus,
                                               "poisson_ratio": 0.4},
                               density=1100, damping={"shear": 1e-4 * youngs_modulus,
                                                      "bulk": 1e-4 * youngs_modulus})
        world.add_obstacle("plane", point=[0, 0, 0], normal=[0, 0, 1], friction=0.5)
        z = ball.positions[:, 2]  # a view: it follows the simulation without copying
        height0 = np.ptp(z)
        times, centre, squash = [0.0], [ball.center_of_mass()[2]], [1.0]
        for frame in range(1, int(round(duration * fps)) + 1):
            world.advance_to(frame / fps)
            times.append(world.time)
            centre.append(ball.center_of_mass()[2])
            squash.append(np.ptp(z) / height0)
    return np.array(times), np.array(centre), np.array(squash)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/sweep_stiffness.png", help="PNG to write")
    parser.add_argument("--csv", help="also write the table here")
    parser.add_argument("--values", default="2e4,5e4,1e5,3e5",
                        help="Young's moduli to sweep, Pa, comma-separated")
    parser.add_argument("--cell-size", type=float, default=0.035, help="mesher cell size, m")
    parser.add_argument("--duration", type=float, default=0.5, help="simulated time per run, s")
    parser.add_argument("--fps", type=float, default=100, help="samples per simulated second")
    args = parser.parse_args()
    values = [float(v) for v in args.values.split(",")]

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    rows = []
    for E in values:
        t, centre, squash = drop(E, args.cell_size, args.duration, args.fps)
        rows.append((E, squash.min(), centre.min()))
        print(f"E = {E:9.3g} Pa: most squashed to {squash.min():.3f} of its height, "
              f"centre down to {centre.min():.4f} m")
        left.plot(t, centre, label=f"E = {E:.3g} Pa")
    left.set_xlabel("time (s)")
    left.set_ylabel("height of the centre of mass (m)")
    left.legend(loc="upper right")
    right.semilogx([r[0] for r in rows], [r[1] for r in rows], "o-")
    right.set_xlabel("Young's modulus (Pa)")
    right.set_ylabel("smallest height / rest height")
    fig.suptitle("A rubber ball dropped on the floor (piola)")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    fig.savefig(args.out, dpi=100)
    print(f"wrote {args.out}")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["youngs_modulus", "min_height_ratio", "min_centre_height"])
            w.writerows(rows)


if __name__ == "__main__":
    main()
