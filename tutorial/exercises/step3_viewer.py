"""Checks for the exercises of notebook 03 (Step 3, the viewer).

Exercise 3.1, refuse another model's message: a ``RttJointStateSubscriber``
subclass that refuses, whole, a JointState naming a joint this body does not
have (or none of its joints), counting it as ``wrong_model``.
Exercise 3.2, your own joint matcher: ``my_match(joints, names, positions)``
returning what to apply, checked against the hostile messages.

The module is over 400 lines and still one job: both checks judge the joint
matching of notebook 03 on the same tank (``_tank``): 3.2 a matcher of the
learner's own, 3.1 a subscriber by what it applied to that tank (its
experiment, ``_applied``, run where the class lives).
"""

from __future__ import annotations

import math

from tutorial.exercises.grader import (
    Case,
    CaseFailed,
    Result,
    experiments,
    grade,
    hidden_random,
    observe,
    same_numbers,
    same_value,
    show,
)

TANK = ["TURRET_Y", "TURRET_P"]

# (label, names, positions): the hostile messages of notebook 03, and a few more
HOSTILE = [
    ("in order", ["TURRET_Y", "TURRET_P"], [0.3, 0.2]),
    ("reordered", ["TURRET_P", "TURRET_Y"], [0.2, 0.3]),
    ("unknown name", ["TURRET_Y", "GUN", "TURRET_P"], [0.3, 9.0, 0.2]),
    ("duplicate name", ["TURRET_Y", "TURRET_Y", "TURRET_P"], [0.3, 0.4, 0.2]),
    ("short positions", ["TURRET_Y", "TURRET_P"], [0.3]),
    ("short names", ["TURRET_Y"], [0.3, 0.2]),
    ("NaN", ["TURRET_Y", "TURRET_P"], [math.nan, 0.2]),
    ("minus infinity", ["TURRET_Y", "TURRET_P"], [0.1, -math.inf]),
    ("huge", ["TURRET_Y", "TURRET_P"], [1e300, 0.2]),
    ("past the limit a little", ["TURRET_P"], [0.80]),
    ("past the limit a lot", ["TURRET_P"], [0.90]),
    ("empty", [], []),
]


def _tank():
    """A Body of the tank alone, over its own MjData (the caller's thread owns it)."""
    import mujoco

    from tutorial.core.body import Body
    from tutorial.core.world import build_world
    from tutorial.notebook.runs import load

    model = build_world(load("tank_view.yaml").models)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return Body(model, data, "Tank")


def _crane():
    import mujoco

    from tutorial.core.body import Body
    from tutorial.core.world import ModelEntry, build_world
    from tutorial.notebook.session import MODEL

    model = build_world([ModelEntry("Crane", MODEL / "crane.xml")])
    return Body(model, mujoco.MjData(model), "Crane")


def check_own_matcher(func) -> Result:
    """Check ``func(joints, names, positions) -> {name: position}`` against the library's matcher.

    ``joints`` is ``Body.joint_infos``; the result must be exactly what
    :func:`tutorial.interfaces.joint_state.match_joint_state` applies: matched by
    name in any order; unknown names, every entry of a duplicated name,
    entries without a position, non-finite values and values outside the
    joint's range by more than 0.05 rad (0.01 m for a slide) are skipped.
    """
    from tutorial.interfaces.joint_state import match_joint_state

    tank, crane = _tank().joint_infos, _crane().joint_infos
    rows = [(label, tank, names, positions) for label, names, positions in HOSTILE]
    rows += [
        ("a slide a little past its limit", crane, ["TROLLEY"], [crane[2].upper + 0.005]),
        ("a slide 0.05 m past its limit", crane, ["TROLLEY"], [crane[2].upper + 0.05]),
        ("an unlimited hinge far round", crane, ["SLEW", "LUFF"], [100.0, 0.1]),
        ("an unlimited hinge at infinity", crane, ["SLEW", "LUFF"], [math.inf, 0.1]),
        ("just below a lower limit", tank, ["TURRET_P"], [tank[1].lower - 0.03]),
        ("far below a lower limit", tank, ["TURRET_P"], [tank[1].lower - 0.2]),
        ("three copies of a name", tank, ["TURRET_Y", "TURRET_Y", "TURRET_P", "TURRET_Y"], [0.1, 0.2, 0.3, 0.4]),
    ]
    hints = {
        "in order": "apply each named joint's position: {name: position} for every entry that passes the rules.",
        "reordered": "match by name, not by index: the message may list joints in any order.",
        "unknown name": "skip a name the body does not have, and keep going.",
        "duplicate name": "a name given twice: which value is right cannot be known, so skip every copy.",
        "short positions": "an entry without a position is skipped (never read past the array).",
        "short names": "a position without a name is skipped.",
        "NaN": "math.isfinite(q) is False for NaN and infinities: skip those.",
        "minus infinity": "math.isfinite(q) is False for NaN and infinities: skip those.",
        "huge": "a value far outside the joint's range (info.lower, info.upper) is skipped, not clamped.",
        "past the limit a little": "within 0.05 rad of a limit is what a joint pressing on its stop reports: apply it.",
        "past the limit a lot": "more than 0.05 rad past a limit: skip it.",
        "a slide a little past its limit": "a slide's tolerance is 0.01 m (info.kind == 'slide').",
        "a slide 0.05 m past its limit": "a slide's tolerance is 0.01 m (info.kind == 'slide').",
        "an unlimited hinge far round": "an unlimited joint (info.limited False) has no range to check.",
        "an unlimited hinge at infinity": "no range to check, but infinity is still not a position: "
        "math.isfinite(q), not only math.isnan(q).",
        "just below a lower limit": "the 0.05 rad tolerance holds at both ends: lower - 0.05 <= q <= upper + 0.05.",
        "far below a lower limit": "more than 0.05 rad below the lower limit: skip it.",
        "three copies of a name": "every copy of a name given more than once is skipped: count them "
        "(collections.Counter), do not pair them off.",
    }

    def case(label, joints, names, positions, hidden=False):
        who = "crane" if joints is crane else "tank"
        call = label if hidden else f"my_match({who} joints, {show(names)}, {show(positions)}) ({label})"
        hint = "follow each rule of the statement, for every message." if hidden else hints.get(label, "")

        def run():
            expected = match_joint_state(joints, names, positions).applied
            got = func(joints, list(names), list(positions))
            if not _same_applied(got, expected):
                shape = "" if type(got) is dict else "return a plain dict: {joint name (str): position (float)}."
                raise CaseFailed(f"{call} returned {_show_dict(got)}, expected {_show_dict(expected)}.", shape)

        return Case(call, run, hint, hidden)

    cases = [case(*row) for row in rows]
    rng = hidden_random("3.2")  # while grading: this learner's own messages, judged by the library's matcher
    for _ in range(30 if rng else 0):
        joints = rng.choice((tank, crane))
        names, positions = _random_message(rng, joints)
        cases.append(
            case(
                "a random message: names known, unknown and repeated, values in, near and out of range",
                joints,
                names,
                positions,
                True,
            )
        )
    return grade("Exercise 3.2, your own joint matcher", cases)


POOLS = (["TURRET_Y", "TURRET_P"], ["SLEW", "LUFF", "TROLLEY"], ["TURRET_P", "GUN"])  # the tank's, the crane's, mixed


def _random_run(rng) -> list[tuple[list[str], list[float]]]:
    """A hidden run of 3.1: 1 to 4 messages (names, positions), each of 0 to 3 distinct names of one of
    :data:`POOLS`, each position in -0.1 to 0.7 rad or NaN."""
    run = []
    for _ in range(rng.randrange(1, 5)):
        pool = rng.choice(POOLS)
        names = list(dict.fromkeys(rng.choice(pool) for _ in range(rng.randrange(0, 4))))  # each name once
        run.append((names, [rng.choice((rng.uniform(-0.1, 0.7), math.nan)) for _ in names]))
    return run


def _sure_messages(rng) -> list[tuple[list[str], list[float]]]:
    """Two messages every hidden grading of 3.1 has, so an answer that mishandles one fails for every learner,
    not for a lucky draw's: 1 or 2 of the tank's names, every position NaN (not another model's: the matcher
    rejects each entry); and the tank's names with the gun's before the last (another model's, whatever its
    last name)."""
    names = rng.sample(POOLS[0], rng.randrange(1, 3))
    mixed = [*rng.sample(["GUN", "TURRET_Y"], 2), "TURRET_P"]
    return [(names, [math.nan] * len(names)), (mixed, [rng.uniform(-0.1, 0.7) for _ in mixed])]


def _random_message(rng, joints) -> tuple[list[str], list[float]]:
    """A message for ``joints`` by the statement's rules: any order, unknown and repeated names, values in
    range, within and past the tolerance, non-finite; sometimes a position or a name short."""
    names, positions = [], []
    for _ in range(rng.randrange(0, 6)):
        info = rng.choice(joints)
        names.append(rng.choice([info.name] * 4 + ["GUN", "TURRET_Y", "SLEW"]))
        low, high = (info.lower, info.upper) if info.limited else (-10.0, 10.0)
        tolerance = 0.01 if info.kind == "slide" else 0.05
        positions.append(
            rng.choice(
                (
                    rng.uniform(low, high),
                    high + rng.uniform(0.0, 0.9) * tolerance,
                    low - rng.uniform(1.1, 3.0) * tolerance,
                    rng.choice((math.nan, math.inf, -math.inf, 1e300)),
                )
            )
        )
    if names and rng.random() < 0.2:
        (positions if rng.random() < 0.5 else names).pop()
    return names, positions


def _same_dict(got, expected: dict, same) -> bool:
    """``got`` is a dict of exactly ``expected``'s names (str), each value ``same(value, expected's)``."""
    if type(got) is not dict or len(got) != len(expected) or not all(type(k) is str for k in got):
        return False
    return all(k in got and same(got[k], v) for k, v in expected.items())


def _same_applied(got, expected: dict) -> bool:
    """What a matcher applies: each joint's position the same number (exact types)."""
    return _same_dict(got, expected, lambda a, b: same_numbers(a, b, 1e-12))


def _same_counts(got, expected: dict) -> bool:
    """Rejections by reason: each the same count (exact types)."""
    return _same_dict(got, expected, same_value)


def _show_dict(d) -> str:
    if not isinstance(d, dict):
        return repr(d)
    return "{" + ", ".join(f"{k!r}: {show(v)}" for k, v in d.items()) + "}"


def check_wrong_model(cls) -> Result:
    """Check a ``RttJointStateSubscriber`` subclass that refuses another model's messages whole.

    A JointState that names a joint the body does not have, or none of its
    joints, is refused: nothing is applied, ``summary()["rejected"]`` counts
    it once as ``wrong_model`` and ``applied`` does not count it.  Any other
    message is handled as before (the matcher still rejects bad entries).
    """

    def run_messages(messages, kind=cls):
        """``(the tank's joint positions, rounded, summary())`` after a fresh controller (``kind``) on a fresh tank
        applied each message (the learner's class: where it lives, :func:`observe`)."""
        sent = [(list(m.name), list(m.position)) for m in messages]
        got = observe(_applied, cls, sent) if kind is cls else _applied(kind, sent)
        if got is None:
            raise CaseFailed(
                f"{cls.__name__}.configure() returned False.",
                "keep RttJointStateSubscriber.configure: return super().configure(config).",
            )
        return got

    def expect(label, messages, applied, rejected, positions, hint, hidden=False):
        sent = "; ".join(f"{show(list(m.name))} {show(list(m.position))}" for m in messages)
        call = label if hidden else f"{cls.__name__}.update_joint_state() for {sent} ({label})"

        def run():
            got, summary = run_messages(messages)
            summary = summary if type(summary) is dict else {}
            # no hints of their own below: the grader gives the case's (grader._failed)
            if not (same_value(summary.get("applied"), applied) and _same_counts(summary.get("rejected"), rejected)):
                raise CaseFailed(
                    f"{call} gave applied={summary.get('applied')!r}, rejected={summary.get('rejected')!r}"
                    f"; expected applied={applied}, rejected={rejected}."
                )
            if got != positions:
                raise CaseFailed(f"{call} left the tank at {got}, expected {positions}.")

        return Case(call, run, hint, hidden)

    def hidden_cases(rng):
        """Random runs of messages, the tank's, the crane's and mixed ones, judged by the lesson's subscriber
        (what it applies and counts: its frozen copy, ``app/reference``) plus the statement's rule (another model's
        message is refused whole).  The first run also has the two messages of :func:`_sure_messages`, each at a
        drawn place."""
        from tutorial.app.reference.joint_state_subscriber import RttJointStateSubscriber

        for k in range(8):
            run = _random_run(rng)
            for sure in _sure_messages(rng) if k == 0 else ():
                run.insert(rng.randrange(len(run) + 1), sure)
            messages = [message(names, positions) for names, positions in run]
            ours = [m for m in messages if m.name and all(n in TANK for n in m.name)]
            refused = len(messages) - len(ours)
            positions, summary = run_messages(ours, RttJointStateSubscriber)
            rejected = dict(summary["rejected"], **({"wrong_model": refused} if refused else {}))
            yield expect(
                "a random run of the tank's, the crane's and mixed messages",
                messages,
                summary["applied"],
                dict(sorted(rejected.items())),
                positions,
                "follow each rule of the statement, for every message, in order.",
                True,
            )

    message = _message
    zero = {"TURRET_Y": 0.0, "TURRET_P": 0.0}
    rng = hidden_random("3.1")  # while grading: this learner's own runs of messages
    return grade(
        "Exercise 3.1, refuse another model's message",
        [
            expect(
                "the tank's own message",
                [message(TANK, [0.3, 0.2])],
                1,
                {},
                {"TURRET_Y": 0.3, "TURRET_P": 0.2},
                "a message of this body's joints is applied as before.",
            ),
            expect(
                "the tank's joints, reordered",
                [message(["TURRET_P", "TURRET_Y"], [0.2, 0.3])],
                1,
                {},
                {"TURRET_Y": 0.3, "TURRET_P": 0.2},
                "order does not matter: the names are all the tank's.",
            ),
            expect(
                "only one of the tank's joints",
                [message(["TURRET_P"], [0.2])],
                1,
                {},
                {"TURRET_Y": 0.0, "TURRET_P": 0.2},
                "a message naming some of this body's joints (and nothing else) is this body's: apply it, "
                "as a robot that publishes its joints in groups does.",
            ),
            expect(
                "the crane's message",
                [message(["SLEW", "LUFF", "TROLLEY"], [0.5, 0.2, 1.0])],
                0,
                {"wrong_model": 1},
                zero,
                "none of these names is a joint of the body (self.body.joint_names): refuse it whole, "
                "count self.rejected['wrong_model'] += 1, and do not call super().update_joint_state().",
            ),
            expect(
                "one of the tank's joints and one unknown",
                [message(["TURRET_Y", "GUN"], [0.3, 0.1])],
                0,
                {"wrong_model": 1},
                zero,
                "one unknown name is enough: the message is from another model.",
            ),
            expect(
                "an empty message",
                [message([], [])],
                0,
                {"wrong_model": 1},
                zero,
                "a message that names none of the body's joints is not this body's.",
            ),
            expect(
                "the tank's, with a NaN",
                [message(TANK, [math.nan, 0.2])],
                1,
                {"not_finite": 1},
                {"TURRET_Y": 0.0, "TURRET_P": 0.2},
                "a message of this body stays with the matcher, which rejects the NaN entry alone.",
            ),
            expect(
                "the crane's message, twice",
                [message(["SLEW", "LUFF"], [0.5, 0.2]), message(["TROLLEY"], [1.0])],
                0,
                {"wrong_model": 2},
                zero,
                "count every refused message: self.rejected['wrong_model'] += 1, not = 1.",
            ),
            expect(
                "the crane's, then the tank's",
                [message(["SLEW"], [0.5]), message(TANK, [0.4, 0.1])],
                1,
                {"wrong_model": 1},
                {"TURRET_Y": 0.4, "TURRET_P": 0.1},
                "after refusing one message, the next good one is applied.",
            ),
            *(hidden_cases(rng) if rng else ()),
        ],
    )


def _message(names, positions):
    """A ``sensor_msgs/JointState`` naming ``names`` at ``positions`` (rad)."""
    from sensor_msgs.msg import JointState

    msg = JointState()
    msg.name, msg.position = list(names), [float(p) for p in positions]
    return msg


def _applied(cls, sent) -> tuple[dict, object] | None:
    """A fresh ``cls()`` configured on a fresh tank, given a JointState of each ``(names, positions)`` of ``sent``
    on this thread: ``(the tank's joint positions rounded to 1e-9 rad, its summary())``; None when its
    ``configure()`` returned False."""
    import rclpy

    from tutorial.core.controller import ControllerConfig

    body = _tank()
    node = rclpy.create_node("exercise_check_wrong_model")
    try:
        controller = cls()
        if not controller.configure(ControllerConfig(name="Strict", body=body, node=node)):
            return None
        for names, positions in sent:
            controller.update_joint_state(_message(names, positions))
        summary = controller.summary()
        controller.unconfigure()
    finally:
        node.destroy_node()
    return {k: round(v, 9) for k, v in body.joint_positions().items()}, summary


# The experiments these checks have the kernel that holds the class run while grading (grader.EXPERIMENTS),
# listed here rather than decorated: make mutate leaves a decorated function alone.
experiments(_applied)
