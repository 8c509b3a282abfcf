"""Walls from a script: their motion changed between runs goes on from where the wall is, the particles feel it, a
change at the start is that of the file, and a checkpoint holds it."""
import numpy as np
import pytest

import haet
from conftest import EXAMPLE, HOPPER, small

# One disk at rest on the floor of examples/box2d_settle.toml (walls[1], named "floor" here).
ONE = ["insert[1].count=1", "insert[1].region={ lo = [0.045, 0.0], hi = [0.055, 0.0022] }", "walls[1].name=floor"]


def test_walls_are_listed_in_the_scenarios_order():
    with small(extra=["walls[1].name=floor"]) as sim:
        w = sim.walls
        assert [x["index"] for x in w] == [1, 2, 3]
        assert w[0]["name"] == "floor" and w[0]["kind"] == "plane"
        assert list(w[0]["normal"]) == [0.0, 1.0] and list(w[0]["velocity"]) == [0.0, 0.0]
        assert w[0]["angular_velocity"] is None


def test_a_moving_floor_carries_a_resting_particle():
    v = np.array([0.05, 0.0])
    with small(count=1, extra=ONE, duration=0.2) as sim:
        sim.run(until=0.05)  # settled on the floor
        assert abs(sim.velocities[0, 0]) < 1e-9
        t0, p0 = sim.time, sim.walls[0]["point"]
        sim.set_wall("floor", velocity=v)
        p1 = sim.walls[0]["point"]
        assert np.array_equal(p0, p1)  # no jump
        assert list(sim.walls[0]["velocity"]) == list(v)
        sim.run(until=0.1)
        # the floor has gone on from where it was
        assert sim.walls[0]["point"] == pytest.approx(p0 + v * (sim.time - t0), abs=1e-15)
        # friction drags the disk along until it rolls without slipping, at v/3 for a uniform disk (the tangential
        # spring then oscillates about that state, by some per cent)
        vx, spin = sim.velocities[0, 0], sim.angular_velocities[0]
        assert vx == pytest.approx(v[0] / 3, rel=0.1)
        assert vx + spin * sim.radii[0] == pytest.approx(v[0], rel=0.1)  # the contact point moves with the floor
        sim.set_wall(1, velocity=[0.0, 0.0])  # by its index; stopped where it is
        p2 = sim.walls[0]["point"]
        sim.run(until=0.15)
        assert np.array_equal(sim.walls[0]["point"], p2)


@pytest.mark.parametrize("method", ["tdm", "edm"])
def test_a_wall_velocity_set_at_the_start_is_that_of_the_file(method):
    v = (0.0, 0.2)  # the floor rises into the disks
    with small(method=method, velocity=(0.0, -0.1)) as a, \
            small(method=method, velocity=(0.0, -0.1), extra=[f"walls[1].velocity=[{v[0]}, {v[1]}]"]) as b:
        a.set_wall(1, velocity=v)
        a.run(until=0.02)
        b.run(until=0.02)
        assert np.array_equal(a.positions, b.positions)
        assert np.array_equal(a.velocities, b.velocities)


def test_a_wall_velocity_set_mid_run_is_in_the_checkpoint(tmp_path):
    with small(count=1, extra=ONE, duration=0.2) as sim:
        sim.run(until=0.05)
        sim.set_wall("floor", velocity=[0.05, 0.0])
        sim.run(until=0.06)
        sim.save(tmp_path / "state.haet")
        sim.run(until=0.1)
        x, floor = sim.positions.copy(), sim.walls[0]["point"]
    from conftest import box2d
    with haet.Simulation.load(tmp_path / "state.haet", EXAMPLE, set=box2d(count=1, duration=0.2) + ONE) as sim:
        assert list(sim.walls[0]["velocity"]) == [0.05, 0.0]
        sim.run(until=0.1)
        assert np.array_equal(sim.positions, x)
        assert np.array_equal(sim.walls[0]["point"], floor)


def test_a_turning_segment_goes_on_from_its_pose():
    # examples/hopper2d.toml's left silo wall, a polyline, turned about its centre of rotation from mid-run
    with haet.Simulation.from_file(HOPPER, set=["insert[1].count=50"]) as sim:
        sim.run(until=0.01)
        before = sim.walls[0]
        assert before["kind"] == "mesh" and before["angular_velocity"] == 0.0
        sim.set_wall("silo_left", angular_velocity=0.5)
        after = sim.walls[0]
        assert np.array_equal(before["rotation"], after["rotation"])
        assert after["shift"] == pytest.approx(before["shift"], abs=1e-15)
        t0 = sim.time
        sim.run(until=0.02)
        a = 0.5 * (sim.time - t0)
        turned = sim.walls[0]
        assert turned["rotation"] == pytest.approx(np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]),
                                                   abs=1e-12)
        sim.set_wall("silo_left", angular_velocity=0.0, velocity=[0.0, 0.01])
        still = sim.walls[0]
        assert np.array_equal(still["rotation"], turned["rotation"])
        sim.run(until=0.03)
        assert np.array_equal(sim.walls[0]["rotation"], turned["rotation"])
        assert sim.walls[0]["shift"] == pytest.approx(still["shift"] + np.array([0.0, 0.01]) * 0.01, abs=1e-12)
        assert np.all(np.isfinite(sim.positions))


def test_bad_wall_changes_raise():
    with small(extra=["walls[1].name=floor"]) as sim:
        with pytest.raises(ValueError, match="no wall named"):
            sim.set_wall("roof", velocity=[0.0, 0.0])
        with pytest.raises(ValueError, match="no walls\\[7\\]"):
            sim.set_wall(7, velocity=[0.0, 0.0])
        with pytest.raises(ValueError, match="planes do not rotate"):
            sim.set_wall("floor", angular_velocity=1.0)
        with pytest.raises(ValueError, match="2 components"):
            sim.set_wall("floor", velocity=[0.0, 0.0, 1.0])
        with pytest.raises(ValueError, match="not finite"):
            sim.set_wall("floor", velocity=[np.nan, 0.0])
        with pytest.raises(ValueError, match="give velocity"):
            sim.set_wall("floor")
    with small(method="haet") as sim:
        with pytest.raises(ValueError, match="hybrid"):
            sim.set_wall(1, velocity=[0.0, 0.1])
    with haet.Simulation.from_file(HOPPER, set=["insert[1].count=50", "method=tdm"]) as sim:
        sim.set_wall("silo_left", velocity=[0.0, 0.0])  # a time-driven run moves any wall
    with haet.Simulation.from_file(HOPPER, set=["insert[1].count=50", "method=edm"]) as sim:
        # the event-driven engine predicts a polyline only while it stands still
        with pytest.raises(ValueError, match="moves only planes"):
            sim.set_wall("silo_left", velocity=[0.0, 0.1])
        sim.set_wall("floor", velocity=[0.0, 0.0])
