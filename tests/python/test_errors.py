"""Every error path raises a Python exception; none ends the interpreter."""
import os
import signal
import threading
import time

import numpy as np
import pytest

import haet
from conftest import EXAMPLE, box2d, small


def test_a_bad_scenario_raises_scenario_error_with_its_place(scene):
    text = EXAMPLE.read_text().replace("friction = 0.5", "friction = -1.0")
    path = scene(text)
    with pytest.raises(haet.ScenarioError) as e:
        haet.Simulation.from_file(path)
    assert isinstance(e.value, ValueError)
    assert e.value.file == str(path)
    assert e.value.line == text.splitlines().index("friction = -1.0") + 1
    assert e.value.key == "materials.sand.friction"
    assert e.value.message and e.value.message in str(e.value)


def test_a_missing_file_and_unknown_keys_raise_scenario_error(tmp_path):
    with pytest.raises(haet.ScenarioError):
        haet.Simulation.from_file(tmp_path / "nothing.toml")
    with pytest.raises(haet.ScenarioError) as e:
        haet.Simulation.from_string("frobnicate = 3\n" + EXAMPLE.read_text())
    assert e.value.key == "frobnicate"
    with pytest.raises(haet.ScenarioError):
        small(extra=["tdm.dt=-1"])
    with pytest.raises(TypeError, match="no TOML value"):
        haet.Simulation.from_dict({"name": object()})


def test_a_bad_dict_raises_scenario_error_naming_the_dict():
    import tomllib
    d = tomllib.loads(EXAMPLE.read_text())
    d["materials"]["sand"]["friction"] = -1.0
    with pytest.raises(haet.ScenarioError) as e:
        haet.Simulation.from_dict(d)
    assert e.value.file == "<dict>"
    assert e.value.line == 0  # the dict has no lines
    assert e.value.key == "materials.sand.friction"
    assert str(e.value).startswith("<dict>: materials.sand.friction: ")
    del d["materials"]["sand"]["friction"]
    d["domain"]["gravity"] = "down"
    with pytest.raises(haet.ScenarioError) as e:
        haet.Simulation.from_dict(d)
    assert e.value.file == "<dict>" and e.value.key == "domain.gravity"


def test_a_blow_up_raises_simulation_error():
    # a time step far above the contact duration: the overlaps grow past the limit
    with small(velocity=(0.0, -2.0), extra=["tdm.dt=2e-4"]) as sim:
        with pytest.raises(haet.SimulationError):
            sim.run(until=0.05)
        assert sim.status.startswith("failed")


def test_an_output_that_cannot_be_written_raises_os_error(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(OSError):
        small(out=blocker / "run")


def test_a_bad_checkpoint_raises_checkpoint_error(tmp_path):
    bad = tmp_path / "bad.haet"
    bad.write_bytes(b"not a checkpoint")
    with pytest.raises(haet.CheckpointError):
        haet.Simulation.load(bad, EXAMPLE)
    with pytest.raises(haet.CheckpointError):
        haet.Simulation.load(tmp_path / "missing.haet", EXAMPLE)


def test_bad_arguments_raise():
    with small() as sim:
        with pytest.raises(ValueError):
            sim.run(until=float("nan"))
        with pytest.raises(ValueError):
            sim.gravity = [1.0, 2.0, 3.0]
        with pytest.raises(ValueError):
            sim.add_particles(np.zeros((2, 3)), [0.001, 0.001])
        with pytest.raises(ValueError):
            sim.add_particles([[0.02, 0.02]], [-1.0])
        sim.finish()
        with pytest.raises(ValueError, match="finished"):
            sim.run(until=1.0)


def test_the_gil_is_released_while_the_run_goes_on():
    count = [0]
    going = threading.Event()
    going.set()

    def spin():
        while going.is_set():
            count[0] += 1

    t = threading.Thread(target=spin)
    t.start()
    try:
        with small(threads=1) as sim:
            time.sleep(0.05)
            before = count[0]
            sim.run(until=0.05)
            during = count[0] - before
    finally:
        going.clear()
        t.join()
    assert during > 10000


def test_a_run_in_another_thread_leaves_ctrl_c_to_python():
    with small() as sim:
        t = threading.Thread(target=lambda: sim.run(until=0.01))
        t.start()
        t.join()
        assert sim.time == pytest.approx(0.01)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_ctrl_c_stops_the_run_cleanly_and_raises_keyboard_interrupt():
    with small(threads=1) as sim:
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            sim.run(until=100.0)
        timer.join()
        assert 0 < sim.time < 100.0
        assert sim.time == pytest.approx(sim.steps * sim.dt)  # at the end of a step
        assert sim.status == "interrupted"
        # Python's own handler is back, and the run may go on
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        t = sim.time
        sim.step(10)
        assert sim.time > t and sim.status == "completed"
    with pytest.raises(KeyboardInterrupt):  # Ctrl-C between runs is Python's
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1)
