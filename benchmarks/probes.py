"""Measuring points the benchmarks attach to the tutorial's own programs.

Both probes write what they saw as JSON when their program ends: the step
clock to the file named by the ``RTT_PROBE_FILE`` environment variable, each
viewer probe to that name with its body's name before the suffix
(``view.json`` -> ``view.Tank1.json``), so one viewer can mirror several
bodies.  Times are ``time.monotonic_ns()``, one clock for every process on
the machine, so times taken in two processes can be subtracted.
"""

from __future__ import annotations

import json
import os
import time

from tutorial.controllers.joint_state_subscriber import RttJointStateMonitor
from tutorial.core.controller import SimpleController


def _write(record: dict, body_name: str | None = None) -> None:
    path = os.environ.get("RTT_PROBE_FILE")
    if path:
        if body_name is not None:
            stem, suffix = os.path.splitext(path)  # view.json -> view.Tank1.json
            path = f"{stem}.{body_name}{suffix}"
        with open(path, "w") as f:
            json.dump(record, f)


class StepClock(SimpleController):
    """Simulation side: the wall-clock time at which each step started, by its simulation time.

    Attach it before the publishers (one is enough for a world of several
    bodies): it runs first in each step, so its time is the moment that
    step's states (the publishers' stamp) were taken.
    """

    def initialize(self, io) -> bool:
        self.io = io
        self.sim_ns: list[int] = []
        self.wall_ns: list[int] = []
        return True

    def control(self) -> bool:
        self.sim_ns.append(round(self.io.current_time * 1e9))
        self.wall_ns.append(time.monotonic_ns())
        return True

    def stop(self) -> None:
        _write({"sim_ns": self.sim_ns, "wall_ns": self.wall_ns})


class ProbedJointStateSubscriber(RttJointStateMonitor):
    """Viewer side: when each state was applied on the main thread, and what each frame showed."""

    def configure(self, config) -> bool:
        self.applied_log: list[tuple[int, int, int]] = []  # (stamp ns, callback at ns, applied at ns)
        self.frame_log: list[tuple[int, int, float]] = []  # (drawn at ns, stamp ns shown, scene update s)
        self.latest_stamp = -1
        return super().configure(config)

    def update_joint_state(self, msg, arrival):
        report = super().update_joint_state(msg, arrival)
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        self.applied_log.append((stamp, int(arrival * 1e9), time.monotonic_ns()))
        self.latest_stamp = stamp
        return report

    def frame_drawn(self, seconds: float) -> None:
        """Called by the benchmark's viewer after each scene update (main thread)."""
        self.frame_log.append((time.monotonic_ns(), self.latest_stamp, seconds))

    def unconfigure(self) -> None:
        super().unconfigure()
        loop = self.config.call_later.__self__  # the MainLoop: its counters show whether a backlog grew
        _write(
            {
                "applied": self.applied_log,
                "frames": self.frame_log,
                "posted": loop.posted,
                "coalesced": loop.coalesced,
                "executed": loop.executed,
                "max_pending": loop.max_pending,
                "yields": loop.yields,
                "yield_timeouts": loop.yield_timeouts,
            },
            self.config.body_name,
        )
