"""Scenes and helpers of the Python module's tests (the module is on PYTHONPATH: the build's python/ directory)."""
import os
import pathlib
import subprocess

import pytest

import haet

SOURCE = pathlib.Path(__file__).resolve().parents[2]


EXAMPLE = SOURCE / "examples" / "box2d_settle.toml"
HOPPER = SOURCE / "examples" / "hopper2d.toml"


def box2d(method="tdm", count=400, velocity=(0.0, 0.0), gravity=(0.0, -9.81), duration=0.05):
    """The overrides that make examples/box2d_settle.toml small: disks on a lattice at a given velocity, with
    contacts on the floor from the start."""
    return [f"method={method}", f"duration={duration}", f"insert[1].count={count}", "insert[1].arrangement=lattice",
            "insert[1].radius=0.001", "insert[1].temperature=0", f"insert[1].velocity=[{velocity[0]}, {velocity[1]}]",
            f"domain.gravity=[{gravity[0]}, {gravity[1]}]", "output.series_period=0.005",
            "output.snapshot_period=0.025"]


def small(*, extra=(), **kw):
    """The small box as a Simulation; keywords: those of box2d, and out, threads."""
    sim_kw = {k: kw.pop(k) for k in ("out", "threads") if k in kw}
    return haet.Simulation.from_file(EXAMPLE, set=box2d(**kw) + list(extra), **sim_kw)


@pytest.fixture
def scene(tmp_path):
    """Writes a scene's text to a file in tmp_path and gives its path."""
    def write(text, name="scene.toml"):
        p = tmp_path / name
        p.write_text(text)
        return p
    return write


def haet_binary():
    return os.environ.get("HAET_BINARY") or str(SOURCE / "build" / "haet")


def haet_run(scenario, out, sets=()):
    """`haet run` of a scenario file into out with overrides; returns the exit code."""
    args = [a for kv in sets for a in ("--set", kv)]
    return subprocess.run([haet_binary(), "run", str(scenario), "--out", str(out), "--quiet", *args],
                          capture_output=True, text=True).returncode


def last_snapshot(directory):
    shots = sorted(pathlib.Path(directory).glob("particles_*.vtu"))
    assert shots, f"no snapshot in {directory}"
    return shots[-1]
