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
"""

from __future__ import annotations

import math

from tutorial.exercises.capture import CapturingNode
from tutorial.exercises.grader import Case, CaseFailed, Result, grade, not_done, show

DURATION = 2.0  # s of simulated time per checked run


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

    def at(self, seconds: float):
        """``(qpos, root position, root quaternion w x y z, qvel, qfrc_actuator)`` at the step of ``seconds``.

        None when no step of the run is at ``seconds``.
        """
        return self.controller.states.get(round(seconds / self.controller.io.time_step))


# A drive that turns the tank on the spot, left, from 0.2 s: the pose's orientation then changes (the
# demo drive only goes straight in the check's 2 s, where any quaternion near identity passes).
TURN_SCRIPT = ((0.2, (0.0, 0.0, 0.0, 0.0)), (10.0, (0.8, 0.0, 0.0, 0.0)))


def _drive(name: str, cls, parameters: dict, script=None):
    """Run the scripted drive with ``cls`` attached as ``name``; ``(capturing node, probe, app)``.

    Raises:
        tutorial.app.app.ControllerError: the learner's controller refused to configure (or raised there).
    """
    import rclpy

    from tutorial.controllers.tank_controller import RttTankController
    from tutorial.joystick.scripted import ScriptedJoy
    from tutorial.notebook.runs import load, run_headless

    project = load("tank_world.yaml").with_controller("Tank", name, cls, parameters)
    node = CapturingNode(rclpy.create_node("exercise_check"))
    probe = _Probe()
    tank = RttTankController()
    summary, app = run_headless(
        project,
        DURATION,
        node=node,
        attach=[
            ("Tank", "ScriptedJoy", ScriptedJoy(tank, script=script)),
            ("Tank", "RttTankController", tank),
            ("Tank", "Probe", probe.controller),
        ],
    )
    if summary.get("error"):
        if "NotImplementedError" in summary["error"]:
            raise NotImplementedError
        raise CaseFailed("the simulation failed: " + summary["error"].strip().splitlines()[-1])
    return node, probe, app


def _stamp(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def check_selected_joints(cls) -> Result:
    """Check a ``RttJointStatePublisher`` subclass with a ``joints`` parameter.

    ``joints`` is a string of joint names separated by commas (spaces around
    a name are ignored); the publisher publishes those joints only, in that
    order, with the right values; an empty string means every joint; a name
    the body does not have makes ``configure`` refuse.
    """
    from tutorial.app.app import ControllerError
    from tutorial.interfaces.joint_state import joint_state_topic

    def published(joints: str, rate: float):
        node, probe, app = _drive("Selected", cls, {"joints": joints, "rate": rate})
        pubs = node.published(joint_state_topic("Tank"))
        if len(pubs) != 1:
            raise CaseFailed(
                f"with joints={joints!r} the controller made {len(pubs)} publishers of "
                f"{joint_state_topic('Tank')}, expected 1.",
                "let RttJointStatePublisher.configure "
                "create it: call super().configure(config) and check what it returns.",
            )
        return pubs[0].messages(), probe, app

    def selects(joints: str, expected: list[str], rate: float = 50.0, hint: str = ""):
        call = f"{cls.__name__} with joints={joints!r}, rate={rate}"

        def run():
            messages, probe, app = published(joints, rate)
            body = app.bodies["Tank"]
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
                    true = float(state[0][body.joint(name).info.qpos_adr])
                    if abs(q - true) > 1e-9:
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
                        true = float(source[body.joint(name).info.dof_adr])
                        if abs(v - true) > 1e-9:
                            raise CaseFailed(
                                f"{call}: at t = {_stamp(msg):.3f} s {name}'s {field} was published as "
                                f"{v:.6f} {unit}, but the simulation had {true:.6f} {unit}.",
                                f"a joint's {field} comes from its own dof address (qvel, qfrc_actuator), "
                                "in the order of the names you publish: not from its qpos address.",
                            )

        return Case(call, run, hint)

    def refuses(joints: str):
        call = f"{cls.__name__} with joints={joints!r}"
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
                return
            raise CaseFailed(f"{call} was accepted, but the tank has no joint {joints.split(',')[0].strip()!r}.")

        return Case(call, run, hint)

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
        ],
    )


def check_pose_publisher(cls) -> Result:
    """Check a controller that publishes the body's root pose (``geometry_msgs/PoseStamped``).

    Topic ``/<body>/pose``; ``rate`` Hz of simulated time (default 10), the
    first at t = 0; ``header.frame_id`` ``world``; stamp = simulation time;
    position in m and orientation (x, y, z, w, ROS's order) of the root link.
    """
    call = f"{cls.__name__} on the Tank, scripted drive of {DURATION} s"
    turning = f"{cls.__name__} with rate=25, the tank turning on the spot"
    runs: dict = {}  # one drive per kind serves every case of that kind

    def poses(kind: str = "drive"):
        if kind not in runs:
            from geometry_msgs.msg import PoseStamped

            parameters, script = ({}, None) if kind == "drive" else ({"rate": 25.0}, TURN_SCRIPT)
            node, probe, _ = _drive("PosePublisher", cls, parameters, script)
            pubs = node.published("/Tank/pose")
            if len(pubs) != 1:
                topics = [p.topic for p in node.published()]
                raise CaseFailed(
                    f"{call} published on {topics}, expected one publisher of /Tank/pose.",
                    'name the topic after the body: f"/{config.body_name}/pose".',
                )
            if pubs[0].msg_type is not PoseStamped:
                raise CaseFailed(f"{call} publishes {pubs[0].msg_type.__name__}, expected geometry_msgs/PoseStamped.")
            runs[kind] = (pubs[0].messages(), probe, pubs[0])
        return runs[kind]

    def removed():  # the drive ended with unconfigure()
        poses()[2].require_destroyed(
            f"{cls.__name__}.unconfigure()",
            "in unconfigure(): destroy_publisher(...) of the publisher configure() made (keep the node: "
            "self.node = config.node).",
        )

    def timing(kind: str = "drive", rate: float = 10.0, who: str = call):
        messages, *_ = poses(kind)
        want = round(rate * DURATION)
        if len(messages) < want:
            raise CaseFailed(
                f"{who}: published {len(messages)} poses, expected {want} ({rate:g} Hz for {DURATION} s).",
                "use a PeriodAccumulator(io.time_step, rate) in initialize, with the rate parameter, "
                "and tick() it in control().",
            )
        for k, msg in enumerate(messages[:want]):
            t = _stamp(msg)
            if abs(t - k / rate) > 1e-9:
                raise CaseFailed(
                    f"{who}: pose {k} is stamped {t:.4f} s, expected {k / rate:.4f} s.",
                    f"stamp with simulation time (io.data.time), the first at t = 0, every {1 / rate:g} s: "
                    "read config.parameters['rate'].",
                )

    want = round(10.0 * DURATION)

    def position():
        messages, probe, _ = poses()
        for msg in messages[:want]:
            t = _stamp(msg)
            if msg.header.frame_id != "world":
                raise CaseFailed(
                    f"{call}: frame_id is {msg.header.frame_id!r}, expected 'world'.",
                    "the pose is the root link's, in the world frame.",
                )
            pos = probe.at(t)[1]
            p = msg.pose.position
            got = (p.x, p.y, p.z)
            if max(abs(a - b) for a, b in zip(got, pos)) > 5e-3:
                raise CaseFailed(
                    f"{call}: at t = {t:.2f} s the position was {show(list(got))}, the root was at "
                    f"{show([round(float(v), 4) for v in pos])} m.",
                    "io.body.root_pose() gives the root's (position, quaternion).",
                )

    def orientation(kind: str = "drive", who: str = call):
        messages, probe, _ = poses(kind)
        turned = 0.0
        for msg in messages:
            t = _stamp(msg)
            quat = probe.at(t)[2]
            turned = max(turned, abs(2 * math.atan2(float(quat[3]), float(quat[0]))))
            o = msg.pose.orientation
            got, expected = (o.x, o.y, o.z, o.w), (quat[1], quat[2], quat[3], quat[0])
            if not _same_rotation(got, expected):
                raise CaseFailed(
                    f"{who}: at t = {t:.2f} s the orientation (x, y, z, w) was "
                    f"{show([round(v, 4) for v in got])}, expected "
                    f"{show([round(float(v), 4) for v in expected])}.",
                    "ROS orders a quaternion x, y, z, w; MuJoCo (root_pose) orders it w, x, y, z, "
                    "and the pose is the root's own (io.body.root_pose()), as it turns.",
                )
        if kind == "turn":
            assert turned > 0.3, f"the check's own drive did not turn the tank ({turned:.3f} rad)"

    return grade(
        "Exercise 2.2, publish the pose",
        [
            Case(f"{call}: 10 Hz from t = 0, stamped with simulation time", timing),
            Case(f"{call}: the root's position, frame world", position),
            Case(f"{call}: the root's orientation", orientation),
            Case(f"{turning}: 25 Hz from t = 0", lambda: timing("turn", 25.0, turning)),
            Case(f"{turning}: the root's orientation as it turns", lambda: orientation("turn", turning)),
            Case(f"{cls.__name__}.unconfigure()", removed),
        ],
    )


def _same_rotation(a, b, tol: float = 1e-2) -> bool:
    """Two unit quaternions (x, y, z, w) give the same rotation (q and -q do)."""
    if not all(math.isfinite(v) for v in a):
        return False
    dot = abs(sum(x * y for x, y in zip(a, b)))
    return abs(1.0 - dot) <= tol and abs(sum(x * x for x in a) - 1.0) <= 1e-3
