#!/usr/bin/python3
"""The cost of driving a run from Python one step at a time: N calls sim.step(1) against one call sim.step(N), on
examples/box2d_settle.toml made 10 000 disks. Both go on in one run, in alternating blocks (B single steps, then one
call of B steps, then the other way round), so that a load on the machine that changes over the minutes weighs on
both alike; the run computes the same whatever the pieces (docs/python.md). Writes
bench/results/MACHINE/python_step_loop.csv: one row per block, and the overhead of the loop over the single calls.

    PYTHONPATH=BUILD/python bench/python_step_loop.py [--steps 10000] [--block 500] [--threads 1]
"""
import argparse
import datetime
import pathlib
import subprocess
import time

import haet

HERE = pathlib.Path(__file__).resolve().parent

# examples/box2d_settle.toml made 10 000 disks on a lattice in a box twice as wide and high, no snapshots.
SCENE = HERE.parent / "examples" / "box2d_settle.toml"
SETS = ["domain.hi=[0.2, 0.35]", "walls[3].point=[0.2, 0.0]", "insert[1].count=10000",
        "insert[1].arrangement=lattice", "insert[1].region={ lo = [0.0, 0.0], hi = [0.2, 0.35] }",
        "output.series_period=1.0", "output.snapshot_period=-1"]


def commit():
    return subprocess.run(["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True).stdout.strip() or "NA"


def machine():
    return subprocess.run(["bash", "-c", f"source {HERE}/lib.sh; machine_name"], capture_output=True,
                          text=True).stdout.strip() or "unknown"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=10000, help="steps of each kind")
    ap.add_argument("--block", type=int, default=500, help="steps per block")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--out", type=pathlib.Path, default=None, help="CSV file (default: bench/results/MACHINE/)")
    a = ap.parse_args()
    out = a.out or HERE / "results" / machine() / "python_step_loop.csv"
    out.parent.mkdir(parents=True, exist_ok=True)
    rows, total = [], {"loop": 0.0, "single": 0.0}
    with haet.Simulation.from_file(SCENE, threads=a.threads, set=SETS) as sim:
        n = sim.n_particles
        sim.step(a.block)  # the first steps (pair list, caches) timed by neither
        for b in range(2 * (a.steps // a.block)):
            kind = ("loop", "single")[(b + b // 2) % 2]  # loop single single loop loop single ...
            start = time.perf_counter()
            if kind == "loop":
                for _ in range(a.block):
                    sim.step(1)
            else:
                sim.step(a.block)
            seconds = time.perf_counter() - start
            total[kind] += seconds
            rows.append((b + 1, kind, n, a.block, a.threads, f"{seconds:.5f}"))
    overhead = total["loop"] / total["single"] - 1
    per_call = (total["loop"] - total["single"]) / a.steps
    # Each pair of neighbouring blocks holds one of each kind, timed within seconds of each other: their ratio is
    # the loop's cost under the same load; the spread of the ratios shows how noisy the machine was.
    ratios = []
    for k in range(0, len(rows) - 1, 2):
        by = {rows[k][1]: float(rows[k][5]), rows[k + 1][1]: float(rows[k + 1][5])}
        ratios.append(by["loop"] / by["single"])
    ratios.sort()
    median = ratios[len(ratios) // 2] if len(ratios) % 2 else 0.5 * sum(ratios[len(ratios) // 2 - 1:][:2])
    with open(out, "w") as f:
        f.write("date,haet_commit,block,kind,particles,steps,threads,seconds\n")
        day, head = datetime.date.today().isoformat(), commit()
        for row in rows:
            f.write(",".join(str(v) for v in (day, head) + row) + "\n")
    print(f"{n} particles, {a.steps} steps of each kind in blocks of {a.block}: single calls {total['single']:.3f} s, "
          f"loop {total['loop']:.3f} s: overhead {100 * overhead:.2f} % ({1e6 * per_call:.1f} us per call; "
          f"limit 5 %); loop/single per pair of blocks: min {ratios[0]:.4f}, median {median:.4f} "
          f"({len(ratios)} pairs); {out}")
    return 0 if overhead <= 0.05 else 1


if __name__ == "__main__":
    raise SystemExit(main())
