#!/usr/bin/env python3
"""Writes the starting state of the silo benchmarks as a LAMMPS data file (atom_style sphere, LIGGGHTS's granular):
"Atoms # sphere" lines "id type diameter density x y z", every sphere at rest, none touching another or a wall.

    bench/make_silo_data.py silo OUT [--count N] [--seed S]    spheres in the silo of examples/silo3d.toml
    bench/make_silo_data.py idle OUT                           1 sphere in the same box (memory baseline)

The silo is the one of examples/silo3d.toml and examples/meshes/: a conical hopper from the orifice (radius 4 mm at
z = 0) to radius 20 mm at z = 16 mm, under a cylinder of radius 20 mm up to z = 76 mm, both 64-sided meshes, in the
box [-0.03, 0.03]^2 x [-0.04, 0.08] m. Glass beads (density 2500 kg/m^3) of radius uniform in [0.5, 0.7] mm sit on
the sites of a simple cubic lattice of spacing 1.5 mm (at least 0.1 mm between two spheres), filled from the
bottom of the hopper up (z, then y, then x), taking each site whose sphere keeps 0.05 mm from the silo's inside:
its distance to the profile of the mesh (its faces are the circles' chords, so the radius is scaled by
cos(pi / 64)) is at least the radius plus that gap. Radii come from Python's random.Random(seed), the same on
every machine; the file is the same bytes for the same arguments.
"""
import argparse
import math
import random
import sys

LO = (-0.03, -0.03, -0.04)
HI = (0.03, 0.03, 0.08)
DENSITY = 2500.0  # kg/m^3
RADIUS = (0.0005, 0.0007)  # m
SPACING = 0.0015  # m
GAP = 0.00005  # m, from a wall
ORIFICE, TOP, HOPPER_H, CYL_TOP = 0.004, 0.02, 0.016, 0.076  # m
INSCRIBED = math.cos(math.pi / 64)  # a 64-gon's faces lie this much inside its circle


def profile():
    """The silo's inner wall in the (rho, z) half-plane, as segments: the cone, then the cylinder."""
    a = (ORIFICE * INSCRIBED, 0.0)
    b = (TOP * INSCRIBED, HOPPER_H)
    c = (TOP * INSCRIBED, CYL_TOP)
    return [(a, b), (b, c)]


def distance_to_segment(p, seg):
    (ax, az), (bx, bz) = seg
    dx, dz = bx - ax, bz - az
    t = max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - az) * dz) / (dx * dx + dz * dz)))
    return math.hypot(p[0] - ax - t * dx, p[1] - az - t * dz)


def inside(rho, z, r):
    """True if a sphere of radius r at (rho, z) lies inside the silo, GAP away from its wall."""
    if z - r < GAP or z + r > CYL_TOP:
        return False
    wall_rho = ORIFICE * INSCRIBED + (TOP - ORIFICE) * INSCRIBED * min(z, HOPPER_H) / HOPPER_H
    if rho >= wall_rho:
        return False
    return min(distance_to_segment((rho, z), s) for s in profile()) >= r + GAP


def silo(count, seed):
    rng = random.Random(seed)
    n_xy = int(TOP / SPACING) + 1
    sites = []
    k = 0
    while len(sites) < count:
        z = RADIUS[1] + GAP + k * SPACING
        if z + RADIUS[1] > CYL_TOP:
            raise SystemExit("make_silo_data.py: the silo holds fewer than %d spheres on this lattice" % count)
        for j in range(-n_xy, n_xy + 1):
            for i in range(-n_xy, n_xy + 1):
                # Sites at half-integer offsets: none on the axis, the lattice symmetric about it.
                x, y = (i + 0.5) * SPACING, (j + 0.5) * SPACING
                r = RADIUS[0] + (RADIUS[1] - RADIUS[0]) * rng.random()
                if inside(math.hypot(x, y), z, r) and len(sites) < count:
                    sites.append((2 * r, x, y, z))
        k += 1
    return sites


def write(path, title, sites):
    lines = [title, "", "%d atoms" % len(sites), "1 atom types", ""]
    lines += ["%r %r %slo %shi" % (LO[a], HI[a], "xyz"[a], "xyz"[a]) for a in range(3)]
    lines += ["", "Atoms # sphere", ""]
    for n, (d, x, y, z) in enumerate(sites, 1):
        lines.append("%d 1 %.10g %r %.10g %.10g %.10g" % (n, d, DENSITY, x, y, z))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("kind", choices=("silo", "idle"))
    ap.add_argument("out")
    ap.add_argument("--count", type=int, default=6000)
    ap.add_argument("--seed", type=int, default=19)
    args = ap.parse_args(argv)
    if args.kind == "idle":
        write(args.out, "HAET silo benchmark: idle baseline, 1 sphere in the silo's box", [(0.0012, 0.0, 0.0, 0.03)])
    else:
        sites = silo(args.count, args.seed)
        title = "HAET silo benchmark: %d spheres at rest on a %g m lattice in the silo, seed %d" % (
            len(sites), SPACING, args.seed)
        write(args.out, title, sites)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
