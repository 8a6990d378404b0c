"""Where stick values come from: a gamepad, or the keyboard (the scripted demo: :mod:`tutorial.joystick.demo`).

Every source has ``read(now) -> (axes, buttons)`` in the convention of
:mod:`tutorial.interfaces.joy` (8 axes, stick up/left = +1; 8 buttons), or None when
the user asked to quit.  One thread calls ``read``: the one running ``JoyPublisher.run`` (``rtt-joy``'s main thread).
"""

from __future__ import annotations

import os
import select
import sys

from tutorial.interfaces import joy
from tutorial.joystick.demo import ZERO_AXES, ZERO_BUTTONS

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
