"""The particles as numpy views of the store: they see the current state, and a write through them changes the next
step as the same change in the scenario file does."""
import numpy as np
import pytest

import haet
from conftest import EXAMPLE, box2d, small


def test_views_see_the_store_without_copying():
    with small() as sim:
        x = sim.positions
        assert x.shape == (400, 2) and x.dtype == np.float64
        assert not x.flags.owndata and x.base is not None
        assert np.shares_memory(x, sim.positions)  # the same store, not a copy
        assert sim.angular_velocities.shape == (400,)
        assert sim.radii.shape == (400,) and np.all(sim.radii == 0.001)
        assert sim.masses == pytest.approx(2.0 * np.pi * 1e-6)
        assert sim.materials.dtype == np.uint16 and sim.flags.dtype == np.uint8
        assert sorted(sim.ids) == list(range(400))
        assert sim.forces.shape == (400, 2)
        assert np.all(sim.modes == 1)
        before = sim.positions.copy()
        sim.step(100)
        after = sim.positions
        assert not np.array_equal(before, after)
        assert np.all(after[:, 1] < before[:, 1].max())  # falling
        # the view of the current state: velocities consistent with the series' kinetic energy
        v = sim.velocities
        ke = 0.5 * np.sum(sim.masses * np.sum(v * v, axis=1))
        sim.finish()
        assert sim.series["kinetic_energy"][-1] == pytest.approx(ke, rel=1e-12)


def test_a_pure_event_driven_run_has_no_forces():
    with small(method="edm") as sim:
        sim.run(until=0.01)
        assert sim.forces is None
        assert sim.positions.shape == (400, 2)


# (hard disks in rows driven sideways into a wall collapse inelastically: an upward throw for them)
@pytest.mark.parametrize("method,v", [("tdm", (0.25, -0.5)), ("edm", (0.0, 0.5))])
def test_a_velocity_written_through_a_view_is_that_of_the_file(method, v):
    with small(method=method) as a, small(method=method, velocity=v) as b:
        a.velocities[:] += np.array(v)
        assert np.array_equal(a.velocities, b.velocities)
        a.run(until=0.02)
        b.run(until=0.02)
        assert np.array_equal(a.positions, b.positions)
        assert np.array_equal(a.velocities, b.velocities)
        assert a.series["kinetic_energy"].tobytes() == b.series["kinetic_energy"].tobytes()


# (the hard disks, pushed into a corner by a tilted gravity, collapse inelastically: a weaker gravity for them)
@pytest.mark.parametrize("method,g", [("tdm", (3.0, -9.81)), ("edm", (0.0, -4.0))])
def test_gravity_set_between_runs_is_that_of_the_file(method, g):
    with small(method=method) as a, small(method=method, gravity=g) as b:
        a.gravity = g
        assert tuple(a.gravity) == g
        a.run(until=0.02)
        b.run(until=0.02)
        assert np.array_equal(a.positions, b.positions)


def test_reading_a_view_changes_nothing():
    with small() as a, small() as b:
        for _ in range(20):
            a.step(5)
            a.positions.sum(), a.velocities.sum(), a.masses.sum()
        b.step(100)
        assert np.array_equal(a.positions, b.positions)
        a.finish(), b.finish()
        assert np.array_equal(a.series["rebuilds"], b.series["rebuilds"])


def test_a_mass_written_changes_the_inverse_mass():
    with small(velocity=(0.0, -0.1)) as sim:
        sim.run(until=0.04)
        ref = sim.velocities.copy()
    # every other disk made heavier: with a contact duration fixed (contact.duration) only mass ratios matter
    with small(velocity=(0.0, -0.1)) as sim:
        sim.masses[::2] *= 4.0
        sim.run(until=0.04)
        assert not np.array_equal(sim.velocities, ref)
        assert np.all(np.isfinite(sim.velocities))


def test_a_frozen_flag_written_holds_the_particle():
    with small() as sim:
        sim.flags[0] = haet.FROZEN
        x0 = sim.positions[0].copy()
        sim.step(100)
        i = list(sim.ids).index(0)
        assert np.array_equal(sim.positions[i], x0)


@pytest.mark.parametrize("method", ["tdm", "edm"])
def test_add_and_remove_particles(method):
    with small(method=method) as sim:
        sim.step(10) if method == "tdm" else sim.run(until=0.001)
        sim.add_particles([[0.025, 0.07], [0.03, 0.07]], [0.001, 0.001], velocities=[[0, -0.1], [0, -0.2]],
                          material="sand")
        assert sim.n_particles == 402
        assert set(sim.ids) >= {400, 401}
        sim.remove([0, 5, 400])
        assert sim.n_particles == 399
        assert not {0, 5, 400} & set(sim.ids)
        sim.run(until=0.01)
        assert np.all(np.isfinite(sim.positions))
        with pytest.raises(ValueError, match="no particle with id 0"):
            sim.remove([0])
        with pytest.raises(ValueError, match="no material"):
            sim.add_particles([[0.02, 0.07]], [0.001], material="glass")


def test_the_hybrid_views_are_read_only():
    with small(method="haet") as sim:
        sim.step(5)
        assert sim.modes.shape == (400,)
        with pytest.raises(ValueError):
            sim.positions[0, 0] = 1.0
        with pytest.raises(ValueError, match="hybrid"):
            sim.gravity = [0.0, -1.0]


# examples/box2d_settle.toml's box fed from above by an inlet
INLET = """
[[inlet]]
name = "feed"
material = "sand"
region = { lo = [0.02, 0.12], hi = [0.08, 0.145] }
rate = 4000
interval = 0.002
radius = 0.001
"""


@pytest.mark.parametrize("method", ["tdm", "edm"])
def test_added_particles_take_their_ids_from_the_inlets_counter(method):
    text = EXAMPLE.read_text() + INLET
    with haet.Simulation.from_string(text, path=EXAMPLE, set=box2d(method=method, count=100)) as sim:
        sim.add_particles([[0.05, 0.08]], [0.001])
        assert sim.n_particles == 101 and 100 in set(sim.ids)
        sim.run(until=0.01)
        inserted = sim.n_particles - 101
        assert inserted > 0
        assert len(set(sim.ids)) == sim.n_particles  # none shares an id
        # ids are never reused: not even the largest one's, removed
        top = int(max(sim.ids))
        sim.remove([top])
        sim.add_particles([[0.05, 0.09]], [0.001])
        assert int(max(sim.ids)) == top + 1
        sim.run(until=0.02)
        assert len(set(sim.ids)) == sim.n_particles
