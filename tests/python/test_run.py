"""A run from Python is the run of `haet run`: the same outputs, bit for bit, in one piece or in many."""
import numpy as np
import pytest

import haet
from conftest import EXAMPLE, box2d, haet_run, last_snapshot, small


def series_without(directory, column):
    """series.csv's lines without one column."""
    lines = [line.split(",") for line in (directory / "series.csv").read_text().splitlines()]
    if column not in lines[0]:
        return [",".join(cells) for cells in lines]
    k = lines[0].index(column)
    return [",".join(cells[:k] + cells[k + 1:]) for cells in lines]


def same_outputs(a, b, rebuilds=True):
    """The same series, final state and last snapshot; rebuilds=False: but for series.csv's count of neighbour-list
    builds (an engine that starts again from a changed state builds its list once more: a count, not the state)."""
    if rebuilds:
        assert (a / "series.csv").read_bytes() == (b / "series.csv").read_bytes()
    else:
        assert series_without(a, "rebuilds") == series_without(b, "rebuilds")
    for name in ("final.csv",):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    assert last_snapshot(a).name == last_snapshot(b).name
    assert last_snapshot(a).read_bytes() == last_snapshot(b).read_bytes()


@pytest.mark.parametrize("method", ["tdm", "edm", "haet"])
def test_python_run_gives_the_bits_of_haet_run(tmp_path, method):
    sets = box2d(method=method)
    assert haet_run(EXAMPLE, tmp_path / "cli", sets) == 0
    with haet.Simulation.from_file(EXAMPLE, out=tmp_path / "py", set=sets) as sim:
        sim.run(until=0.05)
        assert sim.finish() == "completed"
    same_outputs(tmp_path / "cli", tmp_path / "py")


def test_pieces_ending_on_steps_give_the_bits_of_one_run(tmp_path):
    with small(out=tmp_path / "one") as sim:
        sim.run(until=0.05)
        steps = sim.steps
    with small(out=tmp_path / "pieces") as sim:
        sim.step(1)
        sim.step(6)
        while sim.steps + 37 <= steps:
            sim.step(37)
        sim.step(steps - sim.steps)
        assert sim.steps == steps
        assert sim.time == pytest.approx(0.05)
    same_outputs(tmp_path / "one", tmp_path / "pieces")


def test_time_steps_and_series():
    with small() as sim:
        assert sim.method == "tdm" and sim.dimension == 2
        assert sim.time == 0 and sim.steps == 0
        dt = sim.dt
        sim.step(10)
        assert sim.steps == 10
        assert sim.time == pytest.approx(10 * dt)
        sim.run(until=0.012)
        s = sim.series
        assert list(s["time"]) == pytest.approx([0.0, 0.005, 0.01])
        assert s["n_particles"][0] == 400
        assert sim.run_info["status"] == "running"
        sim.finish()
        assert sim.run_info["status"] == "completed"
        assert sim.run_info["steps"] == sim.steps


def test_without_out_the_outputs_go_to_a_temporary_directory_removed_at_close():
    sim = small()
    d = sim.directory
    sim.step(5)
    assert (d / "series.csv").exists()
    sim.close()
    assert not d.exists()
    assert sim.closed
    with pytest.raises(ValueError):
        sim.step(1)


def test_from_dict_is_the_loader_of_the_text():
    import tomllib
    d = tomllib.loads(EXAMPLE.read_text())
    d["insert"][0]["count"] = 300
    with haet.Simulation.from_dict(d) as a, haet.Simulation.from_file(EXAMPLE, set=["insert[1].count=300"]) as b:
        a.step(50)
        b.step(50)
        assert np.array_equal(a.positions, b.positions)


def test_overrides_as_haet_run_set():
    with haet.Simulation.from_file(EXAMPLE, set=["insert[1].count=50"]) as sim:
        assert sim.n_particles == 50


def test_step_of_a_pure_event_driven_run_raises():
    with small(method="edm") as sim:
        with pytest.raises(ValueError, match="run\\(until"):
            sim.step(1)
        sim.run(until=0.01)
        assert sim.time == pytest.approx(0.01)


def test_save_and_load_go_on_as_the_run_would(tmp_path):
    path = EXAMPLE
    sets = box2d()
    with haet.Simulation.from_file(path, set=sets) as one:
        one.run(until=0.05)
        x_one = one.positions.copy()
    with haet.Simulation.from_file(path, set=sets) as first:
        first.run(until=0.02)
        first.velocities  # a view handed out and not written: nothing changes
        first.save(tmp_path / "state.haet")
        first.run(until=0.05)
        assert np.array_equal(first.positions, x_one)
    with haet.Simulation.load(tmp_path / "state.haet", path, out=tmp_path / "second", set=sets) as second:
        assert second.time == pytest.approx(0.02)
        second.run(until=0.05)
        assert np.array_equal(second.positions, x_one)
        second.finish()
        assert second.series["time"][0] == pytest.approx(0.02)
        assert second.run_info["resumed_from"] == "state.haet"


# (hard disks in rows driven sideways into a wall collapse inelastically: an upward throw for them)
@pytest.mark.parametrize("method,v", [("tdm", (0.25, -0.5)), ("edm", (0.0, 0.5))])
def test_a_write_through_a_view_gives_the_outputs_of_the_file(tmp_path, method, v):
    """The velocities written before the first step: series, snapshots and final state are those of `haet run` of
    the scenario with that velocity, byte for byte."""
    assert haet_run(EXAMPLE, tmp_path / "cli", box2d(method=method, velocity=v)) == 0
    with haet.Simulation.from_file(EXAMPLE, out=tmp_path / "py", set=box2d(method=method)) as sim:
        sim.velocities[:] += np.array(v)
        sim.run(until=0.05)
        assert sim.finish() == "completed"
    same_outputs(tmp_path / "cli", tmp_path / "py", rebuilds=False)


def test_a_write_mid_run_gives_the_outputs_of_the_same_write_after_a_restart(tmp_path):
    """A velocity written mid-run through a view, and the same write into the run restarted from the checkpoint of
    that time: the same outputs from there on, byte for byte."""
    sets = box2d(velocity=(0.0, -0.1))
    with haet.Simulation.from_file(EXAMPLE, out=tmp_path / "one", set=sets) as a:
        a.run(until=0.02)
        a.save(tmp_path / "state.haet")
        a.velocities[::3] *= -1.0
        a.run(until=0.05)
        a.finish()
    with haet.Simulation.load(tmp_path / "state.haet", EXAMPLE, out=tmp_path / "restart", set=sets) as b:
        b.velocities[::3] *= -1.0
        b.run(until=0.05)
        b.finish()
    one, restart = tmp_path / "one", tmp_path / "restart"
    assert (one / "final.csv").read_bytes() == (restart / "final.csv").read_bytes()
    assert last_snapshot(one).read_bytes() == last_snapshot(restart).read_bytes()
    # the rows after the write's time (the row at it: the continued run wrote it before the write)
    rows = (one / "series.csv").read_text().splitlines()
    later = (restart / "series.csv").read_text().splitlines()
    assert later[1].startswith("0.02,") and len(later) > 4
    assert rows[-(len(later) - 2):] == later[2:]
