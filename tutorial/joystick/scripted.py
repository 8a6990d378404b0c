"""Deterministic joystick input for notebooks, tests and snapshots.

:class:`ScriptedJoy` is a controller that plays :data:`tutorial.joystick.demo.DEMO_SCRIPT`
by *simulated* time and hands the stick state to the tank controller's
``on_joy``, the same callback the ``/joy`` subscription calls: when it
changes, and again every 50 ms of simulated time, as ``rtt-joy`` repeats
at 20 Hz (so the controller's Joy timeout sees a live operator).  No network is
involved, so the same script gives the same trajectory on every run: that is
what lets a notebook show exact numbers.  (Over ROS, messages arrive at
slightly different steps each run.)
"""

from __future__ import annotations

from types import SimpleNamespace

from tutorial.core.controller import SimpleController
from tutorial.joystick.demo import DemoInput

AUTOREPEAT = 0.05  # s of simulated time between repeats of an unchanged state (20 Hz)


class ScriptedJoy(SimpleController):
    """Feeds a target controller's ``on_joy`` from the demo script, by simulated time.

    Args:
        target: the controller whose ``on_joy(msg)`` receives the input, or a
            function returning it (called in ``initialize``, when every
            controller of the project has been configured).
        cycles: how many times to play the script (None: forever).
        script: the script, :data:`tutorial.joystick.demo.DEMO_SCRIPT` unless given
            (e.g. ``SCRIPTS["wall"]``, Step 5's).

    Attach it before the target, so both see the same step.  Runs on the simulation thread.
    """

    def __init__(self, target, cycles: int | None = None, script=None):
        self.target = target
        self.source = DemoInput(start=0.0, cycles=cycles, **({"script": script} if script else {}))
        self.last = None
        self.last_sent = float("-inf")
        self.sent = 0

    def initialize(self, io) -> bool:
        self.io = io
        if callable(self.target) and not hasattr(self.target, "on_joy"):
            self.target = self.target()
        return True

    def control(self) -> bool:
        now = self.io.current_time
        axes, buttons = self.source.read(now)
        if (axes, buttons) != self.last or now - self.last_sent >= AUTOREPEAT - 1e-9:
            self.last, self.last_sent = (axes, buttons), now
            self.target.on_joy(SimpleNamespace(axes=list(axes), buttons=list(buttons)))
            self.sent += 1
        return True
