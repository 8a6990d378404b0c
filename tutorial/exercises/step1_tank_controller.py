"""Checks for the exercises of notebook 01 (Step 1, the tank controller).

Exercise 1.1, steer with the D-pad: ``dpad_track_velocities(axes) -> (left, right)``.
Exercise 1.2, count the shots: a ``RttTankController`` subclass whose
``on_joy`` counts presses of button A and whose ``summary()`` reports ``shots``.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

from tutorial.exercises.grader import (
    Case,
    CaseFailed,
    Result,
    expect_numbers,
    experiments,
    grade,
    hidden_random,
    observe,
    same_numbers,
    same_value,
    show,
)
from tutorial.interfaces import joy

DPAD_SPEED = 1.0  # m/s of both tracks for D-pad up
DPAD_TURN = 0.5  # m/s of each track, opposite ways, for D-pad left or right


def _axes(dh: float = 0.0, dv: float = 0.0, lv: float = 0.0) -> list[float]:
    a = [0.0] * joy.NUM_AXES
    a[joy.DPAD_H], a[joy.DPAD_V], a[joy.LEFT_STICK_V] = dh, dv, lv
    return a


def check_dpad_steering(func) -> Result:
    """Check ``func(axes) -> (left, right)`` track velocities in m/s from the D-pad.

    D-pad up drives both tracks forward at 1.0 m/s, down backward; left turns
    left on the spot (left track -0.5 m/s, right +0.5 m/s), right the other
    way; diagonals add up; a missing or non-finite axis counts as 0; the
    sticks do not move the tracks here.
    """
    table = [
        ("released", _axes(), (0.0, 0.0), "nothing pressed: both tracks stand still."),
        ("up", _axes(dv=1.0), (DPAD_SPEED, DPAD_SPEED), "axis 5 (D-pad vertical) is +1 for up: both forward."),
        ("down", _axes(dv=-1.0), (-DPAD_SPEED, -DPAD_SPEED), "down is axis 5 = -1: both backward."),
        (
            "left",
            _axes(dh=1.0),
            (-DPAD_TURN, DPAD_TURN),
            "axis 4 (D-pad horizontal) is +1 for left, as the sticks: turning left, the left track runs backward.",
        ),
        ("right", _axes(dh=-1.0), (DPAD_TURN, -DPAD_TURN), "right is axis 4 = -1: the right track runs backward."),
        (
            "up and left",
            _axes(dh=1.0, dv=1.0),
            (DPAD_SPEED - DPAD_TURN, DPAD_SPEED + DPAD_TURN),
            "a diagonal is the sum of its two directions.",
        ),
        (
            "down and right",
            _axes(dh=-1.0, dv=-1.0),
            (-DPAD_SPEED + DPAD_TURN, -DPAD_SPEED - DPAD_TURN),
            "a diagonal is the sum of its two directions, reversing too: do not swap the tracks when going back.",
        ),
        (
            "down and left",
            _axes(dh=1.0, dv=-1.0),
            (-DPAD_SPEED - DPAD_TURN, -DPAD_SPEED + DPAD_TURN),
            "reversing while turning left is still the sum: backward, and the left track runs backward harder.",
        ),
        (
            "a Joy with only 4 axes",
            [0.0, 0.0, 0.0, 0.0],
            (0.0, 0.0),
            "a message without axes 4 and 5 must not raise: read axes with joy.axis(axes, index).",
        ),
        (
            "NaN on the vertical axis",
            _axes(dv=float("nan")),
            (0.0, 0.0),
            "a non-finite value counts as 0: joy.axis() does that for you.",
        ),
        ("left stick up, D-pad released", _axes(lv=1.0), (0.0, 0.0), "only axes 4 and 5 count here."),
    ]

    def case(label, axes, expected, hint, hidden=False):
        call = label if hidden else f"dpad_track_velocities({show(axes)}) ({label})"
        return Case(call, lambda: expect_numbers(call, func(list(axes)), expected), hint, hidden)  # the case's hint

    cases = [case(*row) for row in table]
    rng = hidden_random("1.1")  # while grading: this learner's own cases, drawn by the same rules
    for _ in range(24 if rng else 0):
        label, axes, expected = _random_dpad(rng)
        cases.append(case(label, axes, expected, "follow each rule of the statement, for every input.", True))
    return grade("Exercise 1.1, steer with the D-pad", cases)


def _random_dpad(rng) -> tuple[str, list[float], tuple[float, float]]:
    """A hidden case of 1.1, (what it tests, axes, expected (left, right) in m/s): every stick moved; a D-pad
    direction or none; in a quarter of them one D-pad axis NaN or infinite, or else in a fifth of the rest
    a Joy too short for the D-pad's axes."""
    axes = [rng.uniform(-1.0, 1.0) for _ in range(joy.NUM_AXES)]
    dh, dv = rng.choice((-1.0, 0.0, 1.0)), rng.choice((-1.0, 0.0, 1.0))
    axes[joy.DPAD_H], axes[joy.DPAD_V] = dh, dv
    if rng.random() < 0.25:  # a non-finite D-pad axis counts as 0
        bad = rng.choice((joy.DPAD_H, joy.DPAD_V))
        axes[bad] = rng.choice((math.nan, math.inf, -math.inf))
        expected = _dpad(0.0 if bad == joy.DPAD_H else dh, 0.0 if bad == joy.DPAD_V else dv)
        return "a D-pad axis NaN or infinite, the other pressed", axes, expected
    if rng.random() < 0.2:  # a message too short for the D-pad's axes
        return "a Joy too short for the D-pad's axes", axes[: rng.randrange(0, joy.DPAD_H + 1)], (0.0, 0.0)
    return "a D-pad direction (or none) with the sticks moved", axes, _dpad(dh, dv)


def _dpad(dh: float, dv: float) -> tuple[float, float]:
    """The statement's rules: (left, right) in m/s for D-pad axes ``dh`` (left +1) and ``dv`` (up +1)."""
    return DPAD_SPEED * dv - DPAD_TURN * dh, DPAD_SPEED * dv + DPAD_TURN * dh


def _joy(buttons, axes=None) -> SimpleNamespace:
    return SimpleNamespace(axes=list(axes if axes is not None else [0.0] * joy.NUM_AXES), buttons=list(buttons))


def _runs(presses) -> str:
    """``[A, A, A, NONE]`` as ``"A x3, none"``: a short text for a sequence of button states."""
    names = [{tuple(A): "A", tuple(B): "B", tuple(NONE): "none"}.get(tuple(p), show(list(p))) for p in presses]
    out: list[list] = []
    for name in names:
        if out and out[-1][0] == name:
            out[-1][1] += 1
        else:
            out.append([name, 1])
    return ", ".join(f"{n} x{k}" if k > 1 else n for n, k in out)


A = [1, 0, 0, 0, 0, 0, 0, 0]  # button A pressed
B = [0, 1, 0, 0, 0, 0, 0, 0]  # button B pressed
NONE = [0] * joy.NUM_BUTTONS


def check_shot_counter(cls) -> Result:
    """Check a tank controller class that counts presses of button A as ``summary()["shots"]``.

    A press is a change from released to pressed; a button held while the
    joy node repeats the same Joy at 20 Hz is one press; a Joy with too few
    buttons reads A as released; the class still drives (its ``on_joy``
    stores the sticks, as ``RttTankController``'s does).
    """
    sequences = [
        (
            "A held for 10 repeats, then released",
            [A] * 10 + [NONE] * 3,
            1,
            "a press is a change from released to pressed: remember whether A was down in the last Joy.",
        ),
        ("press, release, press", [A, NONE, A], 2, "each 0 -> 1 change of A is a shot."),
        ("the first Joy already has A pressed", [A], 1, "before any Joy, A counts as released."),
        (
            "a Joy with no buttons between two presses",
            [A, [], A],
            2,
            "a Joy with too few buttons reads A as released (and must not raise).",
        ),
        ("only B pressed", [B, B, NONE, B], 0, "A is button 0 (joy.BUTTON_A); B is button 1."),
    ]

    def count(label, presses, expected, hint, hidden=False):
        call = label if hidden else f"{cls.__name__}().on_joy() with buttons {_runs(presses)} ({label})"

        def run():
            shots = observe(_shots_counted, cls, presses)
            if not same_value(shots, expected):
                # no hint of its own: the grader gives the case's (grader._failed)
                raise CaseFailed(f"{call} gave summary()['shots'] == {shots!r}, expected {expected}.")

        return Case(call, run, hint, hidden)

    stick = [0.0, 1.0] + [0.0] * (joy.NUM_AXES - 2)

    def still_drives():
        count_, axes = observe(_input_after_one_joy, cls, A, stick)
        if not (same_numbers(axes, stick) and same_value(count_, 1)):
            raise CaseFailed(
                f"after one on_joy(axes={show(stick)}), take_input() gave ({count_!r}, {show(list(axes))}, ...), "
                f"expected (1, {show(stick)}, ...): the sticks are not stored once.",
                "call super().on_joy(msg) once, first, so the controller still drives.",
            )

    def still_summarises():
        got = observe(_summary_after_one_joy, cls, A)
        if not (type(got) is dict and same_value(got.get("joy_received"), 1)):
            raise CaseFailed(
                f"after one on_joy(), summary() gave {got!r}: RttTankController's own fields are gone.",
                "start from super().summary(): return {**super().summary(), 'shots': shots}.",
            )

    def under_the_lock():
        own, watched = observe(_state_touched, cls, [A, NONE, A])
        on_the_class = [(phase, name) for phase, what, name, _ in watched if what == "class write"]
        if on_the_class:
            phase, name = on_the_class[0]
            raise CaseFailed(
                f"{cls.__name__}: {phase}() changes {name} on the class, which every controller shares.",
                "keep the count on self (self.shots = ...), read and written under self._lock.",
            )
        seen = [row for row in watched if row[2] not in own]
        # what both threads touch: read by summary() (the main thread), read or written by on_joy (the spin thread)
        shared = {n for p, w, n, _ in seen if p == "summary" and w == "read"} & {
            n for p, *_, n, _ in seen if p == "on_joy"
        }
        loose = [(phase, what, name) for phase, what, name, held in seen if name in shared and not held]
        if loose:
            phase, what, name = loose[0]
            raise CaseFailed(
                f"{cls.__name__}: {phase}() {what}s self.{name} outside `with self._lock:`.",
                "on_joy runs on the spin thread and summary() on the main thread: what both touch (the count) is "
                "read and written under self._lock, as RttTankController.on_joy does.",
            )

    cases = [count(*row) for row in sequences]
    rng = hidden_random("1.2")  # while grading: this learner's own sequences, counted by the statement's rule
    for _ in range(12 if rng else 0):
        presses = _random_presses(rng)
        label = "a long random sequence of A, B, both, released and short Joys"
        cases.append(
            count(label, presses, _shots(presses), "a press is each change of A from released to pressed.", True)
        )
    cases.append(Case(f"{cls.__name__}: on_joy(a Joy with the left stick up)", still_drives))
    cases.append(Case(f"{cls.__name__}: summary() after one Joy", still_summarises))
    cases.append(Case(f"{cls.__name__}: what on_joy() remembers, under self._lock", under_the_lock))
    return grade("Exercise 1.2, count the shots", cases)


def _shots_counted(cls, presses) -> object:
    """A new ``cls()`` given a Joy of each buttons list of ``presses``: its ``summary().get("shots")``."""
    controller = cls()
    for buttons in presses:
        controller.on_joy(_joy(buttons))
    return controller.summary().get("shots")


def _input_after_one_joy(cls, buttons, axes) -> tuple:
    """A new ``cls()`` given one Joy: the count and the axes its ``take_input()`` gives."""
    controller = cls()
    controller.on_joy(_joy(buttons, axes))
    count_, got, _ = controller.take_input()
    return count_, got


def _summary_after_one_joy(cls, buttons) -> object:
    """A new ``cls()`` given one Joy: its ``summary()``."""
    controller = cls()
    controller.on_joy(_joy(buttons))
    return controller.summary()


def _state_touched(cls, presses) -> tuple[list, list]:
    """``(RttTankController's own attributes, what the answer touched)`` of a new ``cls()`` given a Joy of each
    of ``presses``, then asked for its ``summary()``: each state attribute read or written, as
    ``(phase, "read" or "write", name, whether its lock was held)`` (:func:`_watched`)."""
    controller = _watched(cls)()
    base = next(c for c in cls.__mro__ if c.__name__ == "RttTankController")
    own = sorted(vars(base()))  # RttTankController's own state: its on_joy keeps it under the lock
    object.__setattr__(controller, "_lock", _WatchedLock(controller._lock))  # the learner's lock, watched
    object.__setattr__(controller, "_watch", [])
    for phase, run in (("on_joy", lambda: [controller.on_joy(_joy(b)) for b in presses]), ("summary", None)):
        before = _class_state(type(controller))
        object.__setattr__(controller, "_phase", phase)
        (run or controller.summary)()
        after = _class_state(type(controller))
        controller.__dict__["_watch"] += [
            (phase, "class write", key[1], False) for key in after if before.get(key, after) is not after[key]
        ]
    return own, [tuple(row) for row in controller.__dict__["_watch"]]


def _class_state(kind: type) -> dict:
    """``{(place, "Class.name"): value}`` of what the answer's classes (:func:`_answers_classes`, the check's
    subclass first) hold themselves: a count kept there, which no instance's write shows, changes it."""
    return {
        (place, f"{k.__name__}.{name}"): value
        for place, k in enumerate(_answers_classes(kind))
        for name, value in vars(k).items()
    }


def _answers_classes(kind: type) -> list[type]:
    """``kind``'s MRO up to ``RttTankController``, which it leaves out (all of it, for a class that is none): the
    answer's classes, the check's subclass first if any.  A plain loop: this runs in the kernel beside the answer,
    which could replace a library's function (``itertools.takewhile``) there, not the language's own."""
    classes = []
    for k in kind.__mro__:
        if k.__name__ == "RttTankController":
            break
        classes.append(k)
    return classes


SHORT = [1]  # a Joy with button A alone: pressed
BOTH = [1, 1] + NONE[2:]  # A and B pressed together
JOYS = (A, A, B, NONE, NONE, SHORT, [], BOTH)  # what a hidden sequence is drawn from: A and none twice as often


def _random_presses(rng) -> list[list[int]]:
    """A hidden sequence of 1.2: 3 to 39 Joys of :data:`JOYS` (A, B, both, released, short and empty ones)."""
    return [rng.choice(JOYS) for _ in range(rng.randrange(3, 40))]


def _shots(presses) -> int:
    """The statement's rule: changes of button A from released to pressed (a too short Joy reads released)."""
    shots, down = 0, False
    for buttons in presses:
        now = len(buttons) > joy.BUTTON_A and buttons[joy.BUTTON_A] == 1
        shots += now and not down
        down = now
    return shots


class _WatchedLock:
    """The check's wrapper of the controller's own lock (a Lock or an RLock): it also says whether it is held."""

    def __init__(self, real):
        self._real = real
        self.depth = 0  # acquisitions not yet released (an RLock may be taken again by its holder)

    @property
    def held(self) -> bool:
        return self.depth > 0

    def acquire(self, *args, **kwargs) -> bool:
        got = self._real.acquire(*args, **kwargs)
        self.depth += bool(got)
        return got

    def release(self) -> None:
        self.depth -= 1
        self._real.release()

    def locked(self) -> bool:
        return self.held

    __enter__ = acquire

    def __exit__(self, *exc) -> None:
        self.release()


def _watched(cls):
    """``cls`` noting, while ``_phase`` names a phase, each state attribute it reads or writes, and if its lock is held.

    A method, a property or any other descriptor is not noted itself: what it reads and writes is.
    """

    def note(obj, what: str, name: str) -> None:
        d = object.__getattribute__(obj, "__dict__")
        if d.get("_phase") is None:  # the check's own _phase and _watch: never through here
            return
        if what == "read" and name[:2] == name[-2:] == "__" and name not in d and not _answers_own(type(obj), name):
            return  # Python's own (__class__, __dict__); state named like them (self.__shots__) is noted
        if hasattr(type(getattr(type(obj), name, None)), "__get__"):
            return  # a method or a property: what it touches is noted when it runs
        d["_watch"].append((d["_phase"], what, name, d["_lock"].held))

    class Watched(cls):
        def __setattr__(self, name, value):
            note(self, "write", name)
            object.__setattr__(self, name, value)

        def __getattribute__(self, name):
            note(self, "read", name)
            return object.__getattribute__(self, name)

    Watched.__name__ = Watched.__qualname__ = cls.__name__
    return Watched


def _answers_own(kind: type, name: str) -> bool:
    """Whether a class of the answer's (below ``RttTankController`` in ``kind``'s MRO) defines ``name`` itself."""
    return any(name in vars(k) for k in _answers_classes(kind)[1:])  # [0] is the check's Watched


# The experiments these checks have the kernel that holds the class run while grading (grader.EXPERIMENTS),
# listed here rather than decorated: make mutate leaves a decorated function alone.
experiments(_shots_counted, _input_after_one_joy, _summary_after_one_joy, _state_touched)
