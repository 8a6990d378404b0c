"""The scripted demo drives: what ``rtt-joy --demo`` plays, and the notebooks' scripted runs.

:class:`DemoInput` has ``read(now) -> (axes, buttons)`` in the convention of
:mod:`tutorial.interfaces.joy` (8 axes, stick up/left = +1; 8 buttons), as
the gamepad and keyboard sources of :mod:`tutorial.tools.joystick.sources` do.
One thread calls ``read``.
"""

from __future__ import annotations

from dataclasses import dataclass

from tutorial.interfaces import joy

ZERO_AXES = (0.0,) * joy.NUM_AXES
ZERO_BUTTONS = (0,) * joy.NUM_BUTTONS

# The demo: (seconds, (left H, left V, right H, right V)); looped.
# It drives forward while turning the turret, spins on the spot while raising
# the barrel, and comes back, so a headless run shows every motion.  The turret
# turns 2 rad right and 1.25 rad back per cycle: it ends each cycle turned.
DEMO_SCRIPT: tuple[tuple[float, tuple[float, float, float, float]], ...] = (
    (0.5, (0.0, 0.0, 0.0, 0.0)),  # still
    (2.5, (0.0, 0.4, -0.4, 0.0)),  # forward at 0.8 m/s, turret turning right
    (2.0, (0.8, 0.0, 0.0, -0.5)),  # turn left on the spot, barrel rising
    (2.5, (0.0, 0.4, 0.25, 0.0)),  # forward, turret turning back left, part of the way
    (2.0, (-0.8, 0.0, 0.0, 0.5)),  # turn right on the spot, barrel lowering
    (1.0, (0.0, 0.0, 0.0, 0.0)),  # still
)

# Step 5's demo: ram the wall ahead at full speed, back off, swing the barrel and turn on
# the spot (and back), again.  Started from the room's centre facing +x, every cycle hits
# the east wall at about 2 m/s: a horizontal acceleration of 35-56 m/s^2 in the IMU's 50 ms
# mean, well over the viewer's 20 m/s^2 collision threshold.
WALL_SCRIPT: tuple[tuple[float, tuple[float, float, float, float]], ...] = (
    (0.5, (0.0, 0.0, 0.0, 0.0)),  # still
    (2.0, (0.0, 1.0, -0.3, 0.0)),  # full speed ahead, into the wall; turret turning right
    (1.6, (0.0, -0.5, 0.3, 0.0)),  # back off at 1 m/s, turret turning back
    (0.8, (0.6, 0.0, 0.0, -0.4)),  # turn left on the spot, barrel rising
    (0.8, (-0.6, 0.0, 0.0, 0.4)),  # and back, barrel lowering
    (0.5, (0.0, 0.0, 0.0, 0.0)),  # still
)
SCRIPTS = {"drive": DEMO_SCRIPT, "wall": WALL_SCRIPT}


@dataclass
class DemoInput:
    """A scripted drive, :data:`DEMO_SCRIPT` unless told otherwise, from ``start`` (s), looped.

    Args:
        start: time the script starts; None waits (sticks at rest) until :meth:`begin`.
        cycles: how many times to play it (None: forever); afterwards the sticks rest at 0.
        script: ``(seconds, (left H, left V, right H, right V))`` steps, e.g. a value of :data:`SCRIPTS`.
    """

    start: float | None = None
    cycles: int | None = None
    script: tuple = DEMO_SCRIPT

    @property
    def waiting(self) -> bool:
        return self.start is None

    def begin(self, now: float) -> None:
        """Start the script at ``now`` (the joy node calls it when /joy gets a subscriber)."""
        self.start = now

    @property
    def period(self) -> float:
        return sum(d for d, _ in self.script)

    def finished(self, now: float) -> bool:
        return self.start is not None and self.cycles is not None and now - self.start >= self.cycles * self.period

    def read(self, now: float):
        if self.start is None or self.finished(now):
            return ZERO_AXES, ZERO_BUTTONS
        t = (now - self.start) % self.period
        for duration, (lh, lv, rh, rv) in self.script:
            if t < duration:
                return (lh, lv, rh, rv, 0.0, 0.0, 0.0, 0.0), ZERO_BUTTONS
            t -= duration
        return ZERO_AXES, ZERO_BUTTONS
