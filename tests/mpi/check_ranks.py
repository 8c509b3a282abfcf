#!/usr/bin/env python3
"""Runs across MPI ranks (docs/parallel.md), checked against the run of one process.

    check_ranks.py CHECK HAET MPIRUN SOURCE_DIR WORK_DIR

CHECK is one of
  conserve  a periodic gas whose particles cross the slabs' faces, on 2 and 4 ranks: every particle of the start
            is in final.csv once, n_particles never changes, and particles did migrate (run.json)
  momentum  the elastic periodic gas on 4 ranks: the momentum of series.csv stays at its start to round-off
  chute     the LAMMPS chute of bench/ (from its lattice, bench/make_chute_data.sh) on 1, 2 and 4 ranks: the kinetic
            energy and the mean velocity over the run agree with one rank's; prints whether they are the same bits
  walls     beads settling in a box of planes (slabs across the height, the cuts placed again as they fall) on 1, 2
            and 4 ranks: the kinetic energy and the floor's load over the run agree with one rank's
  refuse    what does not run across ranks yet exits 2 naming the key (method, inlets, meshes), as bad input does;
            a blow-up on one rank ends every rank with exit 3
"""
import csv
import json
import math
import os
import shutil
import subprocess
import sys

CHECK, HAET, MPIRUN, SRC, WORK = sys.argv[1:6]
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
failures = []


def fail(what):
    failures.append(what)
    print("FAIL:", what)


def run(ranks, scenario, out, sets=(), expect=0):
    """haet run under mpirun -np RANKS (one thread per rank); returns (exit status, stderr)."""
    if os.path.exists(out):
        shutil.rmtree(out)
    cmd = [MPIRUN, "-np", str(ranks), "--oversubscribe", HAET, "run", scenario, "--out", out, "--threads", "1",
           "--quiet"]
    for s in sets:
        cmd += ["--set", s]
    p = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=600)
    if expect is not None and p.returncode != expect:
        fail(f"-np {ranks} {os.path.basename(scenario)}: exit {p.returncode}, expected {expect}\n{p.stderr[-3000:]}")
    return p.returncode, p.stderr


def series(out):
    with open(os.path.join(out, "series.csv")) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    head = rows[0]
    return {c: [float(r[k]) if r[k] != "" else math.nan for r in rows[1:]] for k, c in enumerate(head)}, rows[1:]


def final_ids(out):
    """The ids of final.data's Atoms section (final.csv is in the order of the ids, without them)."""
    ids, inside = [], False
    with open(os.path.join(out, "final.data")) as f:
        for line in f:
            words = line.split()
            if words and words[0] == "Atoms":
                inside = True
            elif inside and words and words[0][0].isalpha():
                break
            elif inside and words:
                ids.append(int(words[0]))
    return ids


def run_json(out):
    with open(os.path.join(out, "run.json")) as f:
        return json.load(f)


GAS = os.path.join(SRC, "examples", "elastic_gas3d.toml")
# Velocity Verlet (runs across ranks take it only), no stress tensor; 600 spheres at v_rms ~ 0.4 m/s cross a slab of
# 4.6 mm in ~10 ms.
GAS_SETS = ["tdm.integrator=\"verlet\"", "output.stress=false", "tdm.steps_per_contact=50", "duration=0.02",
            "output.series_period=0.001", "output.snapshot_period=-1", "insert[1].count=600",
            "domain.hi=[0.0232, 0.0232, 0.0232]"]


def conserve():
    for ranks in (2, 4):
        out = os.path.join(WORK, f"conserve{ranks}")
        status, _ = run(ranks, GAS, out, GAS_SETS)
        if status != 0:
            continue
        s, _ = series(out)
        if set(s["n_particles"]) != {600.0}:
            fail(f"-np {ranks}: n_particles {sorted(set(s['n_particles']))}, expected 600 in every row")
        ids = final_ids(out)
        if len(ids) != 600 or len(set(ids)) != 600:
            fail(f"-np {ranks}: final.csv holds {len(ids)} particles, {len(set(ids))} distinct ids (600 expected)")
        migrated = run_json(out).get("migrated", 0)
        print(f"-np {ranks}: {len(set(ids))} distinct ids, {migrated} migrations")
        if migrated < 50:
            fail(f"-np {ranks}: only {migrated} migrations: the test does not exercise them")


def momentum():
    out = os.path.join(WORK, "momentum4")
    status, _ = run(4, GAS, out, GAS_SETS)
    if status != 0:
        return
    s, _ = series(out)
    # Scale: the sum of |m v| (from the kinetic energy: sum m v^2 = 2 K, m = 2500 * (4/3) pi r^3, r ~ 1 mm).
    m = 2500 * 4 / 3 * math.pi * 1e-9
    scale = 600 * math.sqrt(2 * s["kinetic_energy"][0] / 600 * m)
    worst = 0
    for c in ("momentum_x", "momentum_y", "momentum_z"):
        worst = max(worst, max(abs(v - s[c][0]) for v in s[c]))
    print(f"-np 4: momentum drift {worst:.3e} kg m/s, sum |m v| ~ {scale:.3e}, ratio {worst / scale:.2e}")
    if not worst <= 1e-12 * scale:
        fail(f"momentum drifts by {worst:.3e} kg m/s against sum |m v| ~ {scale:.3e}")
    e = [k + c for k, c in zip(s["kinetic_energy"], s["elastic_energy"])]
    drift = max(abs(v - e[0]) for v in e) / e[0]
    print(f"-np 4: energy drift {drift:.2e}")
    if not drift < 1e-3:
        fail(f"the elastic gas's energy drifts by {drift:.2e} across ranks")


def chute():
    # The chute of bench/compare_lammps.sh, smaller (16 x 8 x 16 spheres): the lattice flows for 40 000 steps on one
    # rank (as bench/lammps/in.chute3d.prep does in LAMMPS) into a dense flow, 1 200 contacts among 2 048 spheres,
    # whose last state (final.csv, the frozen base marked) the three runs start from.
    lattice = os.path.join(WORK, "chute3d.lattice.data")
    env = dict(ENV, NX="16", NY="8", NZ="16")
    subprocess.run([os.path.join(SRC, "bench", "make_chute_data.sh"), "3d", lattice], env=env, check=True,
                   capture_output=True)
    example = os.path.join(SRC, "examples", "lammps_chute3d.toml")
    box = "domain.hi=[16.8, 8.4, 33.6]"
    prep = os.path.join(WORK, "prep")
    status, _ = run(1, example, prep, [f"insert[1].file=\"{lattice}\"", box, "output.stress=false", "duration=4",
                                       "output.series_period=4", "output.snapshot_period=-1"])
    if status != 0:
        return
    with open(example) as f:
        text = f.read()
    text = text.replace('format = "lammps"', 'format = "csv"')
    text = "\n".join(line for line in text.splitlines() if not line.startswith("frozen_types"))
    scenario = os.path.join(WORK, "chute_flowing.toml")
    with open(scenario, "w") as f:
        f.write(text + "\n")
    sets = [f"insert[1].file=\"{os.path.join(prep, 'final.csv')}\"", box, "output.stress=false",
            "output.series_period=0.01", "duration=0.5"]
    got = {}
    for ranks in (1, 2, 4):
        out = os.path.join(WORK, f"chute{ranks}")
        status, _ = run(ranks, scenario, out, sets)
        if status == 0:
            got[ranks] = series(out)
    if 1 not in got:
        return
    (one, rows1) = got[1]
    mass = sum(1.0 for _ in final_ids(os.path.join(WORK, "chute1")))  # m = 1 in LAMMPS lj units

    def mean(v):
        return sum(v) / len(v)

    for ranks in (2, 4):
        if ranks not in got:
            continue
        s, rows = got[ranks]
        # The same bits? The last state of every particle (final.csv, in the order of the ids) against one rank's.
        with open(os.path.join(WORK, f"chute{ranks}", "final.csv")) as f, \
                open(os.path.join(WORK, "chute1", "final.csv")) as g:
            a, b = f.read().splitlines()[2:], g.read().splitlines()[2:]
        worst = max((abs(float(x) - float(y)) for la, lb in zip(a, b)
                     for x, y in zip(la.split(",")[:6], lb.split(",")[:6])), default=0)
        print(f"-np {ranks}: final state {'the same bits as' if a == b else 'not the same bits as'} one rank's "
              f"(largest difference of a position or velocity component {worst:.3e})")
        if len(s["time"]) != len(one["time"]):
            fail(f"-np {ranks}: {len(s['time'])} rows, one rank {len(one['time'])}")
            continue
        for name, a, b in (("kinetic energy", s["kinetic_energy"], one["kinetic_energy"]),
                           ("mean velocity x", [p / mass for p in s["momentum_x"]],
                            [p / mass for p in one["momentum_x"]])):
            rel = abs(mean(a) - mean(b)) / abs(mean(b))
            print(f"-np {ranks}: {name} over the run {mean(a):.6g}, one rank {mean(b):.6g}, relative {rel:.2e}")
            if not rel < 0.02:
                fail(f"-np {ranks}: {name} over the run differs from one rank's by {rel:.2e}")
        if s["n_particles"] != one["n_particles"]:
            fail(f"-np {ranks}: the particle count differs from one rank's")


def walls():
    # Beads dropped into a box of five planes (no periodic axis: the slabs cut the height, and the cuts move as the
    # beads fall, by the re-placement when the counts drift apart) on 1, 2 and 4 ranks: the kinetic energy and the
    # floor's load over the run agree with one rank's, the particles are kept.
    scenario = os.path.join(SRC, "examples", "box3d_settle.toml")
    sets = ["duration=0.08", "output.series_period=0.002", "output.snapshot_period=-1", "output.stress=false",
            "walls[1].name=\"floor\""]
    got = {}
    for ranks in (1, 2, 4):
        out = os.path.join(WORK, f"walls{ranks}")
        status, _ = run(ranks, scenario, out, sets)
        if status == 0:
            got[ranks], _ = series(out)
            if ranks > 1:
                j = run_json(out)
                print(f"-np {ranks}: {j.get('migrated')} migrations, cuts placed again "
                      f"{j['decomposition']['rebalances']} times, axis {j['decomposition']['axis']}")
                ids = final_ids(out)
                if len(set(ids)) != 2000 or len(ids) != 2000:
                    fail(f"-np {ranks}: final.data holds {len(ids)} particles, {len(set(ids))} ids (2000 expected)")
    if 1 not in got:
        return
    one = got[1]

    def mean(v):
        return sum(v) / len(v)

    for ranks in (2, 4):
        if ranks not in got:
            continue
        s = got[ranks]
        # The floor's load is sampled every 2 ms while beads land on it: noisier than the energy.
        for name, tol in (("kinetic_energy", 0.02), ("floor_fz", 0.05)):
            rel = abs(mean(s[name]) - mean(one[name])) / abs(mean(one[name]))
            print(f"-np {ranks}: {name} over the run {mean(s[name]):.6g}, one rank {mean(one[name]):.6g}, "
                  f"relative {rel:.2e}")
            if not rel < tol:
                fail(f"-np {ranks}: {name} over the run differs from one rank's by {rel:.2e}")


def refuse():
    for sets, key in ((["method=\"edm\""], "method"), (["method=\"haet\""], "method"),
                      (["tdm.integrator=\"gear5\"", "output.stress=false"], "tdm.integrator"),
                      (["tdm.integrator=\"verlet\"", "output.stress=true"], "output.stress"),
                      (["no_such_key=1"], "no_such_key")):
        out = os.path.join(WORK, "refused")
        status, err = run(2, GAS, out, sets, expect=2)
        if key not in err:
            fail(f"{sets}: the error does not name {key}:\n{err[-2000:]}")
    # A blow-up on one rank (an overlap beyond max_overlap, first met by whichever rank holds the pair) stops every
    # rank after the same step: exit 3, run.json "failed: ..." naming the particle, as from one process.
    out = os.path.join(WORK, "blowup")
    status, err = run(2, GAS, out, GAS_SETS + ["tdm.max_overlap=1e-4"], expect=3)
    if status == 3 and not run_json(out)["status"].startswith("failed: overlap"):
        fail(f"the blow-up's run.json status: {run_json(out)['status']}")
    inlet = os.path.join(SRC, "examples", "pour3d.toml")
    status, err = run(2, inlet, os.path.join(WORK, "refused"), ["output.stress=false"], expect=2)
    if "inlet" not in err:
        fail(f"pour3d: the error does not name the inlet:\n{err[-2000:]}")


os.makedirs(WORK, exist_ok=True)
{"conserve": conserve, "momentum": momentum, "chute": chute, "walls": walls, "refuse": refuse}[CHECK]()
if failures:
    sys.exit(1)
print("ok")
