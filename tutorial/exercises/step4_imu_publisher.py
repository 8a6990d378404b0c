"""Checks for the exercises of notebook 04 (Step 4, the IMU publisher).

Exercise 4.1, the peak of each period: a ``RttImuStatePublisher`` subclass
that also publishes, after each Imu message, the largest horizontal
acceleration any single step of its period read, as ``std_msgs/Float64`` on
``/<body>/peak_acceleration``.
Exercise 4.2, report collisions: a ``RttImuStatePublisher`` subclass that
also publishes ``geometry_msgs/Vector3Stamped`` on ``/<body>/collision``
when a period's mean horizontal acceleration is above ``threshold``, at most
once per ``holdoff`` seconds of simulated time.

Each check runs the tank in its room driven by the demo script "wall" (by
simulated time, deaf to the network, so always the same run), with a probe
that keeps every step's accelerometer reading, captures what the learner's
controller publishes in-process (:mod:`tutorial.exercises.capture`), in
order across its topics, and compares it with what the readings say it
should be; 4.2 also reads its defaults from ``PARAMETERS``.  The checks run
on the calling thread.

While grading (:func:`tutorial.exercises.grader.hidden_random`) each check
also runs hidden cases, drawn from the learner's seed: for 4.1, rates whose
period is no whole number of steps, and a rate of 0 (each step a period);
for 4.2, other rates, thresholds and holdoffs, a period exactly at
threshold and a period whose y part decides; for both, each message published right after its Imu message,
and the publisher's QoS.

The module is over 400 lines and still one job: the two checks share one
scripted run of the tank (``_drive``, ``_Probe``) and its comparisons.
"""

from __future__ import annotations

import math

import numpy as np

from tutorial.exercises.capture import CapturingNode, RecordedNode, publishers_record, scripted_drive
from tutorial.exercises.grader import (
    Case,
    CaseFailed,
    Result,
    expect_qos,
    experiments,
    grade,
    hidden_random,
    observe,
    show,
)

DURATION = 3.0  # s of simulated time per checked run: the tank hits the wall at about 2.05 s
TIME_STEP_NS = 1_000_000  # the tank world's 1 ms step


class _Probe:
    """A controller keeping every step's accelerometer reading, by step number (simulation thread)."""

    def __init__(self):
        from tutorial.core.controller import SimpleController
        from tutorial.interfaces.imu import find_imu

        class ImuProbe(SimpleController):
            def initialize(probe, io):
                probe.io = io
                probe.accel = find_imu(io.body.model, io.body.body_ids)[0]
                probe.readings = []  # (3,) m/s^2 per step, what control() reads in that step
                return True

            def control(probe):
                probe.readings.append(probe.io.data.sensordata[probe.accel].copy())
                return True

        self.controller = ImuProbe()


class _NotingNode(CapturingNode):
    """A :class:`CapturingNode` that also notes, in ``order``, the topic of each message published, in turn."""

    def __init__(self, node):
        super().__init__(node)
        self.order: list[str] = []

    def create_publisher(self, msg_type, topic, qos_profile, **kwargs):
        publisher = super().create_publisher(msg_type, topic, qos_profile, **kwargs)
        publish = publisher.publish

        def noted(msg) -> None:
            self.order.append(topic)
            publish(msg)

        publisher.publish = noted
        return publisher


def _drive(name: str, cls, parameters: dict, script: str = "wall", duration: float = DURATION):
    """The learner's ``cls`` in a drive by the demo script ``script`` (:func:`_drive_record`, where ``cls`` lives:
    :func:`observe`): ``(its publishers, with the topic of each message in turn as their ``order``, every step's
    accelerometer reading)``."""
    record = observe(_drive_record, cls, name, parameters, script, duration)
    node = RecordedNode(record["publishers"])
    node.order = [str(topic) for topic in record["order"]]
    return node, list(record["readings"])


def _drive_record(cls, name: str, parameters: dict, script: str, duration: float) -> dict:
    """:func:`~tutorial.exercises.capture.scripted_drive` by the demo script ``script`` with ``cls`` and the probe,
    as data: ``{"publishers"`` (:func:`~tutorial.exercises.capture.publishers_record`), ``"order"`` (the topic of
    each message published, in turn), ``"readings"`` (every step's accelerometer reading, (3,) m/s^2)``}``."""
    import rclpy

    from tutorial.joystick.demo import SCRIPTS

    node, probe = _NotingNode(rclpy.create_node("exercise_check_imu")), _Probe()
    scripted_drive(name, cls, parameters, node, SCRIPTS[script], duration, probe.controller)
    return {"publishers": publishers_record(node), "order": node.order, "readings": probe.controller.readings}


def _stamp_ns(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def _one_publisher(node, topic: str, msg_type, call: str, hint: str):
    """The one capturing publisher of ``topic``; CaseFailed when there is none, several, or of another type."""
    pubs = node.published(topic)
    if len(pubs) != 1:
        topics = sorted({p.topic for p in node.published()})
        raise CaseFailed(f"{call} made {len(pubs)} publishers of {topic} (its topics: {topics}), expected 1.", hint)
    if pubs[0].msg_type is not msg_type:
        raise CaseFailed(
            f"{call} publishes {pubs[0].msg_type.__name__} on {topic}, expected "
            f"{msg_type.__module__.split('.')[0]}/{msg_type.__name__}.",
            hint,
        )
    return pubs[0]


def _imu_messages(node, call: str):
    from sensor_msgs.msg import Imu

    from tutorial.interfaces.imu import imu_topic

    return _one_publisher(
        node,
        imu_topic("Tank"),
        Imu,
        call,
        "keep publishing the Imu: call super().configure(config) and super().publish() (or super().control()).",
    ).messages()


def _windows(imu_messages) -> list[tuple[int, int]]:
    """The steps each Imu message averages: ``[first, last]`` step numbers, from the stamps."""
    windows, previous = [], -1
    for msg in imu_messages:
        due = _stamp_ns(msg) // TIME_STEP_NS
        windows.append((previous + 1, due))
        previous = due
    return windows


def _horizontal(v) -> float:
    return math.hypot(float(v[0]), float(v[1]))


def _follows(node, topic: str) -> list:
    """For each message published on ``topic``: the index of the Imu message published just before it
    (None when the message just before it was not an Imu message)."""
    from tutorial.interfaces.imu import imu_topic

    imu, count, previous, after = imu_topic("Tank"), 0, None, []
    for published in node.order:
        count += published == imu
        if published == topic:
            after.append(count - 1 if previous == imu else None)
        previous = published
    return after


def _imu_qos(publisher, call: str) -> None:
    """CaseFailed unless ``publisher`` was made with the QoS of ``imu_qos()`` (the statement's)."""
    from tutorial.interfaces.imu import imu_qos

    expect_qos(f"{call}: the publisher of {publisher.topic}", publisher.qos_profile, imu_qos())


def _half_step(rng, low: int, high: int) -> float:
    """A holdoff of ``low`` to ``high`` ms and a half: never a whole number of steps, so no two stamps
    are exactly a holdoff apart (where the float ``self.data.time`` would decide, not the rule)."""
    return (rng.randrange(low, high) + 0.5) / 1000


def _hidden_peak_rates(rng) -> tuple[float, float]:
    """The rates (Hz) of 4.1's hidden runs: one from 6 to 20, one from 20 to 45, drawn as floats, so their periods
    are no whole number of the 1 ms steps."""
    return rng.uniform(6, 20), rng.uniform(20, 45)


def check_peak_publisher(cls) -> Result:
    """Check a ``RttImuStatePublisher`` subclass publishing each period's peak horizontal acceleration.

    Topic ``/<body>/peak_acceleration``, ``std_msgs/Float64``, m/s^2: after
    each Imu message, the largest ``hypot(x, y)`` of the accelerometer's
    reading in any single step of the steps that message averages.
    Hidden cases: two other rates, whose periods are no whole number of
    steps, and a rate of 0 (every step its own period); each peak published
    right after its Imu message; the publisher's QoS ``imu_qos()``.
    """
    from std_msgs.msg import Float64

    runs: dict = {}  # rate -> (Imu messages, peaks, readings, publisher, node): one run serves several cases

    def run(rate: float):
        if rate not in runs:
            call = "it"  # each case names the controller, its rate and the drive
            node, readings = _drive("PeakImuPublisher", cls, {"rate": rate})
            imu = _imu_messages(node, call)
            peaks = _one_publisher(
                node,
                "/Tank/peak_acceleration",
                Float64,
                call,
                "create it in configure: config.node.create_publisher(Float64, "
                'f"/{config.body_name}/peak_acceleration", imu_qos()).',
            ).messages()
            if len(peaks) != len(imu):
                raise CaseFailed(
                    f"{call} published {len(peaks)} peaks and {len(imu)} Imu messages, "
                    "expected one peak after each Imu message.",
                    "publish the peak in publish(), right after super().publish().",
                )
            publisher = node.published("/Tank/peak_acceleration")[0]
            runs[rate] = (imu, [p.data for p in peaks], readings, publisher, node)
        return runs[rate]

    def compare(label: str, rate: float, chosen, hint: str, hidden: bool = False):
        call = label if hidden else f"{cls.__name__} with rate={rate}, the wall script for {DURATION} s ({label})"

        def check():
            imu, peaks, readings, *_ = run(rate)
            for k, ((first, last), got) in enumerate(zip(_windows(imu), peaks)):
                t = _stamp_ns(imu[k]) * 1e-9
                if not chosen(t):
                    continue
                expected = max(_horizontal(readings[s]) for s in range(first, last + 1))
                if not _same(got, expected):
                    mean = _horizontal([imu[k].linear_acceleration.x, imu[k].linear_acceleration.y])
                    raise CaseFailed(
                        f"{call}: the peak published with the Imu message of t = {t:.2f} s was "
                        f"{_num(got)} m/s^2, expected {_num(expected)} (the largest of its "
                        f"{last - first + 1} steps; their mean was {_num(mean)}).",
                        _diagnose(got, mean, readings, first, last) or hint,
                    )

        return Case(call, check, hint, hidden)

    def right_after():
        if _follows(run(20.0)[4], "/Tank/peak_acceleration") != list(range(len(run(20.0)[0]))):
            raise CaseFailed(f"{cls.__name__}: a peak was not published right after its Imu message.")

    hidden = []
    rng = hidden_random("4.1")  # while grading: other rates for this learner, by the same rule
    if rng:
        periods = "each peak covers exactly the steps its Imu message averages: start over in publish()."
        hidden = [
            *(
                compare("every period, at a rate of no whole number of steps", rate, lambda t: True, periods, True)
                for rate in _hidden_peak_rates(rng)
            ),
            compare(
                "every period, at a rate of zero: each step is a period",
                0.0,
                lambda t: True,
                "a rate of zero publishes at every step, each step a period of its own: do not divide by the rate.",
                True,
            ),
            Case(
                "each peak published right after its Imu message",
                right_after,
                "publish the peak in publish(), after super().publish(): the Imu message first, then its peak.",
                True,
            ),
            Case(
                "the QoS of the peak's publisher",
                lambda: _imu_qos(run(20.0)[3], cls.__name__),
                "create the publisher with imu_qos(), as the statement asks.",
                True,
            ),
        ]
    return grade(
        "Exercise 4.1, the peak of each period",
        [
            compare(
                "at rest, t <= 0.5 s",
                20.0,
                lambda t: t <= 0.5,
                "the peak of a period is the largest math.hypot(a[0], a[1]) of its steps' readings.",
            ),
            compare(
                "hitting the wall, t = 2.1 s",
                20.0,
                lambda t: abs(t - 2.1) < 1e-6,
                "the peak of a period is the largest math.hypot(a[0], a[1]) of its steps' readings.",
            ),
            compare(
                "every period", 20.0, lambda t: True, "each peak covers exactly the steps its Imu message averages."
            ),
            compare("every period", 10.0, lambda t: True, "the rate parameter still sets the period."),
            Case(
                f"{cls.__name__}.unconfigure()",
                lambda: _destroyed(run(20.0)[3], f"{cls.__name__}.unconfigure()", "peak_publisher"),
            ),
            *hidden,
        ],
    )


def _destroyed(publisher, call: str, name: str) -> None:
    """CaseFailed unless the controller destroyed ``publisher`` (its ``unconfigure()``, when the run ended)."""
    publisher.require_destroyed(
        call, f"in unconfigure(): self.node.destroy_publisher(self.{name}), then super().unconfigure()."
    )


def _num(value) -> str:
    """A number for a message: 6 significant digits (a peak at rest is a few 1e-4 m/s^2).

    Every value given is a float: a ``std_msgs/Float64``'s ``data`` (rclpy refuses any other type) or one
    the check computed.
    """
    return f"{value:.6g}"


def _same(got, expected: float) -> bool:
    return isinstance(got, float) and math.isfinite(got) and abs(got - expected) <= 1e-9


def _diagnose(got, mean: float, readings, first: int, last: int) -> str:
    """A hint naming the likely mistake, when ``got`` is what a known mistake gives ("" if none)."""

    def largest(steps, norm=_horizontal):
        return max((norm(readings[s]) for s in steps), default=0.0)

    if _same(got, mean):
        return (
            "that is the horizontal part of the period's mean, what the Imu message carries; "
            "the peak is the largest single step's reading: look at "
            "self.data.sensordata[self.accel] in every control()."
        )
    if _same(got, largest(range(first, last + 1), lambda a: float(sum(v * v for v in a)) ** 0.5)):
        return "horizontal means x and y only: math.hypot(a[0], a[1]); z carries gravity."
    if _same(got, largest(range(0, last + 1))) and first > 0:
        return "start over after publishing each peak: set it back to 0."
    if _same(got, largest(range(max(first - 1, 0), last))):
        return (
            "the step that publishes belongs to the period it ends: add its reading before super().control() publishes."
        )
    return ""


def _reports(n: int) -> str:
    return f"{n} report{'' if n == 1 else 's'}"


def check_collision_reporter(cls) -> Result:
    """Check a ``RttImuStatePublisher`` subclass reporting collisions on ``/<body>/collision``.

    ``geometry_msgs/Vector3Stamped``: published when an Imu message's mean
    horizontal acceleration ``hypot(x, y)`` is above ``threshold`` (m/s^2,
    default 20) and no collision was reported in the ``holdoff`` s (default
    0.5) of simulated time before; the stamp and frame are the Imu
    message's, the vector its acceleration's horizontal part ``(x, y, 0)``.
    The defaults are read from the class's ``PARAMETERS``.  Hidden cases:
    other rates, thresholds and holdoffs; a period exactly at threshold (not
    above it); a period whose y part decides (``hypot(x, y)``, not ``x``
    alone nor the larger part); each report published right after its Imu
    message; the publisher's QoS ``imu_qos()``.

    Raises:
        RuntimeError: the check's own run has no period whose y part decides (the check is broken).
    """
    from geometry_msgs.msg import Vector3Stamped

    runs: dict = {}  # parameters -> (node, publisher, Imu messages, the indices of those reported)

    def outcome(parameters: dict, call: str):
        """Run with ``parameters`` (once) and compare the reports with the rule; raise CaseFailed if they differ."""
        key = tuple(sorted(parameters.items()))
        if key not in runs:
            node, _ = _drive("CollisionReporter", cls, parameters)
            imu = _imu_messages(node, call)
            publisher = _one_publisher(
                node,
                "/Tank/collision",
                Vector3Stamped,
                call,
                "create it in configure: config.node.create_publisher("
                'Vector3Stamped, f"/{config.body_name}/collision", imu_qos()).',
            )
            runs[key] = (node, publisher, imu, _compare_reports(call, parameters, imu, publisher.messages()))
        return runs[key]

    def reports(parameters: dict, label: str = ""):
        where = ", ".join(f"{k}={v}" for k, v in parameters.items()) or "default parameters"
        call = label or f"{cls.__name__} with {where}, the wall script for {DURATION} s"
        if label:  # a hidden run: its rule
            hint = "above threshold, then not again for holdoff s of self.data.time: time, not a count of messages."
        else:  # a visible run that raised (a wrong report has a hint of its own)
            hint = "read threshold and holdoff from config.parameters in configure(); report in publish()."
        return Case(call, lambda: outcome(parameters, call), hint, bool(label))

    def exactly_at_threshold(holdoff: float):
        """Threshold: the horizontal mean of one Imu message of the default run; holdoff: less than a period."""
        _, _, imu, _ = outcome({}, cls.__name__)
        outcome({"threshold": _exact_threshold(imu), "holdoff": holdoff}, cls.__name__)

    def y_decides(holdoff: float):
        """Threshold: between a period's larger part and its hypot(x, y) (:func:`_y_threshold`); holdoff: tiny."""
        _, _, imu, _ = outcome({}, cls.__name__)
        outcome({"threshold": _y_threshold(imu), "holdoff": holdoff}, cls.__name__)

    def defaults():
        got = observe(_defaults, cls)
        if got != {"threshold": 20.0, "holdoff": 0.5}:
            raise CaseFailed(
                f"its defaults are {got}, expected threshold 20.0 and holdoff 0.5.",
                'declare them: PARAMETERS = {**RttImuStatePublisher.PARAMETERS, "threshold": (float, 20.0, ...), '
                '"holdoff": (float, 0.5, ...)}.',
            )

    def right_after(parameters: dict):
        node, _, _, reported = outcome(parameters, cls.__name__)
        if _follows(node, "/Tank/collision") != reported:
            raise CaseFailed(f"{cls.__name__}: a report was not published right after its Imu message.")

    hidden = []
    rng = hidden_random("4.2")  # while grading: this learner's own parameters, judged by the same rule
    if rng:
        low, hit, tiny = _hidden_collision_parameters(rng)
        hidden = [
            reports(low, "driving hard: a faster rate, a low threshold, a longer holdoff"),
            reports(hit, "the hit: a slower rate, another threshold and holdoff"),
            Case(
                "a period exactly at threshold is not above it",
                lambda: exactly_at_threshold(tiny),
                "above threshold means hypot(x, y) > threshold: a period exactly at it is no collision.",
                True,
            ),
            Case(
                "a period whose y part decides: hypot(x, y), neither x alone nor the larger part",
                lambda: y_decides(tiny),
                "the horizontal acceleration is math.hypot(a.x, a.y): both parts count.",
                True,
            ),
            Case(
                "each report published right after its Imu message",
                lambda: right_after(low),
                "report in publish(), after super().publish(): the Imu message first, then its report.",
                True,
            ),
            Case(
                "the QoS of the collision publisher",
                lambda: _imu_qos(outcome({}, cls.__name__)[1], cls.__name__),
                "create the publisher with imu_qos(), as the statement asks.",
                True,
            ),
        ]
    return grade(
        "Exercise 4.2, report collisions",
        [
            Case(f"{cls.__name__}.PARAMETERS", defaults),
            reports({}),
            reports({"threshold": 10.0}),
            reports({"threshold": 10.0, "holdoff": 0.1}),
            # driving hard is above 3 m/s^2 for most periods from 0.55 s on: the holdoff runs from the last
            # report, not from the last period above threshold (that would report once and fall silent)
            reports({"threshold": 3.0, "holdoff": 0.12}),
            Case(
                f"{cls.__name__}.unconfigure()",
                lambda: _destroyed(
                    outcome({}, cls.__name__)[1], f"{cls.__name__}.unconfigure()", "collision_publisher"
                ),
            ),
            *hidden,
        ],
    )


def _defaults(cls) -> dict:
    """The defaults ``cls.PARAMETERS`` declares for threshold and holdoff (None for one it lacks)."""
    declared = getattr(cls, "PARAMETERS", {})
    return {name: declared.get(name, (None, None))[1] for name in ("threshold", "holdoff")}


def _hidden_collision_parameters(rng) -> tuple[dict, dict, float]:
    """4.2's hidden parameters: ``(driving hard, the hit, a tiny holdoff in s)``.

    Driving hard: a faster rate (30 to 50 Hz), a low threshold (2.5 to 5 m/s^2) and a holdoff of many periods
    (150.5 to 399.5 ms): time, not a count of messages.  The hit: a slower rate (9.5 to 15 Hz, where the hit's
    period is above 13 m/s^2; below 9.5 Hz it may be diluted to 12), a threshold of 5 to 10 m/s^2 and a holdoff
    of 20.5 to 599.5 ms.  The tiny holdoff (2.5 to 44.5 ms) is shorter than the default period (50 ms): each
    period above is reported.  Every holdoff is a whole number of ms and a half (:func:`_half_step`).
    """
    low = {"rate": rng.uniform(30, 50), "threshold": rng.uniform(2.5, 5), "holdoff": _half_step(rng, 150, 400)}
    hit = {"rate": rng.uniform(9.5, 15), "threshold": rng.uniform(5, 10), "holdoff": _half_step(rng, 20, 600)}
    return low, hit, _half_step(rng, 2, 45)


def _compare_reports(call: str, parameters: dict, imu, got) -> list[int]:
    """CaseFailed unless ``got`` are the reports the rule makes of ``imu``; the indices of the Imu messages reported."""
    threshold, holdoff = parameters.get("threshold", 20.0), parameters.get("holdoff", 0.5)
    reported, last = [], None
    for k, msg in enumerate(imu):
        a, t = msg.linear_acceleration, _stamp_ns(msg)
        if math.hypot(a.x, a.y) > threshold and (last is None or t - last >= holdoff * 1e9):
            reported.append(k)
            last = t
    expected = [imu[k] for k in reported]
    if not expected:
        raise CaseFailed(
            f"{call}: the Imu messages show no collision at all; the tank should have hit the wall at about 2.05 s.",
            "keep RttImuStatePublisher's behaviour: call super().publish().",
        )
    at = [round(_stamp_ns(m) * 1e-9, 3) for m in got]
    want = [round(_stamp_ns(m) * 1e-9, 3) for m in expected]
    if len(got) != len(expected):
        raise CaseFailed(
            f"{call} made {_reports(len(got))}, stamped t = {at} s; expected "
            f"{_reports(len(expected))}, at t = {want} s.",
            "report when hypot(x, y) of the mean is above threshold, and then not "
            "again until holdoff s of simulated time have passed since that report "
            "(a period above threshold that is not reported does not start it again).",
        )
    for report, msg, t in zip(got, expected, want):
        a, stamp, should = msg.linear_acceleration, report.header.stamp, msg.header.stamp
        vector = [report.vector.x, report.vector.y, report.vector.z]
        if (stamp.sec, stamp.nanosec) != (should.sec, should.nanosec):  # nanosec is below 1 s, sec the rest
            raise CaseFailed(
                f"{call}: the report of the Imu message of t = {t} s is stamped sec={stamp.sec}, "
                f"nanosec={stamp.nanosec}; expected sec={should.sec}, nanosec={should.nanosec}.",
                "copy the Imu message's header (stamp and frame_id).",
            )
        if report.header.frame_id != msg.header.frame_id:
            raise CaseFailed(
                f"{call}: the report at t = {t} s has frame_id "
                f"{report.header.frame_id!r}, expected {msg.header.frame_id!r}.",
                "the vector is in the IMU's frame: use the Imu message's frame_id.",
            )
        if not all(abs(g - e) <= 1e-9 for g, e in zip(vector, [a.x, a.y, 0.0])):  # NaN fails
            raise CaseFailed(
                f"{call}: the report at t = {t} s carries {show(vector)}, expected {show([a.x, a.y, 0.0])}.",
                "the vector is the mean acceleration's horizontal part: (x, y, 0).",
            )
    return reported


def _y_threshold(imu) -> float:
    """A threshold that a mean's y part decides: halfway between ``max(|x|, |y|)`` and ``hypot(x, y)`` of the Imu
    message whose hypot is the most above its larger part (at least 5 % above: no float rounding decides)."""
    means = [(m.linear_acceleration.x, m.linear_acceleration.y) for m in imu]
    x, y = max(means, key=lambda v: _horizontal(v) / max(abs(v[0]), abs(v[1]), 1e-300))
    larger = max(abs(x), abs(y))
    if not _horizontal((x, y)) >= 1.05 * larger > 0.0:  # the check's own run is at fault, not the learner's answer
        raise RuntimeError("the Imu messages have no mean whose y part decides whether it is above a threshold")
    return (larger + _horizontal((x, y))) / 2


def _exact_threshold(imu) -> float:
    """The horizontal mean of an Imu message below the largest, the same by every usual way to compute it
    (``math.hypot``, ``math.sqrt(x * x + y * y)``, ``numpy.hypot``, ``numpy.linalg.norm``)."""
    means = sorted(((m.linear_acceleration.x, m.linear_acceleration.y) for m in imu), key=_horizontal, reverse=True)
    for x, y in means:
        h = math.hypot(x, y)
        if h < _horizontal(means[0]) and h == math.sqrt(x * x + y * y) == np.hypot(x, y) == np.linalg.norm([x, y]):
            return h
    raise CaseFailed("the Imu messages have no mean that every way to compute hypot(x, y) gives alike.")


# The experiments these checks have the kernel that holds the class run while grading (grader.EXPERIMENTS),
# listed here rather than decorated: make mutate leaves a decorated function alone.
experiments(_drive_record, _defaults)
