"""Moves every motorised numbered joint of any body along a slow sine, by torque PD.

A controller for models that have no joystick mapping (the crane, the
24-joint arm): something to publish and to watch.  Each joint follows
``mid + amp * sin(1.5 t + k)`` over the middle third of its range (or
+-0.33 rad when unlimited), joint ``k`` a phase step behind joint ``k - 1``.
All joints are computed at once with NumPy: one vector operation per step
instead of a Python loop over joints.
"""

import numpy as np

from tutorial.controller import SimpleController

P_GAIN = 300.0  # N*m/rad (N/m for slides)
D_GAIN = 30.0  # N*m*s/rad


class SwingController(SimpleController):
    """Sine references for every joint with a motor, followed by torque PD."""

    def initialize(self, io):
        self.io = io
        infos = [j.info for j in io.body.joints if j.info.motor >= 0]
        lower = np.array([i.lower if i.limited else -1.0 for i in infos])
        upper = np.array([i.upper if i.limited else 1.0 for i in infos])
        self.mid, self.amp = (lower + upper) / 2, (upper - lower) / 3
        self.phase = np.arange(len(infos), dtype=float)
        self.qadr = np.array([i.qpos_adr for i in infos], dtype=int)
        self.vadr = np.array([i.dof_adr for i in infos], dtype=int)
        self.motor = np.array([i.motor for i in infos], dtype=int)
        self.gear = np.array([i.gear for i in infos])
        self.qpos, self.qvel, self.ctrl = io.data.qpos, io.data.qvel, io.data.ctrl
        return True

    def control(self):
        target = self.mid + self.amp * np.sin(1.5 * self.io.current_time + self.phase)
        u = P_GAIN * (target - self.qpos[self.qadr]) - D_GAIN * self.qvel[self.vadr]
        self.ctrl[self.motor] = u / self.gear
        return True
