"""The simulation thread stops with a clear error when the physics blows up, instead of silently resetting."""

import mujoco

from tutorial.core.controller import SimpleController
from tutorial.core.simulator import Attachment, Simulator
from tutorial.core.world import ModelEntry, build_world

from conftest import MODEL


class Explosive(SimpleController):
    """Explicit damping far too stiff for the 1 ms step: the classic way to blow a simulation up."""

    def initialize(self, io):
        self.joint = io.body.joint("TURRET_P")
        return True

    def control(self):
        self.joint.u = -1e5 * (self.joint.dq - 0.1)
        return True


def test_an_unstable_simulation_ends_with_an_error_not_a_silent_reset():
    model = build_world([ModelEntry("Room", MODEL / "room.xml"), ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    sim = Simulator(model, data, [Attachment("Explosive", Explosive(), "Tank")], realtime_sync=False, duration=5.0)
    sim.start()
    assert sim.join(30)
    assert sim.error is not None and "became unstable" in sim.error
    assert sim.steps < 5000


class Counting(SimpleController):
    """Counts its control() calls (simulation thread), and signals when it has made ``until`` of them."""

    def __init__(self, until: int):
        import threading

        self.calls, self.until, self.reached = 0, until, threading.Event()

    def initialize(self, io):
        return True

    def control(self):
        self.calls += 1
        if self.calls == self.until:
            self.reached.set()
        return True


def test_a_paused_simulation_holds_its_time_and_calls_no_controller_until_resumed():
    import time

    model = build_world([ModelEntry("Room", MODEL / "room.xml"), ModelEntry("Tank", MODEL / "tank.xml")])
    counting = Counting(until=200)
    sim = Simulator(model, mujoco.MjData(model), [Attachment("C", counting, "Tank")], realtime_sync=True, duration=1.0)
    sim.start()
    try:
        assert counting.reached.wait(10)
        sim.pause()
        assert sim.paused
        deadline = time.monotonic() + 5
        while sim.snapshot().step != sim.steps and time.monotonic() < deadline:  # the held state, published
            time.sleep(0.01)  # polling the simulation thread's snapshot, within the deadline
        held_time, held_calls = sim.sim_time, counting.calls
        wall = time.monotonic()
        while time.monotonic() - wall < 0.3:  # 300 ms paused: nothing may move
            assert sim.sim_time == held_time and counting.calls == held_calls
            time.sleep(0.02)  # sampling the paused simulation, within its 300 ms
        sim.resume()
        assert sim.join(10)
    finally:
        sim.request_stop()
        sim.join(10)
    assert sim.error is None, sim.error
    assert sim.steps == 1000 and counting.calls == 1000  # the whole second simulated, nothing skipped
    assert sim.paused_for >= 0.3
    # the pause is not counted as lateness: counted, the factor would be about 1.0 / 1.3
    assert 0.9 <= sim.real_time_factor <= 1.05, sim.real_time_factor


def test_a_paused_simulation_stops_when_asked():
    model = build_world([ModelEntry("Room", MODEL / "room.xml"), ModelEntry("Tank", MODEL / "tank.xml")])
    counting = Counting(until=10)
    sim = Simulator(model, mujoco.MjData(model), [Attachment("C", counting, "Tank")], realtime_sync=True)
    sim.start()
    assert counting.reached.wait(10)
    sim.pause()
    sim.request_stop()
    assert sim.join(10) and sim.error is None


def test_the_realtime_slice_comes_from_the_environment_or_a_clear_error():
    """A class's server sets RTT_REALTIME_SLICE_MS (course/jupyterhub_config.py); elsewhere a step at a time."""
    import pytest

    from tutorial.core.simulator import REALTIME_MIN_SLEEP, realtime_slice

    assert realtime_slice(None) == realtime_slice(" ") == REALTIME_MIN_SLEEP == 0.0002
    assert realtime_slice("10") == 0.010 and realtime_slice("0.2") == 0.0002 and realtime_slice("50") == 0.050
    for bad in ("0", "0.1", "51", "-10", "nan", "inf", "ten"):
        with pytest.raises(ValueError, match=r"RTT_REALTIME_SLICE_MS must be milliseconds from 0.2 to 50"):
            realtime_slice(bad)


class Clocked(SimpleController):
    """Keeps each step's wall time (simulation thread)."""

    def initialize(self, io):
        import time

        self.wall, self.clock = [], time.perf_counter
        return True

    def control(self):
        self.wall.append(self.clock())
        return True


def _gaps_over_3_ms(slice_ms, monkeypatch) -> tuple[int, float]:
    """A 0.6 s real-time run: the steps followed by a sleep over 3 ms, and how far simulated time ended ahead, s."""
    if slice_ms is None:
        monkeypatch.delenv("RTT_REALTIME_SLICE_MS", raising=False)
    else:
        monkeypatch.setenv("RTT_REALTIME_SLICE_MS", slice_ms)
    model = build_world([ModelEntry("Room", MODEL / "room.xml"), ModelEntry("Tank", MODEL / "tank.xml")])
    clocked = Clocked()
    sim = Simulator(model, mujoco.MjData(model), [Attachment("C", clocked, "Tank")], realtime_sync=True, duration=0.6)
    sim.start()
    assert sim.join(30) and sim.error is None
    gaps = [b - a for a, b in zip(clocked.wall, clocked.wall[1:])]
    return sum(g > 0.003 for g in gaps), sim.steps * sim.time_step - sim.wall_time


def test_a_class_server_s_simulation_keeps_real_time_in_slices(monkeypatch):
    """With RTT_REALTIME_SLICE_MS=10 the thread runs ~10 steps, then sleeps ~10 ms: fewer wake-ups, same time."""
    sliced, ahead = _gaps_over_3_ms("10", monkeypatch)
    assert -0.05 <= ahead <= 0.0115, ahead  # at most a slice and a step ahead of wall time (late: a loaded machine)
    assert 30 <= sliced <= 62, sliced  # about 60 sleeps of about 10 ms (a late one can take two slices)
    stepwise, ahead = _gaps_over_3_ms(None, monkeypatch)
    assert -0.05 <= ahead <= 0.0015, ahead
    # a sleep before nearly every step, each well under 3 ms; a few longer gaps are the machine's (another
    # thread holding the interpreter lock, a collection)
    assert stepwise <= 12, stepwise
