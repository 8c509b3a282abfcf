#!/usr/bin/env python3
"""One starting configuration of an elastic hard-sphere gas, written for each code of bench/peers/.

    make_gas.py PHI CELLS SEED PREFIX

N = 4 CELLS^3 spheres of diameter 1 on a face-centred cubic lattice in a periodic cube at volume fraction PHI
(L^3 = N (pi/6) / PHI), with Maxwell velocities at k_B T / m = 1 (each component Gaussian of variance 1, the mean
removed, then scaled to the exact temperature). Units: the diameter, the mass, and tau = sqrt(m sigma^2 / k_B T),
those of Smallenburg's EDMD (Eur. Phys. J. E 45, 22, 2022). Writes
  PREFIX.sph  N, the box, then "a x y z r" per sphere (Smallenburg's snapshot format; that code draws its own
              velocities at the same temperature)
  PREFIX.csv  x,y,z,radius,vx,vy,vz (HAET's particle file, docs/scenario.md)
and prints "N L" on standard output.
"""
import math
import random
import sys


def main() -> int:
    if len(sys.argv) != 5:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    phi, cells, seed, prefix = float(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    if not 0 < phi < 0.7 or cells < 1:
        print("make_gas.py: PHI must lie in (0, 0.7) and CELLS be at least 1", file=sys.stderr)
        return 2
    n = 4 * cells**3
    box = (n * math.pi / 6 / phi) ** (1 / 3)
    a = box / cells
    basis = [(0.25, 0.25, 0.25), (0.75, 0.75, 0.25), (0.75, 0.25, 0.75), (0.25, 0.75, 0.75)]
    pos = [((i + bx) * a, (j + by) * a, (k + bz) * a)
           for i in range(cells) for j in range(cells) for k in range(cells) for (bx, by, bz) in basis]
    rng = random.Random(seed)
    vel = [[rng.gauss(0, 1) for _ in range(3)] for _ in range(n)]
    mean = [sum(v[c] for v in vel) / n for c in range(3)]
    for v in vel:
        for c in range(3):
            v[c] -= mean[c]
    scale = math.sqrt(3 * n / sum(v[0] ** 2 + v[1] ** 2 + v[2] ** 2 for v in vel))
    with open(prefix + ".sph", "w") as f:
        f.write(f"{n}\n{box:.12f} {box:.12f} {box:.12f}\n")
        for x, y, z in pos:
            f.write(f"a {x:.12f} {y:.12f} {z:.12f} 0.5\n")
    with open(prefix + ".csv", "w") as f:
        f.write("x,y,z,radius,vx,vy,vz\n")
        for (x, y, z), v in zip(pos, vel):
            f.write(f"{x:.12f},{y:.12f},{z:.12f},0.5,{v[0] * scale:.12f},{v[1] * scale:.12f},{v[2] * scale:.12f}\n")
    print(n, f"{box:.12f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
