"""The Step 3 monitor in this process: what it says and shows, message by message (notebook 03's lesson).

A stand-in node keeps the subscriptions; each callback is called as the spin
thread would, and the main thread's posted work runs on a real
:class:`MainLoop` owned by the test.
"""

from __future__ import annotations

from types import SimpleNamespace

import mujoco
import pytest

from tutorial.controllers.joint_state_subscriber import RttJointStateMonitor
from tutorial.core.body import Body
from tutorial.core.call_later import MainLoop
from tutorial.core.controller import ControllerConfig
from tutorial.core.world import ModelEntry, build_world

from conftest import MODEL
from conftest import ViewerNode as Node

pytestmark = pytest.mark.unit


def state(t, names, positions):
    sec = int(t)
    return SimpleNamespace(
        header=SimpleNamespace(stamp=SimpleNamespace(sec=sec, nanosec=round((t - sec) * 1e9))),
        name=list(names),
        position=list(positions),
    )


def make_monitor():
    """A configured monitor of the tank, its stand-in node, the main thread's loop and the status records."""
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    body = Body(model, mujoco.MjData(model), "Tank")
    loop, node, out = MainLoop(), Node(), []
    config = ControllerConfig(
        name="RttJointStateMonitor", body=body, node=node, parameters={}, call_later=loop.call_later,
        call_every=loop.call_every, output=out.append,
    )  # fmt: skip
    m = RttJointStateMonitor()
    assert m.configure(config)
    return SimpleNamespace(m=m, loop=loop, node=node, out=out, body=body)


@pytest.fixture
def monitor():
    return make_monitor()


def events(out, kind):
    return [r for r in out if r.get("event") == kind]


def test_it_subscribes_live_and_late_and_reports_its_first_state(monitor):
    live, late = monitor.node.subscriptions
    assert live.topic == late.topic == "/Tank/joint_state"
    assert live.qos.durability.name == "VOLATILE" and late.qos.durability.name == "TRANSIENT_LOCAL"
    assert live.events is not None and live.events.matched == monitor.m.on_matched
    live.callback(state(1.5, ["TURRET_Y", "TURRET_P"], [0.3, 0.1]))
    assert monitor.out == []  # the spin thread only posts
    monitor.loop.process_pending()
    assert monitor.body.joint_positions() == pytest.approx({"TURRET_Y": 0.3, "TURRET_P": 0.1})
    (first,) = events(monitor.out, "first_state")
    assert first == {
        "event": "first_state", "node": "/rtt_viewer", "topic": "/Tank/joint_state",
        "message": "first joint state on /Tank/joint_state: 2/2 joints matched",
        "line": "[/rtt_viewer] first joint state on /Tank/joint_state: 2/2 joints matched", "matched": 2, "joints": 2,
    }  # fmt: skip
    assert monitor.node.destroyed == [late]  # live states flow: the late subscription goes
    live.callback(state(1.52, ["TURRET_Y"], [0.4]))
    monitor.loop.process_pending()
    assert len(events(monitor.out, "first_state")) == 1  # once


def test_stamps_that_go_back_are_reported_and_the_new_run_shown(monitor):
    live = monitor.node.subscriptions[0]
    for t, q in ((5.0, 0.2), (0.02, -0.2)):
        live.callback(state(t, ["TURRET_Y"], [q]))
        monitor.loop.process_pending()
    (back,) = events(monitor.out, "stamps_back")
    assert back["message"] == "/Tank/joint_state: stamps went back from 5.000 s to 0.020 s (a new run?): showing it"
    assert monitor.body.joint_positions()["TURRET_Y"] == pytest.approx(-0.2)
    live.callback(state(0.04, ["TURRET_Y"], [-0.1]))  # forward again: nothing more to say
    monitor.loop.process_pending()
    s = monitor.m.summary()
    assert s["stamps_back"] == 1 and s["applied"] == 3 and s["received"] == 3 and s["late_states"] == 0
    assert s["topic"] == "/Tank/joint_state" and s["rejected"] == {}
    assert s["last_positions"] == {"TURRET_Y": -0.1, "TURRET_P": 0.0}


def test_a_late_state_is_shown_only_while_no_live_one_came(monitor):
    live, late = monitor.node.subscriptions
    late.callback(state(12.25, ["TURRET_P", "X"], [0.2, 1.0]))
    monitor.loop.process_pending()
    (shown,) = events(monitor.out, "late_state")
    assert shown["message"] == (
        "/Tank/joint_state: showing the newest state published before this viewer started (t = 12.250 s)"
    )
    assert shown["stamp"] == 12.25 and shown["matched"] == 1 and shown["joints"] == 2
    assert monitor.body.joint_positions()["TURRET_P"] == pytest.approx(0.2)
    assert monitor.node.destroyed == [late] and monitor.m.summary()["late_states"] == 1
    # A live state came first: a late one that arrives after it is not shown.
    other = make_monitor()
    live2, late2 = other.node.subscriptions
    live2.callback(state(1.0, ["TURRET_P"], [0.05]))
    other.loop.process_pending()
    late2.callback(state(0.5, ["TURRET_P"], [0.3]))
    other.loop.process_pending()
    assert events(other.out, "late_state") == [] and other.m.summary()["late_states"] == 0
    assert other.body.joint_positions()["TURRET_P"] == pytest.approx(0.05)


def test_publishers_are_counted_and_two_are_a_warning(monitor):
    live = monitor.node.subscriptions[0]
    for count in (1, 2, 1):
        monitor.m.on_matched(SimpleNamespace(current_count=count))
        monitor.loop.process_pending()
    assert [(r["count"], r["node"], r["topic"]) for r in events(monitor.out, "publishers")] == [
        (1, "/rtt_viewer", "/Tank/joint_state"), (2, "/rtt_viewer", "/Tank/joint_state"),
        (1, "/rtt_viewer", "/Tank/joint_state"),
    ]  # fmt: skip
    (warning,) = events(monitor.out, "warning")
    assert warning["message"] == (
        "2 publishers on /Tank/joint_state: the view mixes their states and cannot tell which robot it is showing"
    )
    monitor.m.on_matched(SimpleNamespace(current_count=3))
    monitor.m.on_matched(SimpleNamespace(current_count=0))  # two at once: the newest count wins
    monitor.loop.process_pending()
    assert events(monitor.out, "publishers")[-1]["count"] == 0 and len(events(monitor.out, "warning")) == 1
    assert live not in monitor.node.destroyed  # publishers coming and going leave the subscription alone


def test_rejections_are_counted_by_reason_and_unconfigure_drops_both_subscriptions(monitor):
    live, late = monitor.node.subscriptions
    live.callback(state(1.0, ["TURRET_Y", "TURRET_Y", "wheel"], [0.1, 0.2, 0.3]))
    monitor.loop.process_pending()
    live.callback(state(1.1, ["TURRET_P"], [float("nan")]))
    monitor.loop.process_pending()
    assert monitor.m.summary()["rejected"] == {"duplicate_name": 2, "not_finite": 1, "unknown_name": 1}
    monitor.m.unconfigure()
    assert late in monitor.node.destroyed and live in monitor.node.destroyed


def test_a_rejected_name_is_in_the_status_line_printable_and_short():
    """The status line names what it rejected, newest first, three a reason at most; a received name is shown
    printable and cut short (it comes from the network)."""
    from tutorial.view.status import format_status

    t = make_timed_monitor()
    live = t.node.subscriptions[0]
    for k, name in enumerate(["elbow", "wrist", "elbow", "x" * 100, "bad\nname"]):
        live.callback(state(1.0 + k, [name, "TURRET_P"], [0.0, 0.1]))
        t.loop.process_pending()
    live.callback(state(9.0, ["TURRET_P"], [9.0]))
    t.loop.process_pending()
    t.m.report_status()
    (status,) = events(t.out, "status")
    assert status["rejected_names"] == {
        "out_of_range": ["TURRET_P"],
        "unknown_name": ["'bad\\nname'", "x" * 37 + "...", "elbow"],
    }
    line = format_status(status)
    assert "rejected: out_of_range 1 (TURRET_P), unknown_name 5 ('bad\\nname', xxx" in line, line
    assert "\n" not in line


def test_the_topic_said_is_the_remapped_one_and_the_late_subscription_is_quiet_on_volatile_publishers():
    """With ``-r /Tank/joint_state:=/joint_states`` the monitor says the topic it really hears; and the late
    joiner's transient-local subscription, which a volatile publisher cannot match, handles that event itself
    (with a handler, rclpy prints no warning; tests/test_robot_description.py sees that for real)."""
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    body = Body(model, mujoco.MjData(model), "Tank")
    node, loop = Node(), MainLoop()
    node.create_subscription = lambda msg_type, topic, callback, qos, event_callbacks=None: (
        node.subscriptions.append(
            sub := SimpleNamespace(
                topic=topic, topic_name="/joint_states", callback=callback, qos=qos, events=event_callbacks
            )
        )
        or sub
    )
    config = ControllerConfig(
        name="RttJointStateMonitor", body=body, node=node, parameters={}, call_later=loop.call_later,
        call_every=loop.call_every, output=[].append,
    )  # fmt: skip
    m = RttJointStateMonitor()
    assert m.configure(config)
    live, late = node.subscriptions
    assert live.topic == "/Tank/joint_state" and m.topic == "/joint_states" == late.topic
    assert late.events is not None and late.events.incompatible_qos is not None
    late.events.incompatible_qos(SimpleNamespace(total_count=1))  # handled, and nothing said


class Clock:
    def __init__(self, now=10.0):
        self.now = now

    def __call__(self):
        return self.now


def make_timed_monitor():
    """A monitor on the test's clock, its timers kept instead of run: ``(period, func)`` each."""
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    body = Body(model, mujoco.MjData(model), "Tank")
    loop, node, out, timers = MainLoop(), Node(), [], []
    config = ControllerConfig(
        name="RttJointStateMonitor", body=body, node=node, parameters={}, call_later=loop.call_later,
        call_every=lambda period, func: timers.append((period, func)), output=out.append,
    )  # fmt: skip
    m = RttJointStateMonitor()
    assert m.configure(config)
    clock = Clock()
    m.status.clock = clock
    m.status._last_report = clock.now
    return SimpleNamespace(m=m, loop=loop, node=node, out=out, body=body, timers=timers, clock=clock)


def test_the_status_line_and_the_stale_watch_run_on_their_timers_and_name_the_node():
    t = make_timed_monitor()
    assert t.timers == [(1.0, t.m.report_status), (0.25, t.m.check_stale)]
    live = t.node.subscriptions[0]
    t.clock.now = 10.5
    live.callback(state(1.0, ["TURRET_Y", "X"], [0.3, 1.0]))  # arrives at 10.5 s
    t.clock.now = 10.75
    t.loop.process_pending()  # shown a quarter of a second later
    t.clock.now = 11.0
    t.m.report_status()
    (status,) = events(t.out, "status")
    assert status == {
        "event": "status", "rate_hz": 1.0, "received": 1, "applied": 1, "age_ms": 500.0, "matched": 1, "joints": 2,
        "rejected": {"unknown_name": 1}, "rejected_names": {"unknown_name": ["X"]}, "stale": False,
        "stamps_back": 0, "node": "/rtt_viewer",
    }  # fmt: skip
    t.clock.now = 12.0
    t.m.check_stale()
    (stale,) = events(t.out, "stale")
    assert stale == {"event": "stale", "silent_s": 1.5, "node": "/rtt_viewer"}


def test_the_late_state_is_in_the_status_line_with_its_age_and_matches():
    t = make_timed_monitor()
    late = t.node.subscriptions[1]
    t.clock.now = 10.25
    late.callback(state(3.0, ["TURRET_P", "Y"], [0.2, 0.0]))
    t.clock.now = 10.5
    t.loop.process_pending()
    t.clock.now = 11.0
    t.m.report_status()
    (status,) = events(t.out, "status")
    assert (status["age_ms"], status["matched"], status["applied"], status["received"]) == (750.0, 1, 0, 0)


def test_a_second_late_state_after_the_first_is_not_shown():
    t = make_timed_monitor()
    live, late = t.node.subscriptions
    late.callback(state(3.0, ["TURRET_P"], [0.2]))
    t.loop.process_pending()
    assert t.node.destroyed == [late]
    late.callback(state(4.0, ["TURRET_P"], [-0.1]))  # was already on its way when the subscription went
    t.loop.process_pending()
    assert t.body.joint_positions()["TURRET_P"] == pytest.approx(0.2)
    assert len(events(t.out, "late_state")) == 1 and t.m.summary()["late_states"] == 1
    assert t.node.destroyed == [late]  # dropped once
    t.m.unconfigure()
    assert t.node.destroyed == [late, live]


def test_equal_stamps_are_not_going_back_and_each_going_back_is_counted():
    t = make_timed_monitor()
    live = t.node.subscriptions[0]
    for stamp in (2.0, 2.0, 1.0, 3.0, 0.5):
        live.callback(state(stamp, ["TURRET_Y"], [0.1]))
        t.loop.process_pending()
    assert [r["message"] for r in events(t.out, "stamps_back")] == [
        "/Tank/joint_state: stamps went back from 2.000 s to 1.000 s (a new run?): showing it",
        "/Tank/joint_state: stamps went back from 3.000 s to 0.500 s (a new run?): showing it",
    ]
    assert t.m.summary()["stamps_back"] == 2


def test_the_summary_rounds_positions_to_the_nanoradian():
    t = make_timed_monitor()
    live = t.node.subscriptions[0]
    live.callback(state(1.0, ["TURRET_Y"], [0.12345678912345]))
    t.loop.process_pending()
    assert t.m.summary()["last_positions"]["TURRET_Y"] == 0.123456789


def test_the_notebooks_plain_subscriber_hands_each_message_to_the_main_thread():
    from tutorial.controllers.joint_state_subscriber import RttJointStateSubscriber

    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    body = Body(model, mujoco.MjData(model), "Tank")
    loop, node = MainLoop(), Node()
    config = ControllerConfig(name="S", body=body, node=node, call_later=loop.call_later)
    s = RttJointStateSubscriber()
    assert s.configure(config)
    (sub,) = node.subscriptions
    assert sub.topic == "/Tank/joint_state" and sub.events is None
    sub.callback(state(1.0, ["TURRET_Y"], [0.5]))
    sub.callback(state(1.02, ["TURRET_Y"], [0.6]))  # the newer replaces the one still waiting
    assert body.joint_positions()["TURRET_Y"] == 0.0  # the callback touched nothing
    assert loop.process_pending() == 1
    assert body.joint_positions()["TURRET_Y"] == pytest.approx(0.6)
    assert s.summary() == {"topic": "/Tank/joint_state", "applied": 1, "rejected": {},
                           "last_positions": {"TURRET_Y": 0.6, "TURRET_P": 0.0}}  # fmt: skip
    s.unconfigure()
    assert node.destroyed == [sub]
