#!/usr/bin/env python3
"""Height profiles of a run's coarse-grained fields (fields_NAME.csv of a 1-axis [[fields]] block; docs/scenario.md,
"Fields"): volume fraction, velocity, stress against the grid's coordinate, at one output time (the last by default),
drawn with matplotlib into a PNG.

    tools/plot_profiles.py runs/chute3d_profiles/fields_z.csv [--time T] [--out profiles.png]

With --slope DEGREES (a chute) it also draws the weight above each height, int_z rho g cos(theta) and
int_z rho g sin(theta) (g = 1, or --gravity), against sigma_zz and -sigma_xz: the momentum balance of steady flow
(docs/physics.md L.8), and v_x against H^{3/2} - (H - z)^{3/2}, Bagnold's profile.
"""
import argparse
import csv
import math
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("--time", type=float, help="the output time to draw (default: the last)")
    ap.add_argument("--out", default="profiles.png")
    ap.add_argument("--slope", type=float, help="chute angle [degrees]: draw the momentum balance and Bagnold's law")
    ap.add_argument("--gravity", type=float, default=1.0, help="|g| for the momentum balance (default 1)")
    ap.add_argument("--base", type=float, default=0.0, help="height of the base, where the flow depth starts")
    a = ap.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("plot_profiles.py needs matplotlib (Debian: python3-matplotlib)")
    with open(a.csv) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{a.csv}: no rows")
    axis = list(rows[0].keys())[1]
    times = sorted({float(r["time"]) for r in rows})
    t = a.time if a.time is not None else times[-1]
    t = min(times, key=lambda x: abs(x - t))
    sel = [r for r in rows if float(r["time"]) == t]
    z = [float(r[axis]) for r in sel]

    def col(name):
        return [float(r[name]) for r in sel] if name in sel[0] else None

    panels = [("volume_fraction", ["volume_fraction"]), ("velocity", ["velocity_x", "velocity_y", "velocity_z"]),
              ("stress", ["stress_xx", "stress_yy", "stress_zz", "stress_xz"])]
    fig, axes = plt.subplots(1, 3 + (a.slope is not None), figsize=(4 * (3 + (a.slope is not None)), 5))
    for ax, (title, names) in zip(axes, panels):
        for n in names:
            v = col(n)
            if v is not None:
                ax.plot(v, z, label=n)
        ax.set_xlabel(title)
        ax.legend(fontsize="small")
    axes[0].set_ylabel(axis)
    if a.slope is not None:
        th = math.radians(a.slope)
        rho = col("density")
        h = z[1] - z[0]
        above, s = [0.0] * len(z), 0.0
        for q in reversed(range(len(z))):
            above[q] = s + 0.5 * rho[q] * h
            s += rho[q] * h
        ax = axes[2]
        ax.plot([w * a.gravity * math.cos(th) for w in above], z, "k--", label="weight cos")
        ax.plot([-w * a.gravity * math.sin(th) for w in above], z, "k:", label="-weight sin")
        ax.legend(fontsize="small")
        phi = col("volume_fraction")
        top = max(zz for zz, p in zip(z, phi) if p > 0.5 * max(phi))
        H = top - a.base
        x = [H ** 1.5 - max(H - (zz - a.base), 0.0) ** 1.5 for zz in z]
        vx = col("velocity_x")
        keep = [(xx, v) for xx, v, zz in zip(x, vx, z) if a.base < zz < top]
        axes[3].plot([k[0] for k in keep], [k[1] for k in keep], "o", ms=3)
        axes[3].set_xlabel("H^3/2 - (H - z)^3/2")
        axes[3].set_ylabel("v_x")
        axes[3].yaxis.set_label_position("right")
    fig.suptitle(f"{a.csv} at t = {t:g}")
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print(f"{a.out}: {len(z)} cells at t = {t:g}")


if __name__ == "__main__":
    main()
