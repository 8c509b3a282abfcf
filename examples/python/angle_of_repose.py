#!/usr/bin/python3
"""A staged protocol no scenario file can say: pour disks into a box, let them settle until the kinetic energy is
below a threshold, tilt gravity step by step until the bed avalanches, let it settle again and measure the angle
of its free surface to the tilted horizontal: the angle of repose. Draws angle_of_repose.png.

    PYTHONPATH=build/python examples/python/angle_of_repose.py [--out DIR]

About a minute on one core (800 disks, 2D).
"""
import argparse
import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import haet  # noqa: E402

G = 9.81
# Quiet: a mean kinetic energy per disk of 1e-10 J, about 1e-3 of the energy m g d of lifting one (6e-6 kg) by its
# diameter; a tilt whose creep brings twice that has set the bed flowing.
QUIET = 1e-10
SCENE = {
    "name": "angle_of_repose",
    "dimension": 2,
    "method": "tdm",
    "duration": 10.0,  # an upper bound: the script decides when each stage ends
    "seed": 7,
    "domain": {"lo": [0.0, 0.0], "hi": [0.12, 0.08], "gravity": [0.0, -G]},
    "materials": {"sand": {"density": 2.0, "restitution": 0.3, "friction": 0.5}},
    "contact": {"normal": "linear", "duration": 5e-4, "tangential": "spring"},
    "walls": [
        {"point": [0.0, 0.0], "normal": [0.0, 1.0], "material": "sand"},
        {"point": [0.0, 0.0], "normal": [1.0, 0.0], "material": "sand"},
        {"point": [0.12, 0.0], "normal": [-1.0, 0.0], "material": "sand"},
    ],
    "insert": [{"arrangement": "random", "count": 800, "radius": [0.0008, 0.0012], "material": "sand",
                "region": {"lo": [0.0, 0.0], "hi": [0.12, 0.07]}}],
    "output": {"series_period": 0.01, "snapshot_period": -1},
}


def kinetic_energy(sim):
    v = sim.velocities
    return 0.5 * float(np.sum(sim.masses * np.sum(v * v, axis=1)))


def settle(sim, threshold, piece=0.02, limit=3.0):
    """Short runs until the mean kinetic energy per particle is below `threshold` [J]; the history of (time, total
    kinetic energy)."""
    history = []
    start = sim.time
    while True:
        sim.run(until=sim.time + piece)
        e = kinetic_energy(sim)
        history.append((sim.time, e))
        if e < threshold * sim.n_particles or sim.time - start > limit:
            return history


def surface(sim, tilt, bins=24):
    """The free surface in the frame of the tilted gravity: per bin of the downhill coordinate, the highest disk
    top. Returns (s, h) of the bins in the middle of the box (away from the walls)."""
    c, s_ = math.cos(tilt), math.sin(tilt)
    x, r = sim.positions, sim.radii
    u = x[:, 0] * c + x[:, 1] * s_  # along the tilted horizontal
    h = -x[:, 0] * s_ + x[:, 1] * c + r  # up, against the tilted gravity
    edges = np.linspace(u.min(), u.max(), bins + 1)
    k = np.clip(np.digitize(u, edges) - 1, 0, bins - 1)
    top = np.full(bins, -np.inf)
    np.maximum.at(top, k, h)
    mid = 0.5 * (edges[1:] + edges[:-1])
    keep = slice(bins // 6, bins - bins // 6)
    return mid[keep], top[keep]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=pathlib.Path, default=pathlib.Path("runs/angle_of_repose"))
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    with haet.Simulation.from_dict(SCENE, out=a.out) as sim:
        print(f"pour: {sim.n_particles} disks")
        poured = settle(sim, threshold=QUIET)
        print(f"settled at t = {sim.time:.2f} s, kinetic energy {poured[-1][1]:.3g} J")
        # Tilt gravity by 2 degrees at a time; an avalanche shows as kinetic energy far above the creep of a tilt.
        tilt, tilts = 0.0, []
        while tilt < math.radians(45):
            tilt += math.radians(2.0)
            sim.gravity = [G * math.sin(tilt), -G * math.cos(tilt)]
            sim.run(until=sim.time + 0.05)
            e = kinetic_energy(sim)
            tilts.append((math.degrees(tilt), e))
            print(f"tilt {math.degrees(tilt):4.1f} deg: kinetic energy {e:.3g} J")
            if e > 2 * QUIET * sim.n_particles:
                break
        print(f"avalanche at a tilt of {math.degrees(tilt):.1f} deg (the angle of maximum stability)")
        after = settle(sim, threshold=QUIET)
        s, h = surface(sim, tilt)
        slope, offset = np.polyfit(s, h, 1)
        repose = math.degrees(math.atan(-slope))
        print(f"angle of repose: {repose:.1f} deg")
        x = sim.positions.copy()
        r = sim.radii.copy()
        sim.finish()

    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 4))
    ax0.add_collection(matplotlib.collections.EllipseCollection(2 * r, 2 * r, 0, units="xy", offsets=x,
                                                                transOffset=ax0.transData, facecolor="tab:orange"))
    c, sn = math.cos(tilt), math.sin(tilt)
    line = np.array([s[[0, -1]] * c - (slope * s[[0, -1]] + offset) * sn,
                     s[[0, -1]] * sn + (slope * s[[0, -1]] + offset) * c])
    ax0.plot(line[0], line[1], "k--", label=f"surface: {repose:.1f} deg to the tilted horizontal")
    ax0.annotate("", xy=(0.06 + 0.01 * sn, 0.075 - 0.01 * c), xytext=(0.06, 0.075),
                 arrowprops={"arrowstyle": "->"})
    ax0.set(xlim=(0, 0.12), ylim=(0, 0.08), aspect="equal", xlabel="x [m]", ylabel="y [m]",
            title=f"after the avalanche (gravity tilted {math.degrees(tilt):.0f} deg)")
    ax0.legend(loc="lower left", fontsize=8)
    t = np.array(poured + after)
    ax1.semilogy(t[:, 0], t[:, 1], ".-", label="settling")
    ax1.set(xlabel="time [s]", ylabel="kinetic energy [J]", title="pour, settle, tilt, settle")
    ax1.legend()
    fig.tight_layout()
    fig.savefig(a.out / "angle_of_repose.png", dpi=120)
    print(f"plot: {a.out / 'angle_of_repose.png'}")


if __name__ == "__main__":
    main()
