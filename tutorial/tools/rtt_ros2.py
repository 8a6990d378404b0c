"""``rtt-ros2``: the ``ros2`` commands of ROS 2's beginner tutorials, on rclpy (there is no ros2cli wheel).

    rtt-ros2 node list                     rtt-ros2 node info /rtt
    rtt-ros2 topic list [-t]               rtt-ros2 topic info /Tank/joint_state
    rtt-ros2 topic echo /Tank/joint_state [--once]
    rtt-ros2 topic hz /Tank/joint_state [--window 100]
    rtt-ros2 topic pub /joy sensor_msgs/msg/Joy '{axes: [0.0, 1.0]}' [--once | --times N] [--rate 1]
    rtt-ros2 service list [-t]             rtt-ros2 service call /rtt/list_parameters rcl_interfaces/srv/ListParameters
    rtt-ros2 param list /rtt               rtt-ros2 param get /rtt use_sim_time
    rtt-ros2 param set /rtt use_sim_time false
    rtt-ros2 lifecycle get /node           rtt-ros2 lifecycle set /node configure
    rtt-ros2 action list [-t]              rtt-ros2 interface show sensor_msgs/msg/Joy
    rtt-ros2 action send_goal /Tank/turn_turret test_msgs/action/NestedMessage '{nested_field: {float64_value: 1.0}}' -f

(the book's page *The ros2 commands* says what differs, and which of ROS 2's beginner tutorials can be
followed with it).  The same spelling as ``ros2`` and, where a tutorial shows it, the same
output: ``topic echo`` prints each message as YAML followed by ``---``,
``topic hz`` prints ``average rate`` with its min, max, standard deviation
and window each second, ``param get`` prints ``Boolean value is: False``.
It is not ros2cli: there is no daemon (each command discovers for
``--spin-time`` s first), and a command it does not have is refused (those
in ``NOT_HERE`` saying what to do instead).  It does one job, the ``ros2`` command line, in one
module: each command is a function of a few lines, and the table at the end
(``COMMANDS``) maps the words to them.  Discovery stays on this machine unless
``ROS_AUTOMATIC_DISCOVERY_RANGE`` says otherwise, as for every ``rtt-*``
program.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time

from tutorial.ros import env as ros_env
from tutorial.ros import program as ros_program
from tutorial.ros.messages import interface_type, set_fields, to_yaml

NODE_NAME = "rtt_ros2"
NOT_HERE = {  # what ros2 has and this does not: refused, saying what to do instead
    "action info": "rtt-ros2 node info NODE lists each node's action servers and clients",
    "service type": "rtt-ros2 service list -t lists each service with its type",
    "service find": "rtt-ros2 service list -t lists each service with its type",
    "topic find": "rtt-ros2 topic list -t lists each topic with its type",
    "topic bw": "rtt-ros2 topic hz gives the rate; python -m benchmarks.experiments.network measures bandwidth",
    "topic delay": "a message's header stamp against the clock: rtt-ros2 topic echo shows the stamp",
    "param dump": "rtt-ros2 param list NODE, then param get each",
    "param load": "rtt-run PROJECT --ros-args --params-file FILE.yaml sets them at the start",
    "param describe": "rtt-ros2 service call NODE/describe_parameters rcl_interfaces/srv/DescribeParameters "
    "'{names: [NAME]}'",
    "run": "the rtt-* programs are commands of their own (the book's Executables page)",
    "launch": "the launch files are Python: python launch_py/stepN_launch.py (there is no launch_ros wheel)",
    "doctor": "notebook 00 checks the set-up",
}


_STOP = ros_program.StopRequest()  # Ctrl-C and SIGTERM: a flag the waits below look at (installed by main)


def _check_stop() -> None:
    """Raise ``KeyboardInterrupt`` here, at a point of this module's choosing, once Ctrl-C was pressed.

    Not wherever the main thread happens to be (Python's own handler): inside
    rclpy's executor, an interrupted spin can leave a goal's answer half
    taken, and a cancel that follows never hears back.
    """
    if _STOP.requested:
        _STOP.requested = False  # a second Ctrl-C asks again
        raise KeyboardInterrupt


def _pause(seconds: float) -> None:
    """``time.sleep(seconds)`` in slices of 0.1 s at most, each ended by :func:`_check_stop`: a Ctrl-C is
    seen within 0.1 s (a sleep the signal interrupts goes on sleeping once its handler has run)."""
    end = time.monotonic() + seconds
    while True:
        _check_stop()
        left = end - time.monotonic()
        if left <= 0:
            return
        time.sleep(min(0.1, left))


class CommandFailed(Exception):
    """What was asked could not be done (no publisher, no server, no answer in time): exit status 1."""


def main(argv: list[str] | None = None) -> int:
    """``rtt-ros2 VERB SUBVERB ...``; the exit status (0, 1 when what was asked failed, 2 for a bad command)."""
    import rclpy
    from rclpy.exceptions import NameValidationException
    from rclpy.signals import SignalHandlerOptions

    argv = list(sys.argv if argv is None else argv)
    p = _parser()
    args = ros_program.parse_command_line(p, argv)
    asked = " ".join(w for w in (args.verb, getattr(args, "subverb", None)) if w)
    if asked in NOT_HERE:
        print(f"rtt-ros2 {asked}: not here: {NOT_HERE[asked]}", file=sys.stderr)
        return 2
    if args.verb is None or getattr(args, "subverb", None) is None:
        p.print_help()
        return 2
    ros_env.use_localhost_by_default()
    # Ctrl-C sets a flag that every wait here looks at, at least every 0.1 s (_check_stop): the context stays up,
    # so a goal can still be cancelled (rclpy's own handler would shut the context down first).
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    _STOP.install()
    node = rclpy.create_node(NODE_NAME, start_parameter_services=False)
    try:
        return COMMANDS[(args.verb, args.subverb)](node, args)
    except KeyboardInterrupt:
        return 0
    except BrokenPipeError:  # | head: the reader has what it wanted
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - Python's own advice: no second error at exit
        return 0
    except CommandFailed as exc:
        print(f"rtt-ros2: {exc}", file=sys.stderr)
        return 1
    except (ValueError, NameValidationException) as exc:  # a bad type, field, value or name: one line
        print(f"rtt-ros2: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rtt-ros2", description=__doc__.splitlines()[0])
    p.add_argument(
        "--spin-time",
        type=float,
        default=2.0,
        help="seconds of discovery before a list or info is read (default 2: with no daemon, a command "
        "sees only what answered by then)",
    )
    verbs = p.add_subparsers(dest="verb")

    common = argparse.ArgumentParser(add_help=False)  # --spin-time after the command too, as ros2 takes it
    common.add_argument("--spin-time", type=float, default=argparse.SUPPRESS, help=argparse.SUPPRESS)

    def verb(name: str, subverbs: dict[str, callable]) -> None:
        sub = verbs.add_parser(name).add_subparsers(dest="subverb")
        for subverb, add in subverbs.items():
            add(sub.add_parser(subverb, parents=[common]))

    def nothing(_):
        return None

    def node_name(q):
        q.add_argument("node_name", help="a node's full name, e.g. /rtt")

    def topic_name(q):
        q.add_argument("topic_name")

    def show_types(q):
        q.add_argument("-t", "--show-types", action="store_true")

    def echo(q):
        topic_name(q)
        q.add_argument("--once", action="store_true", help="print one message and exit")
        q.add_argument("--timeout", type=float, default=None, help="exit after this many seconds")
        q.add_argument("--truncate-length", type=int, default=128, help="longest array or string printed")

    def hz(q):
        topic_name(q)
        q.add_argument("--window", "-w", type=_positive_int, default=10_000, help="intervals the rate is taken over")
        q.add_argument("--timeout", type=float, default=None, help="exit after this many seconds")

    def pub(q):
        topic_name(q)
        q.add_argument("message_type", help="e.g. sensor_msgs/msg/Joy")
        q.add_argument("values", nargs="?", default="{}", help="the fields, in YAML: '{axes: [0.0, 1.0]}'")
        q.add_argument("-1", "--once", action="store_true", help="publish one message and exit")
        q.add_argument("-t", "--times", type=_positive_int, default=0, help="publish this many and exit")
        q.add_argument("-r", "--rate", type=_positive_float, default=1.0, help="messages per second (default 1)")
        q.add_argument(
            "-w",
            "--wait-matching-subscriptions",
            type=int,
            default=None,
            help="wait for this many subscribers first (default 1 with --once or --times, else 0)",
        )

    def call(q):
        q.add_argument("service_name")
        q.add_argument("service_type", help="e.g. std_srvs/srv/Trigger")
        q.add_argument("values", nargs="?", default="{}", help="the request's fields, in YAML")

    def param_list(q):
        q.add_argument("node_name", nargs="?", default=None, help="a node's full name; none: every node")

    def param_get(q):
        node_name(q)
        q.add_argument("parameter_name")

    def param_set(q):
        param_get(q)
        q.add_argument("value", help="in YAML: true, 3, 2.5, text, [1, 2]")

    def transition(q):
        node_name(q)
        q.add_argument("transition", help="a transition's label: configure, activate, deactivate, cleanup, shutdown")

    def send_goal(q):
        q.add_argument("action_name", help="e.g. /Tank/turn_turret")
        q.add_argument("action_type", help="e.g. test_msgs/action/NestedMessage")
        q.add_argument("goal", nargs="?", default="{}", help="the goal's fields, in YAML")
        q.add_argument("-f", "--feedback", action="store_true", help="print each feedback message")

    def anything(q):  # a command that is not here: its arguments are not read
        q.add_argument("rest", nargs=argparse.REMAINDER)

    subverbs = {
        "node": {"list": nothing, "info": node_name},
        "topic": {"list": show_types, "info": topic_name, "echo": echo, "hz": hz, "pub": pub},
        "service": {"list": show_types, "call": call},
        "param": {"list": param_list, "get": param_get, "set": param_set},
        "lifecycle": {"get": node_name, "set": transition},
        "action": {"list": show_types, "send_goal": send_goal},
        "interface": {"show": lambda q: q.add_argument("type_name", help="e.g. sensor_msgs/msg/Joy")},
    }
    for asked in NOT_HERE:
        name, _, subverb = asked.partition(" ")
        if subverb:
            subverbs.setdefault(name, {})[subverb] = anything
        else:
            anything(verbs.add_parser(name, help="not here"))
    for name, table in subverbs.items():
        verb(name, table)
    return p


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text}: must be 1 or more")
    return value


def _positive_float(text: str) -> float:
    value = float(text)
    if not value > 0 or math.isinf(value):
        raise argparse.ArgumentTypeError(f"{text}: must be a number above 0")
    return value


def _hidden(name: str) -> bool:
    """A name ROS 2 hides (a part starting with ``_``: an action's own topics and services), as ros2 hides it."""
    return any(part.startswith("_") for part in name.split("/"))


def _discover(node, seconds: float) -> None:
    _pause(seconds)  # the graph is filled in by rmw's own thread: nothing to spin meanwhile


def _split(full_name: str) -> tuple[str, str]:
    """``/ns/name`` -> ``("name", "/ns")``."""
    namespace, _, name = full_name.rpartition("/")
    return name, namespace or "/"


def _nodes(node) -> list[str]:
    names = node.get_node_names_and_namespaces()
    full = (f"{ns.rstrip('/')}/{n}" for n, ns in names if not (n == NODE_NAME and ns == "/"))
    return sorted(name for name in full if not _hidden(name))


def node_list(node, args) -> int:
    _discover(node, args.spin_time)
    for name in _nodes(node):
        print(name)
    return 0


def node_info(node, args) -> int:
    from rclpy.action import get_action_client_names_and_types_by_node, get_action_server_names_and_types_by_node

    _discover(node, args.spin_time)
    if args.node_name not in _nodes(node):
        print(f"Unable to find node '{args.node_name}'", file=sys.stderr)
        return 1
    name, namespace = _split(args.node_name)
    sections = (
        ("Subscribers", node.get_subscriber_names_and_types_by_node(name, namespace)),
        ("Publishers", node.get_publisher_names_and_types_by_node(name, namespace)),
        ("Service Servers", node.get_service_names_and_types_by_node(name, namespace)),
        ("Service Clients", node.get_client_names_and_types_by_node(name, namespace)),
        ("Action Servers", get_action_server_names_and_types_by_node(node, name, namespace)),
        ("Action Clients", get_action_client_names_and_types_by_node(node, name, namespace)),
    )
    print(args.node_name)
    for title, items in sections:
        print(f"  {title}:")
        shown = [f"    {item}: {', '.join(types)}" for item, types in sorted(items) if not _hidden(item)]
        print(*shown, sep="\n")  # as ros2 prints it: an empty section is an empty line
    return 0


def _print_names(items, show_types: bool) -> int:
    """``name`` or ``name [type]`` per line, as ``ros2 ... list [-t]`` prints them, hidden ones left out; 0."""
    for name, types in sorted(i for i in items if not _hidden(i[0])):
        print(f"{name} [{', '.join(types)}]" if show_types else name)
    return 0


def topic_list(node, args) -> int:
    _discover(node, args.spin_time)
    return _print_names(node.get_topic_names_and_types(), args.show_types)


def topic_info(node, args) -> int:
    _discover(node, args.spin_time)
    types = dict(node.get_topic_names_and_types()).get(args.topic_name)
    if types is None:
        print(f"Unknown topic '{args.topic_name}'", file=sys.stderr)
        return 1
    print(f"Type: {', '.join(types)}")
    print(f"Publisher count: {node.count_publishers(args.topic_name)}")
    print(f"Subscription count: {node.count_subscribers(args.topic_name)}")
    return 0


def _subscribe(node, topic: str, seconds: float, callback):
    """A subscription to ``topic`` with its publishers' type and a QoS they all offer (as ros2cli chooses it):
    reliable and transient local only when every publisher offers it, so a late joiner gets what was kept."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    end = time.monotonic() + max(seconds, 0.0)
    while True:
        publishers = node.get_publishers_info_by_topic(topic)
        if publishers or time.monotonic() >= end:
            break
        _pause(0.05)
    if not publishers:
        raise CommandFailed(f"no publisher of {topic} seen within {seconds:g} s (its type is taken from one)")
    any_type = interface_type(publishers[0].topic_type)  # whatever the topic carries: only printed or counted
    reliable = all(p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in publishers)
    latched = all(p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in publishers)
    qos = QoSProfile(
        depth=10,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
    )
    return node.create_subscription(any_type, topic, callback, qos)


def _spin_until(node, done, timeout: float | None) -> None:
    import rclpy

    end = math.inf if timeout is None else time.monotonic() + timeout
    while not done() and time.monotonic() < end:
        _check_stop()
        rclpy.spin_once(node, timeout_sec=min(0.1, max(0.0, end - time.monotonic())))


def topic_echo(node, args) -> int:
    printed = []

    def show(msg):
        if args.once and printed:
            return
        print(to_yaml(msg, args.truncate_length), end="")
        print("---", flush=True)
        printed.append(True)

    _subscribe(node, args.topic_name, args.spin_time, show)
    _spin_until(node, lambda: args.once and printed, args.timeout)
    return 0 if printed or not args.once else 1


def topic_hz(node, args) -> int:
    """Each second with new messages: their rate, from their arrival times on this machine's clock, over the
    last ``--window`` intervals (as ``ros2 topic hz`` prints it; nothing while none arrive)."""
    from collections import deque

    arrivals: deque[float] = deque(maxlen=args.window + 1)
    received = [0]

    def arrived(msg):
        arrivals.append(time.monotonic())
        received[0] += 1

    _subscribe(node, args.topic_name, args.spin_time, arrived)
    end = math.inf if args.timeout is None else time.monotonic() + args.timeout
    shown, seen = time.monotonic(), 0
    while time.monotonic() < end:
        _spin_until(node, lambda: False, min(1.0 - (time.monotonic() - shown), end - time.monotonic()))
        shown = time.monotonic()
        if received[0] == seen or len(arrivals) < 2:
            continue  # nothing new since the last line
        seen = received[0]
        gaps = [b - a for a, b in zip(list(arrivals), list(arrivals)[1:], strict=False)]
        print(
            f"average rate: {1.0 / statistics.fmean(gaps):.3f}\n\tmin: {min(gaps):.3f}s max: {max(gaps):.3f}s "
            f"std dev: {statistics.pstdev(gaps):.5f}s window: {len(gaps)}",
            flush=True,
        )
    return 0


def _yaml(values: str, what: str):
    import yaml

    try:
        return yaml.safe_load(values)
    except yaml.YAMLError as exc:
        raise ValueError(f"{what}: not YAML: {' '.join(str(exc).split())}") from None


def topic_pub(node, args) -> int:
    from rclpy.qos import QoSProfile

    cls = interface_type(args.message_type)
    msg = cls()
    set_fields(msg, _yaml(args.values, "the message"))
    publisher = node.create_publisher(cls, args.topic_name, QoSProfile(depth=10))
    times = 1 if args.once else args.times
    wait = args.wait_matching_subscriptions
    wait = (1 if times else 0) if wait is None else wait
    if wait:
        print(f"Waiting for at least {wait} matching subscription(s)...", flush=True)
    while publisher.get_subscription_count() < wait:  # as ros2 topic pub -w: until then (Ctrl-C ends it)
        _pause(0.05)
    print("publisher: beginning loop", flush=True)
    count = 0
    while not times or count < times:
        count += 1
        publisher.publish(msg)
        print(f"publishing #{count}: {msg!r}\n", flush=True)
        if not times or count < times:
            _pause(1.0 / args.rate)
    time.sleep(0.2)  # a reliable message still in the writer's queue: let it go before the node is destroyed
    return 0


def service_list(node, args) -> int:
    _discover(node, args.spin_time)
    return _print_names(node.get_service_names_and_types(), args.show_types)


def _call(node, client, request, timeout: float = 10.0, say_waiting: bool = False):
    if say_waiting and not client.wait_for_service(timeout_sec=1.0):  # as ros2 service call says it
        print("waiting for service to become available...", flush=True)
    if not client.wait_for_service(timeout_sec=timeout):
        raise CommandFailed(f"{client.srv_name}: no server answered within {timeout:g} s")
    return _done(node, client.call_async(request), timeout, f"{client.srv_name}: ")


def service_call(node, args) -> int:
    cls = interface_type(args.service_type, "srv")
    request = cls.Request()
    set_fields(request, _yaml(args.values, "the request"))
    client = node.create_client(cls, args.service_name)
    print(f"requester: making request: {request!r}\n", flush=True)
    response = _call(node, client, request, say_waiting=True)
    print(f"response:\n{response!r}\n", flush=True)
    return 0


def _parameters(node, node_name: str, timeout: float = 10.0):
    from rclpy.parameter_client import AsyncParameterClient

    client = AsyncParameterClient(node, node_name)
    if not client.wait_for_services(timeout_sec=timeout):
        raise CommandFailed(f"{node_name}: no parameter services answered within {timeout:g} s (is the node running?)")
    return client


def _done(node, future, timeout: float = 10.0, what: str = ""):
    """The future's result, ``node`` spun until it came; :class:`CommandFailed` after ``timeout`` s (None: no end)."""
    _spin_until(node, future.done, timeout)
    if not future.done():
        raise CommandFailed(f"{what}no response within {timeout:g} s")
    return future.result()


def param_list(node, args) -> int:
    """``param list NODE``: its parameters, indented; ``param list``: every node's, under its name."""
    if args.node_name is not None:
        result = _done(node, _parameters(node, args.node_name).list_parameters())
        for name in sorted(result.result.names):
            print(f"  {name}")
        return 0
    _discover(node, args.spin_time)
    for other in _nodes(node):
        try:
            result = _done(node, _parameters(node, other, timeout=1.0).list_parameters(), timeout=2.0)
        except CommandFailed:
            continue  # a node without parameter services (ros2 leaves it out too)
        print(f"{other}:")
        for name in sorted(result.result.names):
            print(f"  {name}")
    return 0


DESCRIPTIONS = {  # how ros2 param get says each type
    1: ("Boolean value is:", "bool_value"),
    2: ("Integer value is:", "integer_value"),
    3: ("Double value is:", "double_value"),
    4: ("String value is:", "string_value"),
    5: ("Byte values are:", "byte_array_value"),
    6: ("Boolean values are:", "bool_array_value"),
    7: ("Integer values are:", "integer_array_value"),
    8: ("Double values are:", "double_array_value"),
    9: ("String values are:", "string_array_value"),
}


def param_get(node, args) -> int:
    result = _done(node, _parameters(node, args.node_name).get_parameters([args.parameter_name]))
    value = result.values[0] if result.values else None
    if value is None or value.type not in DESCRIPTIONS:
        print("Parameter not set.")
        return 0
    words, field = DESCRIPTIONS[value.type]
    shown = getattr(value, field)
    print(f"{words} {list(shown) if value.type >= 5 else shown}")
    return 0


def param_set(node, args) -> int:
    from rcl_interfaces.msg import Parameter
    from rclpy.parameter import get_parameter_value

    _yaml(args.value, "the value")  # rclpy's reader lets a YAML scanner's error through as a traceback
    value = get_parameter_value(args.value)  # as ros2 param set reads it: YAML, typed (true, 3, 2.5, text)
    parameters = [Parameter(name=args.parameter_name, value=value)]
    result = _done(node, _parameters(node, args.node_name).set_parameters(parameters)).results[0]
    reason = f": {result.reason}" if result.reason else ""
    if result.successful:
        print(f"Set parameter successful{reason}")
        return 0
    print(f"Set parameter failed{reason}", file=sys.stderr)
    return 1


def lifecycle_get(node, args) -> int:
    from lifecycle_msgs.srv import GetState

    state = _call(node, node.create_client(GetState, f"{args.node_name}/get_state"), GetState.Request())
    print(f"{state.current_state.label} [{state.current_state.id}]")
    return 0


def lifecycle_set(node, args) -> int:
    from lifecycle_msgs.srv import ChangeState, GetAvailableTransitions

    available = _call(
        node,
        node.create_client(GetAvailableTransitions, f"{args.node_name}/get_available_transitions"),
        GetAvailableTransitions.Request(),
    )
    labels = {t.transition.label: t.transition.id for t in available.available_transitions}
    if args.transition not in labels:
        print(f"Unknown transition requested, available ones are: {', '.join(sorted(labels))}", file=sys.stderr)
        return 1
    request = ChangeState.Request()
    request.transition.id = labels[args.transition]
    done = _call(node, node.create_client(ChangeState, f"{args.node_name}/change_state"), request)
    if not done.success:
        print("Transitioning failed", file=sys.stderr)
        return 1
    print("Transitioning successful")
    return 0


def action_list(node, args) -> int:
    from rclpy.action import get_action_names_and_types

    _discover(node, args.spin_time)
    return _print_names(get_action_names_and_types(node), args.show_types)


GOAL_STATUS = {4: "SUCCEEDED", 5: "CANCELED", 6: "ABORTED"}  # action_msgs/msg/GoalStatus, as ros2 names them


def action_send_goal(node, args) -> int:
    """The goal, each feedback (with ``-f``), the result and its status, as ``ros2 action send_goal`` prints them.

    It waits for the result as long as the goal runs, as ``ros2`` does; Ctrl-C cancels the goal (once it was
    accepted) and exits 1.  Exit status 1 also when the goal was rejected or did not succeed.

    Raises:
        ValueError: a type or a goal field that is not there, or a value that does not fit its field.
        CommandFailed: no action server within 10 s, no answer to the goal or the cancel within 10 s, or a
            goal that had ended before its cancel arrived.
    """
    from rclpy.action import ActionClient

    cls = interface_type(args.action_type, "action")
    goal = cls.Goal()
    set_fields(goal, _yaml(args.goal, "the goal"))
    client = ActionClient(node, cls, args.action_name)
    print("Waiting for an action server to become available...", flush=True)
    if not client.wait_for_server(timeout_sec=10.0):
        raise CommandFailed(f"{args.action_name}: no action server answered within 10 s")
    print(f"Sending goal:\n     {to_yaml(goal)}", flush=True)

    def feedback(msg) -> None:
        print(f"Feedback:\n    {to_yaml(msg.feedback)}", flush=True)

    sent = client.send_goal_async(goal, feedback_callback=feedback if args.feedback else None)
    try:
        handle = _done(node, sent, what=f"{args.action_name}: ")
    except KeyboardInterrupt:  # before the goal was answered: it may be accepted all the same
        handle = _done(node, sent, what=f"{args.action_name}: ")
        return _cancel(node, handle, args.action_name) if handle.accepted else 1
    if not handle.accepted:
        print("Goal was rejected.", flush=True)
        return 1
    print(f"Goal accepted with ID: {bytes(handle.goal_id.uuid).hex()}\n", flush=True)
    try:
        result = _done(node, handle.get_result_async(), None)  # as long as the goal runs
    except KeyboardInterrupt:
        return _cancel(node, handle, args.action_name)
    status = GOAL_STATUS.get(result.status, "UNKNOWN")
    print(f"Result:\n    {to_yaml(result.result)}")
    print(f"Goal finished with status: {status}")
    return 0 if status == "SUCCEEDED" else 1


def _cancel(node, handle, action_name: str) -> int:
    """Cancel an accepted goal (Ctrl-C), as ``ros2 action send_goal`` does; exit status 1."""
    print("Canceling goal...", flush=True)
    if not _done(node, handle.cancel_goal_async(), what=f"{action_name}: ").goals_canceling:
        raise CommandFailed(f"{action_name}: the goal was not canceled (it had ended)")
    print("Goal canceled.")
    return 1


def interface_show(node, args) -> int:
    """The interface's definition file as its package installed it (nested types are not expanded)."""
    parts = args.type_name.strip("/").split("/")
    if len(parts) != 3:
        raise ValueError(f"{args.type_name!r}: expected a type like sensor_msgs/msg/Joy")
    package, kind, name = parts
    interface_type(args.type_name, kind)  # a package or type that is not here: said as for every command
    path = os.path.join(sys.prefix, "share", package, kind, f"{name}.{kind}")
    if not os.path.isfile(path):
        raise CommandFailed(f"{args.type_name}: no definition file at {path}")
    with open(path, encoding="utf-8") as f:
        print(f.read(), end="")
    return 0


COMMANDS = {
    ("node", "list"): node_list,
    ("node", "info"): node_info,
    ("topic", "list"): topic_list,
    ("topic", "info"): topic_info,
    ("topic", "echo"): topic_echo,
    ("topic", "hz"): topic_hz,
    ("topic", "pub"): topic_pub,
    ("service", "list"): service_list,
    ("service", "call"): service_call,
    ("param", "list"): param_list,
    ("param", "get"): param_get,
    ("param", "set"): param_set,
    ("lifecycle", "get"): lifecycle_get,
    ("lifecycle", "set"): lifecycle_set,
    ("action", "list"): action_list,
    ("action", "send_goal"): action_send_goal,
    ("interface", "show"): interface_show,
}

if __name__ == "__main__":
    sys.exit(main())
