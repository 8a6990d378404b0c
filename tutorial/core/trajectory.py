"""A simulation's trajectory: ``qpos`` at a fixed frame rate, for plots and 3D replays."""

from __future__ import annotations

import numpy as np

from tutorial.core.controller import SimpleController
from tutorial.core.period import PeriodAccumulator


class TrajectoryLog(SimpleController):
    """A controller that keeps ``(time, qpos)`` every ``1/fps`` s of simulated time.

    Args:
        fps: frames per simulated second.

    ``times`` (list of s) and ``frames`` (list of (nq,) arrays) are written by
    the simulation thread; read them after the simulation has ended.
    """

    def __init__(self, fps: float = 30.0):
        self.fps = fps
        self.times: list[float] = []
        self.frames: list[np.ndarray] = []

    def initialize(self, io) -> bool:
        self.io = io
        self.accumulator = PeriodAccumulator(io.time_step, self.fps)
        return True

    def control(self) -> bool:
        if self.accumulator.tick():
            self.times.append(self.io.current_time)
            self.frames.append(self.io.data.qpos.copy())
        return True

    def joint_series(self, body) -> dict[str, np.ndarray]:
        """Numbered joint positions of ``body`` over the recorded frames: name -> (n,) array."""
        q = np.array(self.frames)
        return {j.name: q[:, j.qpos_adr] for j in body.joint_infos}
