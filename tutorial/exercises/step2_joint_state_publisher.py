"""Checks for the exercises of notebook 02 (Step 2, the joint-state publisher).

Exercise 2.1, publish chosen joints: a ``RttJointStatePublisher`` subclass with a
``joints`` parameter (names separated by commas) that publishes only those, in that order.
Exercise 2.2, publish the pose: a controller publishing the body's root pose as
``geometry_msgs/PoseStamped`` on ``/<body>/pose`` at ``rate`` Hz (default 10), frame ``world``.

Each check runs the tank in its room for a short, scripted drive (the demo
script by simulated time, deaf to the network, so always the same run)
with the learner's controller attached, captures what it publishes
in-process (:mod:`tutorial.exercises.capture`) and compares it with the
simulation's own state at each message's stamp.

While grading (:func:`tutorial.exercises.grader.hidden_random`) each check also
runs hidden cases, drawn from the learner's seed: for 2.1, other choices,
spacings and rates of the tank's joints with the turret moving at random, and
names the tank lacks (``configure`` must log an error with
``config.log.error``); for 2.2, the tank tilted and tumbling in the air (no
gravity) at other rates, stamped past 2 s, and the publisher's QoS.

The module is over 400 lines and still one job: the two checks share one
scripted run of the tank (``_drive``, ``_Probe``) and its comparisons.
"""

from __future__ import annotations

import contextlib
import logging
import math

from tutorial.exercises.capture import CapturingNode, RecordedNode, publishers_record, scripted_drive
from tutorial.exercises.grader import (
    Case,
    CaseFailed,
    Result,
    expect_qos,
    experiments,
    grade,
    hidden_random,
    not_done,
    observe,
    show,
)

DURATION = 2.0  # s of simulated time per checked run
# s of a hidden run of 2.2: it stamps t = 2 s, where the simulation's clock reads a hair under 2 (1.99999999999989)
HIDDEN_DURATION = 2.5
TANK = ["TURRET_Y", "TURRET_P"]  # the tank's joints, in its order


class _Probe:
    """A controller that keeps the simulation's state at every step, by step number (simulation thread)."""

    def __init__(self):
        from tutorial.core.controller import SimpleController

        class Probe(SimpleController):
            def initialize(probe, io):
                probe.io, probe.states = io, {}
                return True

            def control(probe):
                step = round(probe.io.current_time / probe.io.time_step)
                pos, quat = probe.io.body.root_pose()
                data = probe.io.data
                probe.states[step] = (data.qpos.copy(), pos, quat, data.qvel.copy(), data.qfrc_actuator.copy())
                return True

        self.controller = Probe()


class _ProbeRecord:
    """A :class:`_Probe`'s run as :func:`_drive_record` recorded it: the states at the steps that messages were
    stamped at (``at``), and the root's quaternion at every step (``quats``)."""

    def __init__(self, record: dict):
        self.time_step, self.quats = float(record["time_step"]), list(record["quats"])
        self.states = {int(k): v for k, v in dict(record["states"]).items()}

    def at(self, seconds: float):
        """``(qpos, root position, root quaternion w x y z, qvel, qfrc_actuator)`` at the step of ``seconds``.

        None when no step of the run is at ``seconds``.
        """
        return self.states.get(round(seconds / self.time_step))


# A drive that turns the tank on the spot, left, from 0.2 s: the pose's orientation then changes (the
# demo drive only goes straight in the check's 2 s, where any quaternion near identity passes).
TURN_SCRIPT = ((0.2, (0.0, 0.0, 0.0, 0.0)), (10.0, (0.8, 0.0, 0.0, 0.0)))


def _drive(name: str, cls, parameters: dict, script=None, duration: float = DURATION, tumble=None):
    """The learner's ``cls`` in a scripted drive (:func:`_drive_record`, where ``cls`` lives: :func:`observe`):
    ``(its publishers, the probe's states, {joint: (qpos address, dof address)})``.

    ``tumble``: the start of a controller attached first (:func:`_tumble`), or None.

    Raises:
        tutorial.app.app.ControllerError: the learner's controller refused to configure; its ``errors_logged``
            is how many errors its logger (``config.log``) had logged.
    """
    from tutorial.app.app import ControllerError

    record = observe(_drive_record, cls, name, parameters, script, duration, tumble)
    if "refused" in record:
        refused = ControllerError(str(record["refused"]))
        refused.errors_logged = record["logged"]
        raise refused
    joints = {str(k): (int(q), int(d)) for k, (q, d) in dict(record["joints"]).items()}
    return RecordedNode(record["publishers"]), _ProbeRecord(record), joints


def _drive_record(cls, name: str, parameters: dict, script, duration: float, tumble) -> dict:
    """:func:`~tutorial.exercises.capture.scripted_drive` with ``cls`` and the probe, as data: ``{"publishers"``
    (:func:`~tutorial.exercises.capture.publishers_record`), ``"joints"`` (the tank's, ``{name: (qpos address,
    dof address)}``), ``"time_step"`` (s), ``"states"`` (the probe's, ``{step: state}``, at each step a message
    was stamped at), ``"quats"`` (the root's, w x y z, every step)``}``; or ``{"refused": why, "logged": n}``
    when ``cls`` refused to configure (``n`` errors its ``config.log`` logged).

    Raises:
        tutorial.app.app.ControllerError: the class's stub raised ``NotImplementedError`` there.
    """
    import rclpy

    from tutorial.app.app import ControllerError

    node, probe = CapturingNode(rclpy.create_node("exercise_check")), _Probe()
    first = _tumbling(tumble) if tumble is not None else None
    with _errors_logged(f"rtt.{name}") as logged:  # config.log, the controller's own logger
        try:
            app = scripted_drive(name, cls, parameters, node, script, duration, probe.controller, first=first)
        except ControllerError as exc:
            if not_done(exc):
                raise
            return {"refused": str(exc), "logged": len(logged)}
    publishers, states = publishers_record(node), probe.controller.states
    dt = probe.controller.io.time_step
    stamped = {round(_stamp(m) / dt) for p in publishers for m in p["messages"] if hasattr(m, "header")}
    body = app.bodies["Tank"]
    return {
        "publishers": publishers,
        "joints": {n: (body.joint(n).info.qpos_adr, body.joint(n).info.dof_adr) for n in body.joint_names},
        "time_step": dt,
        "states": {step: states[step] for step in sorted(stamped) if step in states},
        "quats": [state[2] for state in states.values()],
    }


def _stamp(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def _turret_script(rng):
    """A drive of random sticks (``ScriptedJoy``'s script): the tank rolls, the turret turns and tilts, either way."""

    def sticks():  # the right stick well off its centre: both turret joints move
        turn, tilt = (rng.choice((-1.0, 1.0)) * rng.uniform(0.3, 0.8) for _ in range(2))
        return (0.0, rng.uniform(-0.5, 0.5), turn, tilt)

    return ((0.1, (0.0, 0.0, 0.0, 0.0)), (0.9, sticks()), (1.0, sticks()))


def _tumble(rng) -> dict:
    """A hidden run's start in the air: ``{"quat", "spin", "place", "drift"}``, drawn from ``rng``.

    ``quat``: w x y z, a unit quaternion, every orientation equally likely; ``spin``: rad/s about x, y, z,
    at least 1 and at most 2 about both horizontal axes (either way), so the pose tilts far from upright;
    ``place``: m, a tank's length above the floor; ``drift``: m/s, slow.
    """
    quat = [rng.gauss(0.0, 1.0) for _ in range(4)]
    quat = [v / math.sqrt(sum(q * q for q in quat)) for v in quat]
    return {
        "quat": quat,
        "spin": [rng.choice((-1.0, 1.0)) * rng.uniform(1.0, 2.0) for _ in range(2)] + [rng.uniform(-2.0, 2.0)],
        "place": [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), 1.0],
        "drift": [rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.05, 0.05)],
    }


def _tumbling(start: dict):
    """A controller that turns gravity off and puts the tank in the air at t = 0 (``start``: :func:`_tumble`'s)."""
    from tutorial.core.controller import SimpleController

    class Tumble(SimpleController):
        def initialize(self, io):
            model = io.body.model  # this run's own
            model.opt.gravity[:] = 0.0
            joint = model.body_jntadr[io.body.root_id]  # the root's free joint
            q, v = model.jnt_qposadr[joint], model.jnt_dofadr[joint]
            io.data.qpos[q : q + 7] = start["place"] + start["quat"]  # position, then the quaternion w x y z
            io.data.qvel[v : v + 6] = start["drift"] + start["spin"]
            io.body.notify_kinematic_state_change()
            return True

    return Tumble()


@contextlib.contextmanager
def _errors_logged(name: str):
    """The records of level ERROR or more that logger ``name`` (or a child) handles while the block runs."""
    records: list[logging.LogRecord] = []
    handler = logging.Handler(logging.ERROR)
    handler.emit = records.append
    logger = logging.getLogger(name)
    logger.addHandler(handler)
    try:
        yield records
    finally:
        logger.removeHandler(handler)


# The rates of 2.1's hidden runs, Hz: each period a whole number of the tank's 1 ms steps.
HIDDEN_CHOICE_RATES = (12.5, 20.0, 25.0, 40.0, 100.0, 200.0)
# Kinds of joint name the tank lacks, each with how to draw one (from the random source given).
LACKING = {
    "a joint of the tank in the wrong case": lambda rng: rng.choice((str.lower, str.capitalize))(rng.choice(TANK)),
    "a part of a joint's name": lambda rng: rng.choice(("TURRET", "TURRET_", "URRET_P", "RRET_Y", "_P")),
    "another robot's joint": lambda rng: rng.choice(("GUN", "SLEW", "LUFF", "TROLLEY", "WHEEL_L")),
}


def _spaced(rng, names) -> str:
    """``names`` joined by commas, each with 0 to 2 spaces drawn on either side."""
    return ",".join(" " * rng.randrange(3) + name + " " * rng.randrange(3) for name in names)


def _hidden_choices(rng) -> list:
    """Four hidden runs of 2.1: ``(joints parameter, the names expected, rate in Hz, ScriptedJoy script)``.

    Each chooses 0 to 2 of the tank's joints in a random order (none: every joint is expected), spaced at
    random, at a rate of :data:`HIDDEN_CHOICE_RATES`, with the turret moving (:func:`_turret_script`).
    """
    runs = []
    for _ in range(4):
        chosen = rng.sample(TANK, rng.randrange(3))
        runs.append((_spaced(rng, chosen), chosen or TANK, rng.choice(HIDDEN_CHOICE_RATES), _turret_script(rng)))
    return runs


def _hidden_lacking(rng) -> list:
    """One hidden refusal of 2.1 per kind of :data:`LACKING`: ``(kind, joints parameter)``.

    The parameter names 1 or 2 of the tank's joints and one name it lacks, put before a known name (not only
    the last name is checked), spaced at random.
    """
    cases = []
    for kind, draw in LACKING.items():
        known = rng.sample(TANK, rng.randrange(1, 3))
        known.insert(rng.randrange(len(known)), draw(rng))
        cases.append((kind, _spaced(rng, known)))
    return cases


def check_selected_joints(cls) -> Result:
    """Check a ``RttJointStatePublisher`` subclass with a ``joints`` parameter.

    ``joints`` is a string of joint names separated by commas (spaces around
    a name are ignored); the publisher publishes those joints only, in that
    order, with the right values (position, velocity, effort), at the
    ``rate`` parameter; an empty string means every joint; a name the body
    does not have makes ``configure`` log an error (``config.log.error``) and
    return False.
    """
    from tutorial.app.app import ControllerError
    from tutorial.interfaces.joint_state import joint_state_topic

    def published(joints: str, rate: float, script=None):
        node, probe, addresses = _drive("Selected", cls, {"joints": joints, "rate": rate}, script)
        pubs = node.published(joint_state_topic("Tank"))
        if len(pubs) != 1:
            raise CaseFailed(
                f"with joints={joints!r} the controller made {len(pubs)} publishers of "
                f"{joint_state_topic('Tank')}, expected 1.",
                "let RttJointStatePublisher.configure "
                "create it: call super().configure(config) and check what it returns.",
            )
        return pubs[0].messages(), probe, addresses

    def selects(joints: str, expected: list[str], rate: float = 50.0, hint: str = "", script=None, label=None):
        call = label or f"{cls.__name__} with joints={joints!r}, rate={rate}"

        def run():
            messages, probe, addresses = published(joints, rate, script)
            want = round(rate * DURATION)
            if len(messages) < want:
                raise CaseFailed(
                    f"{call} published {len(messages)} messages in {DURATION} s, expected at least {want}.",
                    "keep publishing through RttJointStatePublisher.control().",
                )
            for msg in messages[:want]:
                names = list(msg.name)
                if names != expected:
                    raise CaseFailed(f"{call} published name={names}, expected {expected}.", hint)
                state = probe.at(_stamp(msg))
                if state is None:
                    raise CaseFailed(f"{call}: a message stamped {_stamp(msg):.3f} s, not a step of the run.")
                for name, q in zip(names, msg.position):
                    true = float(state[0][addresses[name][0]])
                    if not abs(q - true) <= 1e-9:  # a NaN position fails
                        raise CaseFailed(
                            f"{call}: at t = {_stamp(msg):.3f} s {name} was published as "
                            f"{q:.6f} rad, but the simulation had {true:.6f} rad.",
                            "each joint's position must come from its own qpos address, in the "
                            "order of the names you publish.",
                        )
                if not (len(msg.position) == len(msg.velocity) == len(msg.effort) == len(names)):
                    raise CaseFailed(
                        f"{call}: name, position, velocity and effort have lengths "
                        f"{len(names)}, {len(msg.position)}, {len(msg.velocity)}, {len(msg.effort)}.",
                        "a JointState's arrays must all be as long as its name list.",
                    )
                for field, values, source, unit in (
                    ("velocity", msg.velocity, state[3], "rad/s"),
                    ("effort", msg.effort, state[4], "N m"),
                ):
                    for name, v in zip(names, values):
                        true = float(source[addresses[name][1]])
                        if not abs(v - true) <= 1e-9:
                            raise CaseFailed(
                                f"{call}: at t = {_stamp(msg):.3f} s {name}'s {field} was published as "
                                f"{v:.6f} {unit}, but the simulation had {true:.6f} {unit}.",
                                f"a joint's {field} comes from its own dof address (qvel, qfrc_actuator), "
                                "in the order of the names you publish: not from its qpos address.",
                            )

        return Case(call, run, hint, hidden=label is not None)

    def refuses(joints: str, label=None):
        call = label or f"{cls.__name__} with joints={joints!r}"
        hint = (
            "configure() should return False when a name is not in config.body.joint_names "
            "(and log why with config.log.error)."
        )

        def run():
            try:
                published(joints, 50.0)
            except ControllerError as exc:
                if not_done(exc):
                    raise
                if label and not exc.errors_logged:  # a hidden case also holds the statement's config.log.error(...)
                    raise CaseFailed(f"{call}: configure returned False without config.log.error(...).") from None
                return
            unknown = next((n for n in (n.strip() for n in joints.split(",")) if n and n not in TANK), joints)
            raise CaseFailed(f"{call} was accepted, but the tank has no joint {unknown!r}.")

        return Case(call, run, hint, hidden=label is not None)

    def hidden_cases(rng):
        """The statement's rules on this learner's draws (:func:`_hidden_choices`, :func:`_hidden_lacking`)."""
        label = "the tank's joints chosen at random (or none), in a random order and spacing, at a random rate"
        for joints, expected, rate, script in _hidden_choices(rng):
            yield selects(
                joints,
                expected,
                rate,
                "those joints only, in that order, each with its own position, velocity and effort, at the rate.",
                script,
                label + ", the turret moving",
            )
        for kind, joints in _hidden_lacking(rng):
            yield refuses(joints, f"a name the tank lacks ({kind}): configure logs an error, returns False")

    rng = hidden_random("2.1")  # while grading: this learner's own choices, rates, drives and wrong names
    return grade(
        "Exercise 2.1, publish chosen joints",
        [
            selects(
                "TURRET_P,TURRET_Y",
                ["TURRET_P", "TURRET_Y"],
                hint="publish the joints in the order the parameter names them.",
            ),
            selects("TURRET_Y", ["TURRET_Y"], hint="only the named joints: one name, one entry."),
            selects(" TURRET_P , TURRET_Y ", ["TURRET_P", "TURRET_Y"], hint="spaces around a name are ignored."),
            selects("", ["TURRET_Y", "TURRET_P"], hint="an empty string means every joint, as before."),
            selects("TURRET_P", ["TURRET_P"], rate=10.0, hint="the rate parameter still applies."),
            refuses("GUN"),
            refuses("TURRET_Y,GUN"),
            *(hidden_cases(rng) if rng else ()),
        ],
    )


# The rates of 2.2's hidden runs, Hz, by kind: a whole and a fractional number of hertz, each period a whole
# number of the tank's 1 ms steps (so each stamp is a step's exact time).
HIDDEN_POSE_RATES = {"whole": (4.0, 8.0, 20.0, 40.0, 50.0, 100.0, 250.0), "fractional": (2.5, 12.5, 62.5)}


def check_pose_publisher(cls) -> Result:
    """Check a controller that publishes the body's root pose (``geometry_msgs/PoseStamped``).

    Topic ``/<body>/pose``; ``rate`` Hz of simulated time (default 10), the
    first at t = 0; ``header.frame_id`` ``world``; stamp = simulation time
    (whole seconds in ``sec``, the rest in ``nanosec``); position in m and
    orientation (x, y, z, w, ROS's order) of the root link, tilted or not;
    QoS the joint state's; ``unconfigure()`` destroys the publisher.
    """
    call = f"{cls.__name__} on the Tank, scripted drive of {DURATION} s"
    turning = f"{cls.__name__} with rate=25, the tank turning on the spot"
    # kind: (rate, script, duration, tumble); one run per kind serves every case of that kind
    plans: dict = {"drive": (10.0, None, DURATION, None), "turn": (25.0, TURN_SCRIPT, DURATION, None)}
    runs: dict = {}

    def poses(kind: str = "drive"):
        if kind not in runs:
            from geometry_msgs.msg import PoseStamped

            rate, script, duration, tumble = plans[kind]
            parameters = {} if kind == "drive" else {"rate": rate}  # the drive: the default rate
            node, probe, _ = _drive("PosePublisher", cls, parameters, script, duration, tumble)
            pubs = node.published("/Tank/pose")
            if len(pubs) != 1:
                topics = [p.topic for p in node.published()]
                raise CaseFailed(
                    f"published on {topics}, expected one publisher of /Tank/pose.",
                    'name the topic after the body: f"/{config.body_name}/pose".',
                )
            if pubs[0].msg_type is not PoseStamped:
                raise CaseFailed(
                    f"publishes {pubs[0].msg_type.__name__}, expected geometry_msgs/PoseStamped.",
                    "publish a PoseStamped: the pose with its header (the stamp and the frame).",
                )
            messages = pubs[0].messages()
            runs[kind] = (messages[: round(rate * duration)], messages, probe, pubs[0])
        return runs[kind]

    def removed():  # the drive ended with unconfigure()
        poses()[3].require_destroyed(
            f"{cls.__name__}.unconfigure()",
            "in unconfigure(): destroy_publisher(...) of the publisher configure() made (keep the node: "
            "self.node = config.node).",
        )

    def qos():
        from tutorial.interfaces.joint_state import joint_state_qos

        expect_qos(f"{call}: the publisher", poses()[3].qos_profile, joint_state_qos())

    def timing(kind: str = "drive", who: str = call):
        rate, _, duration, _ = plans[kind]
        messages, *_ = poses(kind)
        if len(messages) < round(rate * duration):
            raise CaseFailed(
                f"{who}: published {len(messages)} poses, expected {round(rate * duration)} "
                f"({rate:g} Hz for {duration} s).",
                "use a PeriodAccumulator(io.time_step, rate) in initialize, with the rate parameter, "
                "and tick() it in control().",
            )
        for k, msg in enumerate(messages):
            t = _stamp(msg)
            if not abs(t - k / rate) <= 1e-9:
                raise CaseFailed(
                    f"{who}: pose {k} is stamped {t:.4f} s, expected {k / rate:.4f} s.",
                    f"stamp with simulation time (io.data.time), the first at t = 0, every {1 / rate:g} s: "
                    "read config.parameters['rate']"
                    + (" (10 Hz when none is given: the default in PARAMETERS)." if kind == "drive" else "."),
                )

    def split(kind: str, who: str):  # a ROS time: whole seconds in sec, nanosec below one second
        for msg in poses(kind)[0]:
            if not 0 <= msg.header.stamp.nanosec < 1_000_000_000:
                raise CaseFailed(f"{who}: a stamp of {msg.header.stamp.sec} s and {msg.header.stamp.nanosec} ns.")

    def position(kind: str = "drive", who: str = call, tol: float = 5e-3):
        messages, _, probe, _ = poses(kind)
        for msg in messages:
            t = _stamp(msg)
            if msg.header.frame_id != "world":
                raise CaseFailed(
                    f"{who}: frame_id is {msg.header.frame_id!r}, expected 'world'.",
                    "the pose is the root link's, in the world frame.",
                )
            pos = probe.at(t)[1]
            p = msg.pose.position
            got = (p.x, p.y, p.z)
            if not max(abs(a - b) for a, b in zip(got, pos)) <= tol:
                raise CaseFailed(
                    f"{who}: at t = {t:.2f} s the position was {show(list(got))}, the root was at "
                    f"{show([round(float(v), 4) for v in pos])} m.",
                    "io.body.root_pose() gives the root's (position, quaternion).",
                )

    def orientation(kind: str = "drive", who: str = call, tol: float = 1e-2):
        _, messages, probe, _ = poses(kind)
        for msg in messages:
            t = _stamp(msg)
            quat = probe.at(t)[2]
            o = msg.pose.orientation
            got, expected = (o.x, o.y, o.z, o.w), (quat[1], quat[2], quat[3], quat[0])
            if not _same_rotation(got, expected, tol):
                raise CaseFailed(
                    f"{who}: at t = {t:.2f} s the orientation (x, y, z, w) was "
                    f"{show([round(v, 4) for v in got])}, expected "
                    f"{show([round(float(v), 4) for v in expected])}.",
                    "ROS orders a quaternion x, y, z, w; MuJoCo (root_pose) orders it w, x, y, z, "
                    "and the pose is the root's own (io.body.root_pose()), as it turns.",
                )

    def own_run(kind: str) -> None:
        """After a kind's cases passed, outside them: the check's own run turned or tilted the tank, as it means to.

        Raises:
            RuntimeError: it did not (the check is broken, not the learner's answer).
        """
        if kind not in runs:  # the learner's cases of this kind did not run it
            return
        quats = runs[kind][2].quats
        if kind == "turn" and not _turned(quats) > 0.3:
            raise RuntimeError(f"the check's own drive did not turn the tank ({_turned(quats):.3f} rad)")
        if plans[kind][3] is not None:  # from the first step on: MuJoCo puts a state it cannot step back upright
            after = quats[1:]
            if not _tilted(after) > 0.3:
                raise RuntimeError(f"the check's own run did not tilt the tank ({_tilted(after):.3f})")
            if not _rotated(after) > 1.0:
                raise RuntimeError(f"the check's own run did not tumble the tank ({_rotated(after):.3f} rad)")

    def hidden_cases(rng):
        """The statement's rules on this learner's draws: the tank tilted and tumbling in the air, at a rate of a
        whole and of a fractional number of hertz, its poses compared to a micrometre; and the publisher's QoS."""
        rules = (  # what a case tests, how (kind, who), its hint
            (
                "its rate, the first at the start, stamped with simulation time",
                timing,
                "publish at the rate parameter, as given (a float), the first at the start, stamped with "
                "io.current_time.",
            ),
            (
                "whole seconds in sec, the rest in nanosec",
                split,
                "a ROS time's nanosec is under a second: stamp_parts(io.current_time) splits it.",
            ),
            (
                "the root's position, frame world",
                lambda kind, who: position(kind, who, 1e-6),
                "io.body.root_pose() gives the root's position, tilted or not.",
            ),
            (
                "the root's orientation, tilted",
                lambda kind, who: orientation(kind, who, 1e-9),
                "copy each of the quaternion's four numbers to its own field (ROS: x, y, z, w; root_pose: w, x, y, "
                "z), whatever the tilt: not a yaw alone.",
            ),
        )
        for kind, rates in HIDDEN_POSE_RATES.items():
            plans[kind] = (rng.choice(rates), None, HIDDEN_DURATION, _tumble(rng))
            who = f"the tank tilted and tumbling in the air, at a rate of its own, a {kind} number of hertz"
            for what, test, hint in rules:
                yield Case(f"{who}: {what}", lambda test=test, kind=kind, who=who: test(kind, who), hint, hidden=True)
            own_run(kind)  # its cases passed (the grader stops at a failure): a broken check raises, told as such
        yield Case(
            "the publisher's QoS, the joint state's",
            qos,
            "create the publisher with joint_state_qos(), as the joint state's publisher does.",
            hidden=True,
        )

    def cases(rng):
        """The visible cases, then the hidden ones; between them, outside the learner's cases, checks of its runs."""
        yield Case(
            f"{call}: 10 Hz from t = 0, stamped with simulation time",
            timing,
            "read the rate from config.parameters['rate'] (10 Hz by default) and publish at it, the first at t = 0.",
        )
        yield Case(f"{call}: the root's position, frame world", position)
        yield Case(f"{call}: the root's orientation", orientation)
        yield Case(f"{turning}: 25 Hz from t = 0", lambda: timing("turn", turning))
        yield Case(f"{turning}: the root's orientation as it turns", lambda: orientation("turn", turning))
        own_run("turn")
        yield Case(f"{cls.__name__}.unconfigure()", removed)
        if rng:
            yield from hidden_cases(rng)

    rng = hidden_random("2.2")  # while grading: this learner's own rates and tumbles
    return grade("Exercise 2.2, publish the pose", cases(rng))


def _turned(quats) -> float:
    """The largest turn (rad) about z of quaternions ``quats`` (w x y z) that turn about z alone: 2 atan2(z, w)."""
    return max(abs(2 * math.atan2(float(q[3]), float(q[0]))) for q in quats)


def _tilted(quats) -> float:
    """The largest ``hypot(x, y)`` of quaternions ``quats`` (w x y z): 0 upright, sin(a / 2) tilted by ``a``."""
    return max(math.hypot(float(q[1]), float(q[2])) for q in quats)


def _rotated(quats) -> float:
    """The largest angle (rad) any of quaternions ``quats`` (w x y z, unit) is turned from the first, about any axis."""
    first = quats[0]
    return max(2 * math.acos(min(1.0, abs(sum(float(a) * float(b) for a, b in zip(q, first))))) for q in quats)


def _same_rotation(a, b, tol: float) -> bool:
    """Two quaternions (x, y, z, w) give the same rotation (q and -q do), ``a`` of unit length.

    ``a``'s squared norm is within 1e-3 of 1; ``b`` is a unit quaternion; ``1 - |a . b|`` at most ``tol``
    passes.  A NaN or an infinity in ``a`` never passes: every comparison with a NaN is false, and an
    infinity makes the dot product infinite or NaN.
    """
    dot = abs(sum(x * y for x, y in zip(a, b)))
    return abs(1.0 - dot) <= tol and abs(sum(x * x for x in a) - 1.0) <= 1e-3


# The experiments these checks have the kernel that holds the class run while grading (grader.EXPERIMENTS),
# listed here rather than decorated: make mutate leaves a decorated function alone.
experiments(_drive_record)
