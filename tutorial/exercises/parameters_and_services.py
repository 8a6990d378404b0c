"""Checks for the exercises of notebook 10 (parameters and services).

Exercise 10.1, judge a rate before it is set: ``judge_rate(parameters) ->
SetParametersResult``, the callback a node runs before parameters are set
(``add_on_set_parameters_callback``).  Of the parameters set together, only
``RttJointStatePublisher.rate`` is its own: a float from 0.0 to 1000.0 Hz,
both included, is accepted; anything else is refused with a reason naming
the parameter and the value.  Every other parameter is left alone.

Exercise 10.2, switch the tracks: ``switch_tracks(switch, request, response)``,
the callback of ``/Tank/enable_tracks`` (``std_srvs/SetBool``): the switch's
``enabled`` set to ``request.data`` under its lock, ``success`` True, the
message ``tracks on``, ``tracks off``, ``tracks already on`` or ``tracks
already off``, and the response returned.

Most cases call the learner's function directly; one of each goes through a
real node (its parameter service's callbacks, a service and a client).
Everything is in-process: nothing waits on the network.
"""

from __future__ import annotations

import math
import threading

from tutorial.exercises.grader import Case, CaseFailed, Result, experiments, grade, hidden_random, observe

RATE = "RttJointStatePublisher.rate"
MAX_RATE = 1000.0  # Hz: the simulation's steps per second
ROUND_TRIP_TIMEOUT = 5.0  # s: a service's answer within the check's own process


def _param(name: str, value):
    from rclpy.parameter import Parameter

    return Parameter(name, value=value)


def _show_list(params) -> str:
    return "[" + ", ".join(f"{p.name}={p.value!r}" for p in params) + "]"


def _verdict(call: str, got, accept: bool, bad=None) -> None:
    """Raise CaseFailed unless ``got`` is a SetParametersResult that accepts (``accept``) or refuses, naming ``bad``.

    A line without a hint of its own gets its case's (grader.CaseFailed).
    """
    from rcl_interfaces.msg import SetParametersResult

    if not isinstance(got, SetParametersResult):
        raise CaseFailed(
            f"{call} returned {got!r}, expected a SetParametersResult (rclpy refuses every set without one).",
            "return SetParametersResult(successful=True) or SetParametersResult(successful=False, reason=...).",
        )
    if got.successful != accept:
        raise CaseFailed(
            f"{call} {'refused' if accept else 'accepted'} it, expected it {'accepted' if accept else 'refused'}."
        )
    if not accept and not (RATE in got.reason and repr(bad.value) in got.reason):
        raise CaseFailed(
            f"{call} refused it with the reason {got.reason!r}, expected a reason naming {RATE} and {bad.value!r}.",
            "the reason is all that rtt-ros2 param set (and ros2 param set) shows: say which parameter and what "
            "value was wrong.",
        )


def _rate_ok(value) -> bool:
    """The statement's rule, written out: a float from 0.0 to MAX_RATE Hz, both included."""
    return isinstance(value, float) and not math.isnan(value) and 0.0 <= value <= MAX_RATE


# Other controllers' parameters, and ROS's own, which a hidden case of 10.1 sets beside (or instead of) RATE.
OTHERS = ("RttRobotModelPublisher.rate", "RttImuStatePublisher.rate", "use_sim_time", "camera.rate")


def _among(rng, value, last: bool = False) -> list:
    """A hidden case of 10.1: RATE set to ``value`` with 1 to 3 of :data:`OTHERS`, each far out of any range,
    RATE anywhere among them (after 2 or 3 of them, if ``last``)."""
    count = rng.randrange(2, 4) if last else rng.randrange(1, 4)
    params = [_param(rng.choice(OTHERS), rng.choice((-1.0, 5000.0, math.nan))) for _ in range(count)]
    params.insert(len(params) if last else rng.randrange(len(params) + 1), _param(RATE, value))
    return params


def _hidden_10_1(rng) -> list[tuple[str, list, str]]:
    """The hidden cases of 10.1, each ``(label, parameters, hint)``: a rate a hair past either end, any rate inside,
    another controller's rate far out, RATE among others (good, bad, and bad after several)."""
    return [
        (
            "a rate a hair above the highest",
            [_param(RATE, math.nextafter(MAX_RATE, math.inf))],  # the next float: any tolerance lets it in
            "both ends are included, nothing past them.",
        ),
        ("a rate a hair below zero", [_param(RATE, -math.ulp(0.0))], "a rate below 0 Hz cannot be kept."),
        (
            "a rate anywhere inside the range",
            [_param(RATE, rng.uniform(0.0, MAX_RATE))],
            "every rate from 0 to the highest is a rate.",
        ),
        (
            "another controller's rate far out of range",
            [_param(rng.choice(OTHERS[:2]), MAX_RATE * rng.uniform(2, 9))],
            "only RATE is this callback's to judge.",
        ),
        (
            "a good rate among other parameters set together",
            _among(rng, rng.uniform(1.0, MAX_RATE)),
            "other parameters are not this callback's to refuse.",
        ),
        (
            "a bad rate among other parameters set together",
            _among(rng, rng.choice((-rng.uniform(1, 99), math.inf, math.nan))),
            "judge every parameter of the list, wherever RATE is in it.",
        ),
        (
            "a bad rate after several other parameters",
            _among(rng, MAX_RATE * rng.uniform(1.5, 9), last=True),
            "judge every parameter of the list, to its end.",
        ),
    ]


def check_judge_rate(func) -> Result:
    """Check ``func(parameters) -> SetParametersResult``; see the module text.

    While grading, hidden cases drawn by the same rules (a rate a hair past
    either end, any rate inside, another controller's rate far out, ours
    among several in any position) are judged by :func:`_rate_ok`.
    """

    def case(params: list, hint: str, label: str | None = None) -> Case:  # a hidden case has a label
        ours = [p for p in params if p.name == RATE]
        bad = next((p for p in ours if not _rate_ok(p.value)), None)
        call = label or f"judge_rate({_show_list(params)})"

        def run():
            _verdict(call, func(list(params)), bad is None, bad)

        return Case(call, run, hint, label is not None)

    def on_a_node() -> None:
        """Through a real node: the parameter keeps its value when the callback refuses, takes it when it accepts."""
        import rclpy

        node = rclpy.create_node("exercise_check_rate")
        try:
            node.declare_parameter(RATE, 50.0)
            node.add_on_set_parameters_callback(func)
            call = f"node.set_parameters([{RATE}=2000.0]) with judge_rate as the node's callback"
            refused = node.set_parameters([_param(RATE, 2000.0)])[0]
            if refused.successful or node.get_parameter(RATE).value != 50.0:
                raise CaseFailed(f"{call} set it, expected it refused and {RATE} still 50.0.")
            call = f"node.set_parameters([{RATE}=25.0]) with judge_rate as the node's callback"
            accepted = node.set_parameters([_param(RATE, 25.0)])[0]
            if not accepted.successful or node.get_parameter(RATE).value != 25.0:
                raise CaseFailed(f"{call} gave {accepted.reason or 'a refusal'!r}, expected {RATE} set to 25.0.")
        finally:
            node.destroy_node()

    rng = hidden_random("10.1")
    hidden = [case(params, hint, label) for label, params, hint in _hidden_10_1(rng)] if rng else []
    return grade(
        "Exercise 10.1, judge a rate before it is set",
        [
            case([_param(RATE, 100.0)], "a rate from 0 to 1000 Hz is accepted: SetParametersResult(successful=True)."),
            case([_param(RATE, 0.0)], "0 Hz is accepted: it publishes every step."),
            case([_param(RATE, MAX_RATE)], "1000 Hz itself is accepted: both ends are included."),
            case(
                [_param(RATE, -5.0)],
                "a negative rate is refused, with a reason naming the parameter and its value.",
            ),
            case([_param(RATE, 1000.5)], "past 1000 Hz the simulation cannot keep up: refused."),
            case([_param(RATE, math.nan)], "NaN is no rate; every comparison with NaN is False."),
            case([_param(RATE, math.inf)], "infinity is past 1000 Hz."),
            case(
                [_param("RttRobotModelPublisher.rate", 5000.0)],
                "another controller's rate is not this callback's to judge: accept it.",
            ),
            case(
                [_param("use_sim_time", True), _param(RATE, -1.0)],
                "judge every parameter of the list, not just the first.",
            ),
            case(
                [_param(RATE, 50.0), _param("RttTankController.joy_timeout", -3.0)],
                "a parameter that is not RATE is accepted, whatever its value.",
            ),
            Case(
                f"node.set_parameters([{RATE}=...]) with judge_rate as the node's callback",
                on_a_node,
                "the node runs judge_rate before it sets anything.",
            ),
            *hidden,
        ],
    )


class TrackSwitch:
    """The tracks' switch: ``enabled`` (bool), written by a service's callback and read by the simulation thread.

    Both threads use it under ``lock`` (a ``threading.Lock``).
    """

    def __init__(self, enabled: bool):
        self.lock = threading.Lock()
        self.enabled = enabled


class _WatchedSwitch(TrackSwitch):
    """A switch that notes every write of ``enabled`` made without its lock held (the check's, not a learner's)."""

    def __init__(self, enabled: bool):
        super().__init__(enabled)
        self.unlocked_writes = 0  # the start's own write is the check's

    @property
    def enabled(self) -> bool:
        return self._enabled

    @enabled.setter
    def enabled(self, value) -> None:
        if not self.lock.locked():
            self.unlocked_writes = getattr(self, "unlocked_writes", 0) + 1
        self._enabled = value


def _said(state: bool, was: bool) -> str:
    word = "on" if state else "off"
    return f"tracks already {word}" if state == was else f"tracks {word}"


def _hidden_sequence(rng, meddled: bool) -> tuple[bool, list[tuple[bool, bool]]]:
    """A hidden case of 10.2: a drawn start (on or off) and 4 to 8 requests, each ``(data, turned)``.

    ``turned``: the check turns the switch over, from another thread with the lock held, just before that
    request; only with ``meddled``, and then before at least one request.
    """
    start = rng.random() < 0.5
    steps = [(rng.random() < 0.5, meddled and rng.random() < 0.5) for _ in range(rng.randrange(4, 9))]
    if meddled:
        k = rng.randrange(len(steps))
        steps[k] = (steps[k][0], True)
    return start, steps


def check_switch_tracks(func) -> Result:
    """Check ``func(switch, request, response) -> response``; see the module text.

    While grading, a hidden case sends a drawn sequence of requests from a
    drawn start, each answer and the switch after it judged by the statement.
    """

    # A failing line without a hint of its own gets its case's (grader.CaseFailed).
    def answered(seen: dict, call: str) -> dict:
        """One request's answer (:func:`_switched`), unless it held the lock or returned no response."""
        if seen["locked"]:
            raise CaseFailed(
                f"{call} returned with switch.lock still held: the simulation thread would wait for it forever.",
                "`with switch.lock:` lets the lock go however the block ends.",
            )
        if not seen["response"]:
            raise CaseFailed(
                f"{call} returned {seen['returned']}, expected the response (a service callback returns it)."
            )
        return seen

    def expect(call: str, seen: dict, was: bool, data: bool) -> None:
        wanted = _said(data, was)
        if seen["enabled"] is not data:
            raise CaseFailed(f"{call} left switch.enabled = {seen['enabled']!r}, expected {data}.")
        if not seen["success"]:
            raise CaseFailed(f"{call} answered success=False, expected True: the switch did what was asked.")
        if seen["message"] != wanted:
            raise CaseFailed(f"{call} answered {seen['message']!r}, expected {wanted!r}.")
        if seen["unlocked_writes"]:
            raise CaseFailed(
                f"{call} set switch.enabled outside `with switch.lock:`.",
                "the simulation thread reads it: write it with the lock held.",
            )

    def case(was: bool, data: bool, hint: str) -> Case:
        call = f"switch_tracks(a switch {'on' if was else 'off'}, SetBool.Request(data={data}))"

        def run():
            (seen,) = observe(_switched, func, was, [(data, False)])
            expect(call, answered(seen, call), was, data)

        return Case(call, run, hint)

    def round_trip() -> None:
        call = "a SetBool client asking a service whose callback is switch_tracks to turn a switch off"
        seen = observe(_switched_by_a_service, func)
        if seen["refused"] is not None:  # rclpy could not send what the callback returned
            raise CaseFailed(f"{call}: rclpy could not send the answer ({seen['refused']}).", "return the response.")
        if not seen["done"]:
            raise CaseFailed(f"{call}: no answer within {ROUND_TRIP_TIMEOUT:.0f} s.", "return the response.")
        expect(call, seen, True, False)

    def sequence(rng, call: str, meddled: bool) -> Case:
        start, steps = _hidden_sequence(rng, meddled)
        hint = "each answer says what this request did to the switch as it was, whoever turned it last."

        def run():
            for (data, _), seen in zip(steps, observe(_switched, func, start, steps)):
                expect(call, answered(seen, call), seen["was"], data)

        return Case(call, run, hint, True)

    rng = hidden_random("10.2")
    return grade(
        "Exercise 10.2, switch the tracks",
        [
            case(True, False, "turned off: enabled False, success True, message 'tracks off'."),
            case(False, False, "'tracks already off': the answer says nothing changed."),
            case(False, True, "turned on: enabled True, success True, message 'tracks on'."),
            case(True, True, "a switch already on stays on, and the answer says so: 'tracks already on'."),
            Case(
                "a SetBool client asking a service whose callback is switch_tracks to turn a switch off",
                round_trip,
                "rclpy sends what the callback returns.",
            ),
            *(
                [
                    sequence(rng, "a drawn sequence of requests, from a drawn start", False),
                    sequence(rng, "a switch also turned by another thread between requests", True),
                ]
                if rng
                else []
            ),
        ],
    )


def _answer(switch: _WatchedSwitch, got, was) -> dict:
    """What a check reads of one answer of ``switch_tracks`` (:func:`_switched`): the switch before (``was``) and
    after, whether the lock is still held, and the response (``returned``: its repr when it is none)."""
    from std_srvs.srv import SetBool

    seen = {"was": was, "locked": switch.lock.locked(), "enabled": switch.enabled}
    seen["response"] = isinstance(got, SetBool.Response)
    seen["returned"] = None if seen["response"] else repr(got)[:2000]
    seen["success"], seen["message"] = (bool(got.success), got.message) if seen["response"] else (None, None)
    seen["unlocked_writes"] = switch.unlocked_writes
    return seen


def _switched(func, start: bool, steps) -> list[dict]:
    """``func`` asked each request of ``steps`` (``(data, turned)``: the switch turned over first, under its lock,
    by this thread), on one switch from ``start``: each answer as :func:`_answer` reads it."""
    from std_srvs.srv import SetBool

    switch, seen = _WatchedSwitch(start), []
    for data, turned in steps:
        if turned:
            with switch.lock:
                switch.enabled = not switch.enabled
        was = switch.enabled
        seen.append(_answer(switch, func(switch, SetBool.Request(data=data), SetBool.Response()), was))
    return seen


def _switched_by_a_service(func) -> dict:
    """A SetBool client asking a service whose callback is ``func`` to turn a switch off, on this thread's executor:
    the answer as :func:`_answer` reads it, with ``done`` (it came within :data:`ROUND_TRIP_TIMEOUT`) and ``refused``
    (rclpy's ``TypeError`` sending it, as text, or None)."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from std_srvs.srv import SetBool

    node = rclpy.create_node("exercise_check_switch")
    executor = SingleThreadedExecutor()
    try:
        switch = _WatchedSwitch(True)
        node.create_service(SetBool, "exercise_check_switch/enable_tracks", lambda req, resp: func(switch, req, resp))
        client = node.create_client(SetBool, "exercise_check_switch/enable_tracks")
        executor.add_node(node)
        future = client.call_async(SetBool.Request(data=False))
        try:
            executor.spin_until_future_complete(future, timeout_sec=ROUND_TRIP_TIMEOUT)
        except TypeError as exc:  # rclpy could not send what the callback returned
            return {"refused": repr(exc)[:2000], "done": False}
        if not future.done():
            return {"refused": None, "done": False}
        return {"refused": None, "done": True, **_answer(switch, future.result(), True)}
    finally:
        executor.shutdown()
        node.destroy_node()


# The experiments these checks have the kernel that holds the class run while grading (grader.EXPERIMENTS),
# listed here rather than decorated: make mutate leaves a decorated function alone.
experiments(_switched, _switched_by_a_service)
