"""The grader every exercise's check stands on (tutorial/exercises/grader.py): its rules, one by one.

A check is only as strict as the grader under it: a tolerance that lets a
wrong number through, a count said wrongly, a seed drawn from the wrong text,
a stub's error taken for a bug.  Each test here states one rule of the grader
exactly (the words a learner reads included), so that ``make mutate`` finds
no change to the grader that the tests let pass.
"""

from __future__ import annotations

import logging
import math
import random

import numpy as np
import pytest

from tutorial.exercises import grader
from tutorial.exercises.grader import Case, CaseFailed, Result

from conftest import KERNEL, SEED, hear_the_checks


def failing(what: str, hint: str = ""):
    def run():
        raise CaseFailed(what, hint)

    return run


def raising(exc: BaseException):
    def run():
        raise exc

    return run


# ---- one line per check: what it says when it passes ----


@pytest.mark.parametrize(
    "visible,hidden,said",
    [
        (1, 0, "passed (1 case)."),
        (2, 0, "passed (2 cases)."),
        (1, 1, "passed (1 case and 1 hidden one)."),
        (3, 2, "passed (3 cases and 2 hidden ones)."),
        (0, 1, "passed (0 cases and 1 hidden one)."),
    ],
)
def test_a_passed_check_counts_its_visible_and_hidden_cases(visible, hidden, said):
    cases = [Case(f"v{k}", lambda: None) for k in range(visible)]
    cases += [Case(f"h{k}", lambda: None, hidden=True) for k in range(hidden)]
    result = grader.grade("Exercise 9.9, a test", cases)
    assert (result.passed, result.message, result.case) == (True, said, None)
    assert bool(result) is True
    assert str(result) == repr(result) == f"\u2713 Exercise 9.9, a test: {said}"


def test_a_check_with_no_cases_is_an_error_not_a_pass():
    with pytest.raises(ValueError, match=r"^Exercise 9\.9, a test: a check with no cases cannot pass$"):
        grader.grade("Exercise 9.9, a test", [])


def test_a_check_stops_at_its_first_failed_case():
    ran = []
    cases = [
        Case("first", lambda: ran.append(1)),
        Case("second", failing("second returned 2.")),
        Case("third", lambda: ran.append(3)),
    ]
    result = grader.grade("Exercise 9.9, a test", cases)
    assert ran == [1] and result.case == "second" and bool(result) is False
    assert str(result) == "\u2717 Exercise 9.9, a test: second returned 2."


# ---- what a failed visible case says ----


@pytest.mark.parametrize(
    "call,exc,case_hint,said",
    [
        # the failure names the call itself: said as it is
        ("f(1)", CaseFailed("f(1) returned 2, expected 1."), "", "f(1) returned 2, expected 1."),
        # the failure does not name the call: the call first
        ("f(1)", CaseFailed("returned 2, expected 1."), "", "f(1): returned 2, expected 1."),
        # ... and its subject is said once, not twice
        ("Pub: the stamp", CaseFailed("Pub: 2 s late."), "", "Pub: the stamp: 2 s late."),
        ("Pub: the stamp", CaseFailed("Publisher: 2 s late."), "", "Pub: the stamp: Publisher: 2 s late."),
        ("Pub: x", CaseFailed("Pub:late"), "", "Pub: x: Pub:late"),
        ("Pub: the stamp: at 1 s", CaseFailed("Pub: late."), "", "Pub: the stamp: at 1 s: late."),
        # the failure's own hint wins over the case's; the case's is the fallback
        ("f(1)", CaseFailed("f(1) is wrong.", "its hint"), "case hint", "f(1) is wrong. Hint: its hint"),
        ("f(1)", CaseFailed("f(1) is wrong."), "case hint", "f(1) is wrong. Hint: case hint"),
        # a bug in the learner's code: its type and words, with the input, and the case's hint
        ("f(1)", ZeroDivisionError("division by zero"), "", "f(1) raised ZeroDivisionError: division by zero."),
        ("f(1)", KeyError("x"), "look at x", "f(1) raised KeyError: 'x'. Hint: look at x"),
    ],
)
def test_a_failed_case_says_its_input_what_went_wrong_and_the_hint(call, exc, case_hint, said):
    result = grader.grade("Exercise 9.9, a test", [Case(call, raising(exc), hint=case_hint)])
    assert (result.exercise, result.passed, result.message) == ("Exercise 9.9, a test", False, said)
    assert result.case == call


def test_a_stub_not_written_yet_is_told_as_not_done_not_as_a_bug():
    """``NotImplementedError``, also as the cause or context of another error, is the learner's empty stub."""
    words = (
        "not done yet: f(1) raised NotImplementedError. "
        "Write your code in place of the `raise NotImplementedError` line."
    )

    def from_cause():
        raise ValueError("wrapped") from NotImplementedError()

    def from_context():
        try:
            raise NotImplementedError
        except NotImplementedError:
            raise KeyError("while handling")  # noqa: B904 - its context is the NotImplementedError

    for run in (raising(NotImplementedError()), from_cause, from_context):
        result = grader.grade("Exercise 9.9, a test", [Case("f(1)", run, hint="never said")])
        assert (result.exercise, result.passed, result.message) == ("Exercise 9.9, a test", False, words)
        assert result.case == "f(1)"
    assert grader.not_done(None) is False and grader.not_done(ValueError()) is False
    assert grader.not_done(NotImplementedError()) is True


# ---- what a failed hidden case says: what it tests, never its values ----


@pytest.mark.parametrize(
    "exc,hint,said",
    [
        (CaseFailed("f(0.7312) returned 3."), "", "a hidden case failed: a speed at the limit."),
        (CaseFailed("f(0.7312) returned 3.", "own hint"), "", "a hidden case failed: a speed at the limit."),
        (
            CaseFailed("f(0.7312) returned 3."),
            "the limit",
            "a hidden case failed: a speed at the limit. Hint: the limit",
        ),
        (IndexError("0.7312"), "", "a hidden case failed (IndexError): a speed at the limit."),
        (NotImplementedError(), "", "a hidden case failed (NotImplementedError): a speed at the limit."),
    ],
)
def test_a_failed_hidden_case_names_what_it_tests_without_its_values(exc, hint, said):
    cases = [Case("f(1)", lambda: None), Case("a speed at the limit", raising(exc), hint=hint, hidden=True)]
    result = grader.grade("Exercise 9.9, a test", cases)
    assert (result.exercise, result.passed, result.message) == ("Exercise 9.9, a test", False, said)
    assert result.case == "a speed at the limit"
    assert "0.7312" not in str(result)


def test_the_defaults_of_a_case_and_a_failure():
    run = failing("x")
    assert Case("c", run) == Case("c", run, "", False)
    failed = CaseFailed("what went wrong")
    assert (failed.what, failed.hint, str(failed), failed.args) == (
        "what went wrong",
        "",
        "what went wrong",
        ("what went wrong",),
    )
    assert Result("E", True, "m").case is None


# ---- what the grading kernel's seal hears, and the quiet logs ----


def test_a_check_tells_the_seal_its_begin_its_result_and_its_end_even_when_it_fails():
    heard = hear_the_checks()
    result = grader.grade("Exercise 9.9, a test", [Case("c", lambda: None)])
    assert heard == [
        ("rtt.check_begin", ("Exercise 9.9, a test",)),
        ("rtt.result", (result,)),
        ("rtt.check_end", ("Exercise 9.9, a test",)),
    ]
    heard.clear()
    with pytest.raises(ValueError):
        grader.grade("Exercise 9.8, none", [])
    assert heard == [("rtt.check_begin", ("Exercise 9.8, none",)), ("rtt.check_end", ("Exercise 9.8, none",))]


def test_what_the_code_under_check_logs_is_kept_out_and_the_logger_put_back(caplog, capsys):
    logger = logging.getLogger("rtt")
    handlers, propagate = list(logger.handlers), logger.propagate

    def logs():
        logging.getLogger("rtt.controller").error("a joint the tank lacks")
        assert logger.propagate is False and len(logger.handlers) == len(handlers) + 1

    with caplog.at_level(logging.DEBUG):
        assert grader.grade("Exercise 9.9, a test", [Case("c", logs)]).passed
    assert "a joint the tank lacks" not in caplog.text and "a joint the tank lacks" not in capsys.readouterr().err
    assert (logger.handlers, logger.propagate) == (handlers, propagate)


def test_require_returns_a_pass_and_raises_a_failure_in_lines_of_at_most_88_characters():
    assert grader.WRAP == 88
    heard = hear_the_checks()
    passed = Result("E", True, "fine")
    assert passed.require() is passed
    assert heard == [("rtt.verdict", (passed,))]  # each verdict, to the grading kernel's seal
    word = "/a/path/" + "x" * 100
    with pytest.raises(AssertionError) as raised:
        Result("E", False, f"read {word} and found nothing.").require()
    assert str(raised.value).splitlines() == ["\u2717 E: read", f"  {word}", "  and found nothing."]  # kept whole
    assert [h[0] for h in heard] == ["rtt.verdict", "rtt.verdict"]
    for length, lines in ((88, 1), (89, 2)):
        message = "x" * (length - len("\u2717 E: ") - 4) + " end"
        failed = Result("E", False, message)
        assert len(str(failed)) == length
        with pytest.raises(AssertionError) as raised:
            failed.require()
        said = str(raised.value).splitlines()
        assert len(said) == lines and said[-1] in ("  end", str(failed)), said


# ---- an experiment, run here or in the kernel that holds the class ----


def _experiment(cls, *args):
    return ("ran here", cls, args)


def test_an_experiment_runs_here_on_the_class_outside_grading():
    hear_the_checks()
    assert grader.observe(_experiment, int, 1, "two") == ("ran here", int, (1, "two"))
    assert grader.observe(_experiment, int) == ("ran here", int, ())


def test_while_grading_an_experiment_goes_to_the_kernel_by_the_judges_way_without_the_class():
    """The judge's way to the kernel (put in the box by its audit hook) gets the experiment and its arguments; the
    class is the kernel's, never sent."""
    asked = []
    hear_the_checks()
    KERNEL[:] = [lambda func, *args: asked.append((func, args)) or "the kernel's reply"]
    try:
        assert grader.observe(_experiment, int, 1, "two") == "the kernel's reply"
    finally:
        KERNEL.clear()
    assert asked == [(_experiment, (1, "two"))]
    assert grader.observe(_experiment, int, 3) == ("ran here", int, (3,))  # and here again once the judge is gone


# ---- a failed case's frames, let go ----


def _raised(exc: BaseException) -> BaseException:
    """``exc`` raised and caught here: it has a traceback, as a case's failure has."""
    try:
        raise exc
    except BaseException as caught:  # noqa: BLE001 - the test's own
        return caught


def _chain() -> list[BaseException]:
    """A case's failure and all it chains to: its context (no cause), an exception group with a cause and a
    context of its own and two members, and a cycle back to the failure."""
    failure, context = _raised(CaseFailed("wrong", "hint")), _raised(ValueError("the answer's own"))
    members = [_raised(KeyError("first")), _raised(TypeError("second"))]
    group = _raised(ExceptionGroup("two", members))
    group_cause, group_context = _raised(OSError("cause")), _raised(RuntimeError("context"))
    group.__cause__, group.__context__ = group_cause, group_context
    context.__context__ = group
    group_context.__context__ = failure  # a cycle: the chain is walked once
    failure.__context__ = context
    return [failure, context, group, *members, group_cause, group_context]


@pytest.mark.timeout(20)
@pytest.mark.parametrize("hidden", [False, True])
def test_a_failed_case_keeps_no_traceback_anywhere_in_its_chain(hidden):
    """An answer can keep what it raised inside a case; once the check returns, no exception of the chain holds a
    frame (a cycle in the chain is walked once, and ends)."""
    chain = _chain()
    assert all(e.__traceback__ is not None for e in chain)

    def run():
        raise chain[0]

    result = grader._run_cases("9.9", [Case("the case", run, hidden=hidden)])
    assert not result.passed
    assert [type(e).__name__ for e in chain if e.__traceback__ is not None] == []


# ---- the hidden cases' random source ----


@pytest.fixture
def teachers_seed():
    """The seal's part for hidden_random: a seed for the teacher's checks, then none again."""
    hear_the_checks()
    SEED[:] = ["the teacher's seed for learner a"]
    yield SEED[0]
    SEED.clear()


def test_no_hidden_cases_outside_grading():
    hear_the_checks()
    assert grader.hidden_random("1.1") is None


def test_the_hidden_cases_are_drawn_from_the_teachers_seed_and_the_exercise(teachers_seed):
    drawn, expected = grader.hidden_random("1.1"), random.Random(f"{teachers_seed}/1.1")
    assert [drawn.random() for _ in range(3)] == [expected.random() for _ in range(3)]
    other = grader.hidden_random("1.2").random()
    assert (
        other == random.Random(f"{teachers_seed}/1.2").random()
        and other != random.Random(f"{teachers_seed}/1.1").random()
    )


# ---- comparing numbers and values ----


def test_the_number_types_are_ints_floats_and_numpys_real_scalars_not_bools_or_complex():
    assert grader._number_types() == grader.NUMBER_TYPES  # made once, at import
    for t in (int, float, np.float64, np.float32, np.float16, np.int8, np.int64, np.uint8, np.uint64):
        assert t in grader.NUMBER_TYPES, t
    for t in (bool, np.bool_, complex, np.complex128, str, np.str_, object):
        assert t not in grader.NUMBER_TYPES, t


@pytest.mark.parametrize(
    "got,expected,tol,same",
    [
        (1.5, 1.0, 0.5, True),  # exactly at the tolerance: the same
        (1.5, 1.0, 0.4999, False),
        (0.5, 1.0, 0.5, True),
        (1.0 + 5e-10, 1.0, None, True),  # the default tolerance is 1e-9
        (1.0 + 2e-9, 1.0, None, False),
        (1.0 - 2e-9, 1.0, None, False),
        (2, 2, None, True),
        (np.int64(2), 2.0, None, True),
        (math.nan, math.nan, None, False),  # not finite: never the same
        (math.inf, math.inf, None, False),
        (True, 1, None, False),  # a bool is not a number here
        (1 + 0j, 1.0, None, False),
        ([1.0, 2.0], [1.0, 2.0], None, True),
        ((1.0, 2.0), [1.0, 2.0], None, True),
        (np.array([1.0, 2.0]), (1.0, 2.0), None, True),
        ([1.2, 2.2], [1.0, 2.0], 0.25, True),  # the tolerance holds for every element
        ([1.2, 2.2], [1.0, 2.0], 0.15, False),
        ([1.0, 2.5], [1.0, 2.0], None, False),
        ([1.0], [1.0, 2.0], None, False),
        ([1.0, 2.0, 3.0], [1.0, 2.0], None, False),
        ([], [], None, True),
        (None, [1.0], None, False),
        (3, [1.0], None, False),
        ([[1.0, 2.0]], [[1.0, 2.0]], None, True),
        ([[1.0, 2.5]], [[1.0, 2.0]], None, False),
    ],
)
def test_same_numbers(got, expected, tol, same):
    assert grader.same_numbers(got, expected, *(() if tol is None else (tol,))) is same


@pytest.mark.parametrize(
    "got,expected,same",
    [
        (2, 2, True),
        (np.int64(2), 2, True),
        (2.0, 2, True),  # an int may come as a whole float
        (np.float64(2.0), 2, True),
        (2.5, 2, False),
        (3, 2, False),
        (True, 1, False),
        (1, True, False),
        (True, True, True),
        ("a", "a", True),
        ("a", "b", False),
        ((1, 2), (1, 2), True),
        ([1, 2], (1, 2), False),
        (None, None, True),
        (math.inf, 2, False),
    ],
)
def test_same_value(got, expected, same):
    assert grader.same_value(got, expected) is same


def test_a_value_of_a_class_that_compares_as_it_likes_is_refused_and_told_to_the_seal():
    """same_numbers and same_value refuse a value whose class is not exactly a number type or the expected one,
    and tell the seal (``rtt.suspect``) when that class is an answer's own with a comparison of its own (its own
    ``__eq__``, its metaclass's, or a subclass of a number or a string): not a plain class, not a builtin or NumPy's
    own."""

    class AlwaysEqual:
        def __eq__(self, other):
            return True

    class Child(AlwaysEqual):
        pass

    class MyFloat(float):
        pass

    class MyStr(str):
        pass

    class Plain:
        pass

    class AClassWhoseNameIsLongerThanFortyCharactersByFar(int):
        pass

    class Meta(type):  # a metaclass's comparison makes `type(got) == float` say yes
        def __eq__(cls, other):
            return True

        __hash__ = type.__hash__

    class MetaOfMeta(Meta):
        pass

    class Sly(metaclass=Meta):
        pass

    class Slier(metaclass=MetaOfMeta):  # the comparison one metaclass further up
        pass

    heard = hear_the_checks()
    assert not grader.same_numbers(AlwaysEqual(), 1.0) and not grader.same_value(AlwaysEqual(), "a")
    assert not grader.same_numbers(MyFloat(1.0), 1.0) and not grader.same_value(MyFloat(2.0), 2)
    assert not grader.same_value(AClassWhoseNameIsLongerThanFortyCharactersByFar(3), 3)
    assert not grader.same_value(MyStr("a"), "a") and not grader.same_value(Child(), "a")
    assert not grader.same_value(Plain(), "a")  # refused, but no comparison of its own: untold
    assert not grader.same_value(Sly(), 1.0) and not grader.same_numbers(Slier(), 1.0)
    assert not grader.same_numbers("1.0", 1.0) and not grader.same_value("1", 1)  # builtins: untold
    assert not grader.same_numbers(None, 1.0) and not grader.same_value(np.str_("a"), "a")  # NumPy's own: untold
    assert grader.same_numbers(np.float32(1.0), 1.0) and grader.same_value(np.int64(2), 2)
    assert grader.same_value(True, True)
    own = "a class of its own that compares as it likes"
    assert [h[1][0] for h in heard if h[0] == "rtt.suspect"] == [
        f"a AlwaysEqual, {own}",
        f"a AlwaysEqual, {own}",
        f"a MyFloat, {own}",
        f"a MyFloat, {own}",
        f"a AClassWhoseNameIsLongerThanFortyCharacte, {own}",
        f"a MyStr, {own}",
        f"a Child, {own}",
        f"a Sly, {own}",
        f"a Slier, {own}",
    ], heard


# ---- how values are shown ----


@pytest.mark.parametrize(
    "value,shown",
    [
        (1.23456, "1.2346"),
        (np.float64(1.23456), "1.2346"),
        (2.0, "2.0"),
        (-0.00004, "-0.0"),
        (math.nan, "nan"),
        (math.inf, "inf"),
        (-math.inf, "-inf"),
        (3, "3"),
        ("a", "'a'"),
        (None, "None"),
        ([], "[]"),
        ([1.23456, 2], "[1.2346, 2]"),
        ((), "()"),
        ((1.23456,), "(1.2346,)"),
        ((1, 2.5), "(1, 2.5)"),
        ([(0.11111, [2.22222])], "[(0.1111, [2.2222])]"),
    ],
)
def test_show(value, shown):
    assert grader.show(value) == shown


def test_expect_numbers_says_what_came_back_and_what_was_expected_with_the_hint():
    grader.expect_numbers("f(1)", 1.05, 1.0, tol=0.1)
    grader.expect_numbers("f(1)", [1.0, 2.0], (1.0, 2.0))
    with pytest.raises(CaseFailed) as raised:
        grader.expect_numbers("f(1)", (1.23456, 2), [1.0, 2.0], hint="the sign")
    assert (raised.value.what, raised.value.hint) == ("f(1) returned (1.2346, 2), expected [1.0, 2.0].", "the sign")
    with pytest.raises(CaseFailed) as raised:
        grader.expect_numbers("f(1)", 1.0 + 2e-9, 1.0)
    assert raised.value.what == "f(1) returned 1.0, expected 1.0." and raised.value.hint == ""


def test_expect_qos_names_each_policy_and_fails_on_any_one_of_them():
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    def qos(**changed):
        given = {
            "reliability": ReliabilityPolicy.RELIABLE,
            "durability": DurabilityPolicy.VOLATILE,
            "history": HistoryPolicy.KEEP_LAST,
            "depth": 10,
        }
        return QoSProfile(**(given | changed))

    assert grader.QOS_POLICIES == ("reliability", "durability", "history", "depth")
    grader.expect_qos("Pub", qos(), qos())
    with pytest.raises(CaseFailed) as raised:
        grader.expect_qos("Pub", qos(depth=1), qos())
    assert raised.value.hint == ""
    for changed in (
        {"reliability": ReliabilityPolicy.BEST_EFFORT},
        {"durability": DurabilityPolicy.TRANSIENT_LOCAL},
        {"history": HistoryPolicy.KEEP_ALL},
        {"depth": 1},
    ):
        with pytest.raises(CaseFailed):
            grader.expect_qos("Pub", qos(**changed), qos())
    with pytest.raises(CaseFailed) as raised:
        grader.expect_qos("Pub", qos(reliability=ReliabilityPolicy.BEST_EFFORT, depth=1), qos(), hint="sensor data")
    assert raised.value.what == (
        "Pub: its QoS is reliability best_effort, durability volatile, history keep_last, depth 1; "
        "expected reliability reliable, durability volatile, history keep_last, depth 10."
    )
    assert raised.value.hint == "sensor data"


def test_a_run_that_stopped_on_an_error_is_told_by_its_last_line_and_a_stub_s_as_not_done():
    from tutorial.exercises.grader import CaseFailed, raise_run_error

    raise_run_error({})
    raise_run_error({"error": ""})
    with pytest.raises(NotImplementedError):
        raise_run_error({"error": "Traceback (most recent call last):\n  ...\nNotImplementedError\n"})
    with pytest.raises(CaseFailed) as failed:
        raise_run_error({"error": "Traceback (most recent call last):\n  ...\nTypeError: Expected Float64.\n\n"})
    assert failed.value.what == "the simulation failed: TypeError: Expected Float64."
    with pytest.raises(CaseFailed) as failed:
        raise_run_error({"error": "KeyError: 'GUN'"})
    assert failed.value.what == "the simulation failed: KeyError: 'GUN'."
