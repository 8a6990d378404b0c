"""Checks for the notebooks' exercises: run the learner's code on cases, say one clear line.

Each exercise has a check function (in :mod:`tutorial.exercises.step1_tank_controller`,
``step2_joint_state_publisher``, ...: one module per notebook) that takes
what the learner wrote (a function or a class), runs it on cases and returns a :class:`Result`.  A notebook's check cell
ends with that call, so the cell shows one line:

    ✓ Exercise 1.1, steer with the D-pad: passed (9 cases).
    ✗ Exercise 1.1, steer with the D-pad: dpad_track_velocities(axes=[0, 0, 0, 0, 0, 1.0, 0, 0])
      returned (0.0, 0.0), expected (1.0, 1.0). Hint: ...

A case is a function that raises :class:`CaseFailed` (what failed, with the
input, and a hint) or returns.  Anything else it raises is reported with
the case's input too: a ``NotImplementedError`` means the learner has not
written the code yet, any other exception is a bug in their code.

The checks are deterministic (no wall-clock timing, seeded where random),
so the same code always gets the same line.  Any thread may run them;
a check that simulates runs the simulation on the calling thread.
"""

from __future__ import annotations

import logging
import math
import random
import sys
import textwrap
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

PASS, FAIL = "\u2713", "\u2717"
WRAP = 88  # characters per line of a failed check's exception (Result.require)


class CaseFailed(AssertionError):
    """One case of a check failed.

    Args:
        what: what was called with which input, what came back, what was expected.
        hint: what to look at, for the learner.
    """

    def __init__(self, what: str, hint: str = ""):
        super().__init__(what)
        self.what = what
        self.hint = hint


@dataclass
class Case:
    """One case: ``run()`` raises :class:`CaseFailed` on a wrong answer; ``call`` names the input.

    A ``hidden`` case is drawn for grading (:func:`hidden_random`): ``call`` says what it tests, and its
    failure is told by that alone, never by its values.
    """

    call: str
    run: Callable[[], None]
    hint: str = ""
    hidden: bool = False


@dataclass
class Result:
    """The outcome of one exercise's check; shown as its one line.

    Attributes:
        exercise: e.g. ``"Exercise 1.1, steer with the D-pad"``.
        passed: whether every case passed.
        message: the line shown (without the mark).
        case: the ``call`` of the first failing case, or None.
    """

    exercise: str
    passed: bool
    message: str
    case: str | None = None

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        return f"{PASS if self.passed else FAIL} {self.exercise}: {self.message}"

    __repr__ = __str__

    def require(self) -> Result:
        """This result if it passed; else raise, with its one line (how an nbgrader test cell fails).

        Raises:
            AssertionError: the check failed; the message is the line a learner sees, wrapped at
                :data:`WRAP` characters (nbgrader's feedback shows it in a box that does not wrap).
        """
        sys.audit("rtt.verdict", self)  # to the grading kernel's seal (tutorial.tools.grading.seal), if any
        if not self.passed:
            raise AssertionError(self.wrapped())
        return self

    def wrapped(self) -> str:
        """The one line, wrapped at :data:`WRAP` characters without breaking a word."""
        return textwrap.fill(str(self), WRAP, subsequent_indent="  ", break_long_words=False)


def grade(exercise: str, cases: Iterable[Case]) -> Result:
    """Run the cases in order; stop at the first failure.

    What the controllers log meanwhile (``rtt.*``: the errors a case provokes
    on purpose, such as a joint the tank lacks) is kept out of the output, so
    a check shows its one line; nbgrader also gives no points to a test cell
    that wrote to stderr.

    Returns:
        a passing :class:`Result` naming how many cases ran, or a failing one
        saying which input failed, how, and the hint.
    """
    logger = logging.getLogger("rtt")
    quiet, propagate = logging.NullHandler(), logger.propagate
    logger.addHandler(quiet)  # a handler, so Python's last-resort handler does not print to stderr
    logger.propagate = False
    sys.audit("rtt.check_begin", exercise)  # the grading kernel's seal (tutorial.tools.grading.seal) takes note
    try:
        result = _run_cases(exercise, cases)
        sys.audit("rtt.result", result)
        return result
    finally:
        sys.audit("rtt.check_end", exercise)  # also when a cell's timeout interrupted the check
        logger.removeHandler(quiet)
        logger.propagate = propagate


EXPERIMENTS: dict[str, Callable] = {}  # "module:name" -> every function listed by experiments()


def experiments(*funcs: Callable) -> None:
    """List each ``func(cls, *args)`` of ``funcs`` as one of a check's experiments on a learner's class: what it
    returns is data (the wire's types: numbers, text, lists, tuples, dicts, arrays), which the check then judges.
    A check module lists its own at its end, when it is imported.

    While grading, the check runs in the judge (:mod:`tutorial.tools.grading.judge`), and :func:`observe` has
    the graded kernel, where the class lives, run the experiment by this name.
    """
    for func in funcs:
        EXPERIMENTS[f"{func.__module__}:{func.__qualname__}"] = func


def observe(func: Callable, cls, *args):
    """What experiment ``func(cls, *args)`` (listed by :func:`experiments`) gives: run here, or while grading in the
    kernel that holds the learner's class, whose reply is built back from data.  The caller's thread.

    Raises:
        what the experiment raised (while grading: a class of its name, as the judge rebuilds it).
    """
    box: list = []
    sys.audit("rtt.observe", box)  # the judge, where it runs this check, puts its way to the kernel in the box
    return box[0](func, *args) if box else func(cls, *args)


def hidden_random(exercise: str) -> random.Random | None:
    """The random source of this learner's hidden cases of ``exercise`` (e.g. ``"1.1"``), while grading; else None.

    Its seed is the grader's: drawn per learner from a seed the teacher keeps (``course/grade.py``) and given
    only to the teacher's own checks by the grading kernel's seal (:mod:`tutorial.tools.grading.seal`).  Outside
    grading (a learner's own run) there is none, and a check runs its visible cases alone.  Any thread.
    """
    box: list[str] = []
    sys.audit("rtt.seed", box)  # the seal puts the seed in the box, for a teacher's check only
    return random.Random(f"{box[0]}/{exercise}") if box else None


def _run_cases(exercise: str, cases: Iterable[Case]) -> Result:
    count = hidden = 0
    for case in cases:
        count += 1
        hidden += case.hidden
        try:
            case.run()
        except Exception as exc:  # noqa: BLE001 - a hidden case is told by what it tests
            failure = exc
        else:
            continue
        if not case.hidden:
            result = _failed(exercise, case, failure)
        else:
            hint = f" Hint: {case.hint}" if case.hint else ""
            said = "" if isinstance(failure, CaseFailed) else f" ({type(failure).__name__})"
            result = Result(exercise, False, f"a hidden case failed{said}: {case.call}.{hint}", case.call)
        _forget_frames(failure)
        return result
    if count == 0:
        raise ValueError(f"{exercise}: a check with no cases cannot pass")
    shown = count - hidden
    more = f" and {hidden} hidden one{'s' if hidden != 1 else ''}" if hidden else ""
    return Result(exercise, True, f"passed ({shown} case{'s' if shown != 1 else ''}{more}).")


def _forget_frames(exc: BaseException) -> None:
    """Take the traceback off ``exc`` and every exception it chains (the check's own, and an answer's it raised).

    An answer can keep the exception it raised inside a case; once the check has returned, the frames of its
    traceback (this function's caller among them) would still hold every case, hidden ones too, with what each
    expects.  The seal refuses reading them while a check runs; after it, nothing holds them.  Reads the chain
    through ``BaseException``'s own descriptors, never an answer's class (its ``__context__`` could be a property).
    """
    todo, seen = [exc], set()
    while todo:
        e = todo.pop()
        if not isinstance(e, BaseException) or id(e) in seen:
            continue
        seen.add(id(e))
        BaseException.with_traceback(e, None)  # its traceback, and with it the frames, let go (never read here)
        todo += [_CONTEXT.__get__(e), _CAUSE.__get__(e)]
        if isinstance(e, BaseExceptionGroup):
            todo += list(_GROUP.__get__(e))


_CONTEXT, _CAUSE = vars(BaseException)["__context__"], vars(BaseException)["__cause__"]
_GROUP = vars(BaseExceptionGroup)["exceptions"]


def _failed(exercise: str, case: Case, exc: Exception) -> Result:
    """The result of a visible case that raised ``exc``: what failed, with its input, and the hint."""
    if isinstance(exc, CaseFailed):
        hint = exc.hint or case.hint
        what = exc.what if case.call in exc.what else f"{case.call}: {_unless_said(case.call, exc.what)}"
        return Result(exercise, False, what + (f" Hint: {hint}" if hint else ""), case.call)
    if not_done(exc):  # the learner's stub
        return Result(
            exercise,
            False,
            f"not done yet: {case.call} raised NotImplementedError. "
            "Write your code in place of the `raise NotImplementedError` line.",
            case.call,
        )
    hint = f" Hint: {case.hint}" if case.hint else ""  # the learner's bug, reported with its input
    return Result(exercise, False, f"{case.call} raised {type(exc).__name__}: {exc}.{hint}", case.call)


def _unless_said(call: str, what: str) -> str:
    """``what`` without a leading "subject: " that ``call`` already begins with (said once, not twice)."""
    subject = call.split(": ", 1)[0]
    return what[len(subject) + 2 :] if what.startswith(subject + ": ") else what


def not_done(exc: BaseException | None) -> bool:
    """Whether ``exc`` is, or was caused by, a ``NotImplementedError`` (a stub not yet written)."""
    while exc is not None:
        if isinstance(exc, NotImplementedError):
            return True
        exc = exc.__cause__ or exc.__context__
    return False


def raise_run_error(summary: dict) -> None:
    """Raise as a check must when its scripted run of the learner's controller stopped on an error.

    ``summary``: the run's summary (``run_headless``); nothing happens without an ``"error"`` in it.

    Raises:
        NotImplementedError: the error is a stub's (the learner's code is not written yet).
        CaseFailed: any other error, told by its last line.
    """
    error = summary.get("error")
    if error:
        if "NotImplementedError" in error:
            raise NotImplementedError
        raise CaseFailed("the simulation failed: " + error.strip().splitlines()[-1].rstrip(".") + ".")


class _ExactTypes(frozenset):
    """Types, where ``kind in types`` means one of them itself: compared by identity, never by ``==``, which a
    class of an answer's could answer through its own metaclass (its ``__eq__`` and ``__hash__`` those of
    ``float``)."""

    def __contains__(self, kind) -> bool:
        return any(kind is t for t in frozenset.__iter__(self))


def _number_types() -> frozenset[type]:
    import numpy

    scalars = {t for t in numpy.sctypeDict.values() if issubclass(t, (numpy.integer, numpy.floating))}
    return _ExactTypes({int, float} | scalars)


# The types of number an answer may return, exactly: a subclass of float could compare equal to anything.
NUMBER_TYPES = _number_types()


def same_numbers(got, expected, tol: float = 1e-9) -> bool:
    """True when ``got`` is a number or a sequence of numbers equal to ``expected`` within ``tol``.

    A number is an ``int``, a ``float`` or a NumPy scalar, of exactly that type (not a subclass, whose
    comparisons an answer could make say anything).
    """
    if isinstance(expected, (int, float)):
        if type(got) not in NUMBER_TYPES:
            _suspect(got)
            return False
        return math.isfinite(got) and abs(float(got) - expected) <= tol
    try:
        got = list(got)
    except TypeError:
        return False
    return len(got) == len(expected) and all(same_numbers(g, e, tol) for g, e in zip(got, expected))


def same_value(got, expected) -> bool:
    """True when ``got`` is ``expected``'s type exactly (an int may be a NumPy integer) and equal to it.

    Never calls a method of a class an answer made (its ``__eq__`` could say anything).
    """
    if type(expected) is int:
        if type(got) not in NUMBER_TYPES:
            _suspect(got)
            return False
        return float(got).is_integer() and int(got) == expected
    if type(got) is not type(expected):
        _suspect(got)
        return False
    return got == expected


def _suspect(got) -> None:
    """Tell the grading kernel's seal when a value's class is an answer's own and could compare as it likes."""
    kind = type(got)
    classes = [*kind.__mro__[:-1], *type(kind).__mro__[:-1]]  # its own, and its metaclass's
    if isinstance(got, (int, float, str)) or any("__eq__" in vars(k) for k in classes):
        if kind.__module__ not in ("builtins", "numpy"):
            sys.audit("rtt.suspect", f"a {kind.__name__!s:.40}, a class of its own that compares as it likes")


def show(value) -> str:
    """A short, stable text for a value in a message (floats rounded to 4 decimals)."""
    if isinstance(value, float):
        return repr(round(float(value), 4))  # a NumPy float as a float; NaN and the infinities round to themselves
    if isinstance(value, (list, tuple)):
        inner = ", ".join(show(v) for v in value)
        return f"[{inner}]" if isinstance(value, list) else f"({inner}{',' if len(value) == 1 else ''})"
    return repr(value)


def expect_numbers(call: str, got, expected: Sequence[float] | float, tol: float = 1e-9, hint: str = "") -> None:
    """Raise :class:`CaseFailed` unless ``got`` equals ``expected`` within ``tol``."""
    if not same_numbers(got, expected, tol):
        raise CaseFailed(f"{call} returned {show(got)}, expected {show(expected)}.", hint)


QOS_POLICIES = ("reliability", "durability", "history", "depth")  # what the statements name of a topic's QoS


def expect_qos(call: str, got, expected, hint: str = "") -> None:
    """Raise :class:`CaseFailed` unless QoS profile ``got`` has ``expected``'s :data:`QOS_POLICIES`, naming each."""

    def said(q) -> str:
        return ", ".join(f"{p} {getattr(getattr(q, p), 'name', getattr(q, p))}".lower() for p in QOS_POLICIES)

    if any(getattr(got, p) != getattr(expected, p) for p in QOS_POLICIES):
        raise CaseFailed(f"{call}: its QoS is {said(got)}; expected {said(expected)}.", hint)
