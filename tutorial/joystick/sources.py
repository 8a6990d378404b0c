"""Where stick values come from: a scripted demo, a gamepad, or the keyboard.

Every source has ``read(now) -> (axes, buttons)`` in the convention of
:mod:`tutorial.interfaces.joy` (8 axes, stick up/left = +1; 8 buttons), or None when
the user asked to quit.  One thread calls ``read``: the one running ``JoyPublisher.run`` (``rtt-joy``'s main thread).
"""

from __future__ import annotations

import os
import select
import sys
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


# Choreonoid's virtual joystick keys: key -> (axis, value in ROS convention)
KEYMAP = {
    "e": (joy.LEFT_STICK_V, 1.0),
    "d": (joy.LEFT_STICK_V, -1.0),
    "s": (joy.LEFT_STICK_H, 1.0),
    "f": (joy.LEFT_STICK_H, -1.0),
    "i": (joy.RIGHT_STICK_V, 1.0),
    "k": (joy.RIGHT_STICK_V, -1.0),
    "j": (joy.RIGHT_STICK_H, 1.0),
    "l": (joy.RIGHT_STICK_H, -1.0),
}
KEY_HOLD = 0.6  # s an axis stays deflected after its key's last repeat (covers the terminal's repeat delay)
KEYBOARD_HELP = (
    "keys: E/D left stick up/down, S/F left/right; I/K right stick up/down, J/L left/right; space: release all; q: quit"
)


class KeyboardInput:
    """The keyboard of the terminal this process runs in (Choreonoid's virtual joystick keys).

    A terminal reports key presses, not releases: a key deflects its axis
    until :data:`KEY_HOLD` s after its last (auto-repeated) press.
    Use as a context manager: it puts the terminal in cbreak mode and restores it.

    Raises:
        RuntimeError: standard input is not a terminal.
    """

    def __init__(self, stream=None):
        self.stream = stream or sys.stdin
        if not self.stream.isatty():
            raise RuntimeError("standard input is not a terminal")
        self.held: dict[int, tuple[float, float]] = {}  # axis -> (value, until)

    def __enter__(self):
        import termios
        import tty

        self._fd = self.stream.fileno()
        self._saved = termios.tcgetattr(self._fd)
        tty.setcbreak(self._fd)
        return self

    def __exit__(self, *exc):
        import termios

        termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)

    def read(self, now: float):
        while select.select([self._fd], [], [], 0)[0]:
            key = os.read(self._fd, 1).decode(errors="ignore").lower()
            if key == "q":
                return None
            if key == " ":
                self.held.clear()
            elif key in KEYMAP:
                index, value = KEYMAP[key]
                self.held[index] = (value, now + KEY_HOLD)
        axes = list(ZERO_AXES)
        for index, (value, until) in list(self.held.items()):
            if now < until:
                axes[index] = value
            else:
                del self.held[index]
        return tuple(axes), ZERO_BUTTONS


class GamepadInput:
    """A gamepad through SDL's game-controller API (pygame), which maps any
    known pad to the standard layout.

    Raises:
        RuntimeError: pygame is missing or no game controller is connected.
    """

    def __init__(self):
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        try:
            import pygame
            from pygame._sdl2 import controller
        except ImportError as exc:
            raise RuntimeError(f"pygame is not available: {exc}") from None
        pygame.init()
        controller.init()
        pads = [i for i in range(controller.get_count()) if controller.is_controller(i)]
        if not pads:
            raise RuntimeError("no gamepad found")
        self.pygame = pygame
        self.pad = controller.Controller(pads[0])
        self.name = self.pad.name

    def read(self, now: float):
        pg = self.pygame
        pg.event.pump()
        a = self.pad.get_axis
        b = self.pad.get_button

        def stick(code):  # SDL: -32768..32767, right/down positive -> ROS: left/up positive
            return max(-1.0, min(1.0, -a(code) / 32767.0))

        def trigger(code):  # SDL: 0..32767 -> ROS joy: 1.0 released, -1.0 fully pressed
            return 1.0 - 2.0 * a(code) / 32767.0

        axes = (
            stick(pg.CONTROLLER_AXIS_LEFTX),
            stick(pg.CONTROLLER_AXIS_LEFTY),
            stick(pg.CONTROLLER_AXIS_RIGHTX),
            stick(pg.CONTROLLER_AXIS_RIGHTY),
            float(b(pg.CONTROLLER_BUTTON_DPAD_LEFT) - b(pg.CONTROLLER_BUTTON_DPAD_RIGHT)),
            float(b(pg.CONTROLLER_BUTTON_DPAD_UP) - b(pg.CONTROLLER_BUTTON_DPAD_DOWN)),
            trigger(pg.CONTROLLER_AXIS_TRIGGERLEFT),
            trigger(pg.CONTROLLER_AXIS_TRIGGERRIGHT),
        )
        buttons = tuple(
            int(b(c))
            for c in (
                pg.CONTROLLER_BUTTON_A,
                pg.CONTROLLER_BUTTON_B,
                pg.CONTROLLER_BUTTON_X,
                pg.CONTROLLER_BUTTON_Y,
                pg.CONTROLLER_BUTTON_LEFTSHOULDER,
                pg.CONTROLLER_BUTTON_RIGHTSHOULDER,
                pg.CONTROLLER_BUTTON_BACK,
                pg.CONTROLLER_BUTTON_START,
            )
        )
        return axes, buttons
