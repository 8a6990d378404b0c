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
