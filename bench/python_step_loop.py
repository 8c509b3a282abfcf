#!/usr/bin/python3
"""The cost of driving a run from Python one step at a time: a loop of N calls sim.step(1) against one call
sim.step(N), on examples/box2d_settle.toml made 10 000 disks, in alternating rounds (each round a new run from the same
start, so that both do the same work). Writes bench/results/MACHINE/python_step_loop.csv: one row per round and the
median overhead of the loop over the single call.

    PYTHONPATH=BUILD/python bench/python_step_loop.py [--steps 10000] [--rounds 3] [--threads 1]
"""
import argparse
import pathlib
import statistics
import subprocess
import time

import haet

HERE = pathlib.Path(__file__).resolve().parent

# examples/box2d_settle.toml made 10 000 disks on a lattice in a box twice as wide and high, no snapshots.
SCENE = HERE.parent / "examples" / "box2d_settle.toml"
SETS = ["domain.hi=[0.2, 0.3]", "walls[3].point=[0.2, 0.0]", "insert[1].count=10000", "insert[1].arrangement=lattice",
        "insert[1].region={ lo = [0.0, 0.0], hi = [0.2, 0.25] }", "output.series_period=1.0",
        "output.snapshot_period=-1"]


def machine():
    return subprocess.run(["bash", "-c", f"source {HERE}/lib.sh; machine_name"], capture_output=True,
                          text=True).stdout.strip() or "unknown"


def timed(kind, steps, threads):
    with haet.Simulation.from_file(SCENE, threads=threads, set=SETS) as sim:
        n = sim.n_particles
        start = time.perf_counter()
        if kind == "loop":
            for _ in range(steps):
                sim.step(1)
        else:
            sim.step(steps)
        seconds = time.perf_counter() - start
        assert sim.steps == steps
    return n, seconds


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=10000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--out", type=pathlib.Path, default=None, help="CSV file (default: bench/results/MACHINE/)")
    a = ap.parse_args()
    out = a.out or HERE / "results" / machine() / "python_step_loop.csv"
    out.parent.mkdir(parents=True, exist_ok=True)
    rows, ratios = [], []
    for r in range(a.rounds):
        order = ("loop", "single") if r % 2 == 0 else ("single", "loop")  # alternate which goes first
        t = {}
        for kind in order:
            n, t[kind] = timed(kind, a.steps, a.threads)
            rows.append((r + 1, kind, n, a.steps, a.threads, t[kind]))
            print(f"round {r + 1}: {kind:6s} {a.steps} steps of {n} particles: {t[kind]:.3f} s", flush=True)
        ratios.append(t["loop"] / t["single"] - 1)
    overhead = statistics.median(ratios)
    with open(out, "w") as f:
        f.write("round,kind,particles,steps,threads,seconds\n")
        for row in rows:
            f.write(",".join(str(v) for v in row[:-1]) + f",{row[-1]:.4f}\n")
        f.write(f"# median overhead of the loop of sim.step(1) over sim.step(N): {100 * overhead:.2f} %\n")
    print(f"median overhead of the step(1) loop: {100 * overhead:.2f} % (limit 5 %); {out}")
    return 0 if overhead <= 0.05 else 1


if __name__ == "__main__":
    raise SystemExit(main())
