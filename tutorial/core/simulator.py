"""The simulation thread: it alone owns the simulation's ``MjData``.

:class:`Simulator` runs the controller lifecycle (``initialize``, ``start``,
``control`` every step, ``stop``) and ``mujoco.mj_step`` on one thread.  Other
threads never read that ``MjData``: the main thread asks for a
:class:`Snapshot` (a copy of ``qpos`` taken under a lock at most once per
frame) and draws from its own ``MjData``.  This is the "one owner, one sync
point" rule of MuJoCo's passive viewer.
"""

from __future__ import annotations

import math
import os
import threading
import time
import traceback
from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial.core.body import Body
from tutorial.core.controller import ControllerIO, SimpleController

# In real-time mode the simulation thread sleeps whenever it is at least this far
# ahead of wall-clock time: at a 1 ms step, before nearly every step, so a 1 kHz
# publisher sends one message a millisecond.  Shorter sleeps are lost in the
# operating system's wake-up time.  Sleeping only when 2 ms ahead (two steps at
# a time) saved CPU, but a subscriber then got pairs of messages: keeping the
# newest, it dropped half of them and showed the other half later (the 1 kHz
# latency targets of the book's Benchmarks page).
REALTIME_MIN_SLEEP = 0.0002  # s
# A class's server trades that for CPU: each wake-up costs the thread about 0.1 ms here (the sleep's
# timer, then a first step on cold caches: 0.13 ms against 0.012 ms for the tank's mj_step).  Ahead by
# RTT_REALTIME_SLICE_MS before it sleeps, the simulation wakes that much less often; a subscriber of a
# 50 Hz topic sees nothing of it (course/jupyterhub_config.py, and benchmarks/RESULTS.md's class).
REALTIME_SLICE_VARIABLE = "RTT_REALTIME_SLICE_MS"


def realtime_slice(text: str | None) -> float:
    """How far ahead of wall time the simulation runs before it sleeps, s, from ``RTT_REALTIME_SLICE_MS``.

    None or blank: :data:`REALTIME_MIN_SLEEP` (0.2 ms).

    Raises:
        ValueError: not a number of milliseconds from 0.2 to 50.
    """
    if text is None or not text.strip():
        return REALTIME_MIN_SLEEP
    try:
        ms = float(text)
    except ValueError:
        ms = math.nan
    if not 0.2 <= ms <= 50.0:  # a NaN fails too
        raise ValueError(f"{REALTIME_SLICE_VARIABLE} must be milliseconds from 0.2 to 50, got {text!r}")
    return ms / 1000.0


@dataclass
class Snapshot:
    """The simulation state at one step: ``time`` (s), ``qpos`` (nq,) copy, ``step`` count."""

    time: float
    qpos: np.ndarray
    step: int


@dataclass
class Attachment:
    """A controller and the name of the body it controls."""

    name: str
    controller: SimpleController
    body_name: str


class Simulator:
    """Steps a MuJoCo world on its own thread, calling the controllers each step.

    Args:
        model: the compiled world.
        data: the simulation's ``MjData``; from :meth:`start` on, only the
            simulation thread touches it.
        attachments: the controllers to run, in order.
        node: the ROS 2 node given to controllers through their IO.
        realtime_sync: keep simulation time in step with wall-clock time;
            False runs as fast as possible.
        duration: stop after this much simulated time, s (None: until :meth:`request_stop`).
        record_timing: keep every step's lateness (wall time behind simulated
            time, s, 0 when on time) in :attr:`lateness`, for benchmarks.

    Raises:
        ValueError: ``RTT_REALTIME_SLICE_MS`` is set and wrong (:func:`realtime_slice`).

    ``start``, ``pause``, ``resume``, ``request_stop``, ``join`` and ``snapshot`` may be called from
    any thread; everything else runs on the simulation thread.
    """

    def __init__(self, model, data, attachments, node=None, realtime_sync=True, duration=None, record_timing=False):
        self.model = model
        self.data = data
        self.attachments = list(attachments)
        self.node = node
        self.realtime_sync = realtime_sync
        self.realtime_slice = realtime_slice(os.environ.get(REALTIME_SLICE_VARIABLE))  # s
        self.duration = duration
        self.time_step = float(model.opt.timestep)
        self.steps = 0
        self.wall_time = 0.0
        self.cpu_time = 0.0  # s of CPU the simulation thread used while stepping
        self.error: str | None = None
        self.dropped: list[str] = []  # controllers whose control() returned False
        self.lateness: list[float] | None = [] if record_timing else None
        self._stop = threading.Event()
        self._running = threading.Event()  # cleared while paused: the simulation thread waits on it
        self._running.set()
        self._held = threading.Event()  # set while the simulation thread waits, paused
        self.paused_for = 0.0  # s of wall time spent paused (left out of wall_time)
        self.finished = threading.Event()
        self._snapshot_lock = threading.Lock()
        self._snapshot = Snapshot(float(data.time), data.qpos.copy(), 0)
        self._snapshot_wanted = threading.Event()
        self._thread = threading.Thread(target=self._run, name="simulation", daemon=True)

    # ---- any thread ---------------------------------------------------------
    def start(self) -> Simulator:
        """Start the simulation thread (any thread, once)."""
        self._thread.start()
        return self

    def request_stop(self) -> None:
        """Ask the simulation thread to end after its current step, paused or not (any thread)."""
        self._stop.set()
        self._running.set()

    def pause(self) -> None:
        """Hold the simulation before its next step (any thread).

        Simulated time stands still: no step, no ``control()``, so a controller's
        periods (in simulated time) lose nothing and nothing is published.  The
        simulation thread waits without using the CPU until :meth:`resume`.
        """
        self._running.clear()

    def resume(self) -> None:
        """Go on from where :meth:`pause` held it, in real time from now (any thread)."""
        self._running.set()

    def wait_paused(self, timeout: float) -> bool:
        """Wait until a :meth:`pause` has held the simulation (its snapshot then holds the paused state);
        True when it has (any thread)."""
        return self._held.wait(timeout)

    @property
    def paused(self) -> bool:
        return not self._running.is_set()

    def join(self, timeout: float | None = None) -> bool:
        """Wait for the simulation thread; True when it has ended."""
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def snapshot(self) -> Snapshot:
        """The newest state copied by the simulation thread (any thread).

        Also asks the simulation thread for a fresh copy at its next step, so
        a caller polling once per frame always gets a state at most one frame old.
        """
        self._snapshot_wanted.set()
        with self._snapshot_lock:
            return self._snapshot

    @property
    def sim_time(self) -> float:
        with self._snapshot_lock:
            return self._snapshot.time

    # ---- simulation thread ----------------------------------------------------
    def _run(self) -> None:
        started = []
        try:
            mujoco.mj_forward(self.model, self.data)
            for a in self.attachments:
                io = ControllerIO(
                    body=Body(self.model, self.data, a.body_name),
                    time_step=self.time_step,
                    node=self.node,
                    data=self.data,
                )
                if not a.controller.initialize(io):
                    raise RuntimeError(f"controller {a.name} refused to initialize")
            for a in self.attachments:
                if not a.controller.start():
                    raise RuntimeError(f"controller {a.name} refused to start")
                started.append(a)
            self._loop(started)
        except Exception:  # noqa: BLE001 - reported by the owner through .error
            self.error = traceback.format_exc()
        finally:
            for a in started:
                try:
                    a.controller.stop()
                except Exception:  # noqa: BLE001
                    self.error = (self.error or "") + traceback.format_exc()
            self._publish_snapshot()
            self.finished.set()

    def _loop(self, active: list[Attachment]) -> None:
        m, d, dt = self.model, self.data, self.time_step
        active = list(active)
        controls = [(a, a.controller.control) for a in active]  # bound once: this loop runs every 1 ms
        stop, snapshot_wanted, step = self._stop.is_set, self._snapshot_wanted.is_set, mujoco.mj_step
        running, slice_ = self._running.is_set, self.realtime_slice
        t0_sim = t = float(d.time)
        wall0 = time.perf_counter()
        cpu0 = time.thread_time()
        end = float("inf") if self.duration is None else t0_sim + self.duration - 0.5 * dt
        while t < end and not stop():
            if not running():  # paused: the newest state for the views, then wait (request_stop ends it too)
                self._publish_snapshot()
                held = time.perf_counter()
                self._held.set()
                self._running.wait()
                self._held.clear()
                wall0 += time.perf_counter() - held  # real time goes on from here, with no catching up
                self.paused_for += time.perf_counter() - held
                continue
            for a, control in controls:
                if not control():
                    controls = [(b, c) for b, c in controls if b is not a]
                    self.dropped.append(a.name)
            step(m, d)
            t_next = d.time
            if t_next < t:
                # MuJoCo resets MjData (time back to 0) when accelerations blow up;
                # carrying on would hide it and a --duration run would never end.
                raise RuntimeError(
                    f"the simulation became unstable near t = {t:.3f} s "
                    "(NaN or huge acceleration): check controller gains, armature and the time step"
                )
            t = t_next
            self.steps += 1
            if snapshot_wanted():
                self._snapshot_wanted.clear()
                self._publish_snapshot()
            if self.realtime_sync:
                ahead = (t - t0_sim) - (time.perf_counter() - wall0)
                if self.lateness is not None:
                    self.lateness.append(max(0.0, -ahead))
                if ahead > slice_:
                    time.sleep(ahead)
        self.wall_time = time.perf_counter() - wall0
        self.cpu_time = time.thread_time() - cpu0

    def _publish_snapshot(self) -> None:
        snap = Snapshot(float(self.data.time), self.data.qpos.copy(), self.steps)
        with self._snapshot_lock:
            self._snapshot = snap

    @property
    def real_time_factor(self) -> float:
        """Simulated time over wall time of the finished run (0 when none ran)."""
        return (self.steps * self.time_step) / self.wall_time if self.wall_time > 0 else 0.0
