"""Step 3 across real processes: simulation, joystick and viewer as separate programs."""

import json
import math
import signal

import pytest

from conftest import module_command, publish_and_wait_applied, publishers_seen, wait_until


def viewer(procs, project="project/step3.yaml", name="rtt_viewer", *extra):
    return procs(
        module_command(
            "tutorial.tools.rtt_run", project, "--headless", "--json", *extra, "--ros-args", "-r", f"__node:={name}"
        )
    )


def is_stale(line: str) -> bool:
    return '"event": "stale"' in line


def stop_when_stale(proc, stale_before: int, timeout=30):
    """Wait until the viewer says the data stopped (all delivered states applied), then Ctrl-C it.

    ``stale_before`` is the viewer's count of stale events taken while the
    publisher was still running: only a stale event after those says that
    everything the publisher sent has been delivered and applied.
    """
    proc.wait_for_count(is_stale, stale_before + 1, timeout=timeout)
    proc.p.send_signal(signal.SIGINT)
    assert proc.wait(30) == 0, proc.err
    return proc.summary()


@pytest.mark.more  # make test: a replayed drive's viewer ends on the recording's last state (test_bag_replay)
def test_viewer_ends_on_the_simulations_final_state(procs):
    view = viewer(procs)
    joy = procs(module_command("tutorial.tools.rtt_joy", "--demo", "--duration", "4"))
    sim = procs(
        module_command("tutorial.tools.rtt_run", "project/step2.yaml", "--headless", "--duration", "6", "--json")
    )
    stale_before = view.count(is_stale)  # the simulation is still starting or running
    assert sim.wait(60) == 0, sim.err
    assert joy.wait(30) == 0
    sim_summary = sim.summary()
    view_summary = stop_when_stale(view, stale_before)
    final = sim_summary["bodies"]["Tank"]["joint_positions"]
    shown = view_summary["controllers"]["RttJointStateMonitor"]["last_positions"]
    assert set(shown) == {"TURRET_Y", "TURRET_P"}
    for name in final:
        assert abs(shown[name] - final[name]) <= 1e-6, (name, shown, final)
    assert view_summary["bodies"]["Tank"]["joint_positions"] == pytest.approx(final, abs=1e-6)
    assert abs(final["TURRET_Y"]) > 0.1  # the demo really moved it
    counts = view_summary["controllers"]["RttJointStateMonitor"]
    assert counts["rejected"] == {}
    assert counts["received"] > 100  # 50 Hz for most of 6 s
    assert (
        sim_summary["controllers"]["RttJointStatePublisher"]["published"] == 1 + 299 + 1
    )  # the start state, 50 Hz over 6 s (steps 20, ..., 5980), and the final state


JOIN_DEADLINE = 3.0  # s from a monitor joining (in the ROS graph) to the posture shown, at 0.1 Hz (issue 26)


def test_a_monitor_joining_a_slow_publisher_shows_the_posture_at_once(procs, node):
    """A simulation publishing at 0.1 Hz: a monitor started between two states shows the one its publisher
    kept (the start state) within 3 s of joining the ROS graph, and its status line says so; before issue 26
    the status line said "no state yet, 0/2 joints matched" until the next live state, up to 10 s later
    (6.9 s measured).  Joining is timed from when this test sees the monitor's subscription in the graph:
    the process's own start-up (imports: one to three seconds on a busy machine) is not joining."""
    import json
    import time

    sim = procs(
        module_command(
            "tutorial.tools.rtt_run",
            "project/step2.yaml",
            "--headless",
            "--json",
            "--ros-args",
            "-p",
            "RttJointStatePublisher.rate:=0.1",
        )
    )
    assert wait_until(lambda: node.count_publishers("/Tank/joint_state") >= 1, timeout=60), sim.err
    started = time.monotonic()
    view = viewer(procs)

    def monitor_joined() -> bool:  # its subscriptions are in the ROS graph: it has joined
        return any(i.node_name == "rtt_viewer" for i in node.get_subscriptions_info_by_topic("/Tank/joint_state"))

    assert wait_until(monitor_joined, timeout=60, poll=0.01), view.err
    joined = time.monotonic()
    late = json.loads(view.wait_for_line(lambda line: '"event": "late_state"' in line, timeout=30))
    shown = time.monotonic()
    shown_after = shown - joined
    is_status = lambda line: '"event": "status"' in line  # noqa: E731
    status = json.loads(view.wait_for_count(is_status, view.count(is_status) + 1, timeout=5))  # the next one
    print(
        f"the monitor showed the posture {shown - started:.2f} s after its process started, {shown_after:.2f} s "
        f"after this test saw it join the graph: {late['message']}"
    )
    assert late["stamp"] == 0.0 and late["matched"] == 2  # the state the simulation started in
    assert status["matched"] == 2 and status["age_ms"] is not None  # the status line shows it too
    assert not view.records("first_state")  # no live state yet: the next is 10 s of simulated time away
    assert shown_after <= JOIN_DEADLINE


HOSTILE = [
    # (names, positions, expected rejections)
    (["TURRET_P", "TURRET_Y"], [0.2, 0.3], {}),  # reordered
    (["TURRET_Y", "GUN", "TURRET_P"], [0.1, 9.0, 0.2], {"unknown_name": 1}),  # unknown name
    (["TURRET_Y", "TURRET_Y", "TURRET_P"], [0.1, 0.2, 0.3], {"duplicate_name": 2}),  # duplicate
    (["TURRET_Y", "TURRET_P"], [0.4], {"no_position": 1}),  # short positions
    (["TURRET_Y"], [0.4, 0.5], {"no_name": 1}),  # short names
    (["TURRET_Y", "TURRET_P"], [math.nan, 0.1], {"not_finite": 1}),  # NaN
    (["TURRET_Y", "TURRET_P"], [0.1, -math.inf], {"not_finite": 1}),  # inf
    (["TURRET_Y", "TURRET_P"], [1e300, 0.1], {"out_of_range": 1}),  # huge
    ([], [], {}),  # empty
    (["TURRET_Y", "TURRET_P"], [0.5, 0.25], {}),  # a good one, last
]


@pytest.mark.more  # make test: the same rejections counted in-process (test_fuzz_messages, test_joint_matching)
def test_hostile_publisher_is_counted_exactly(procs, node):
    from sensor_msgs.msg import JointState

    from tutorial.interfaces.joint_state import joint_state_qos

    view = viewer(procs)
    pub = node.create_publisher(JointState, "/Tank/joint_state", joint_state_qos())
    # Both sides must have matched: the publisher counting the viewer is not enough, a message
    # sent before the viewer has matched the publisher is dropped (discovery is not symmetric).
    assert wait_until(lambda: pub.get_subscription_count() >= 1, timeout=30)
    assert wait_until(lambda: publishers_seen(view) >= 1, timeout=30), view.out
    expected = {}
    for sent, (names, positions, rejections) in enumerate(HOSTILE, start=1):
        # The next message goes out only once the viewer has applied this one: a stalled
        # keep-last-1 reader cannot have it replaced, nor can it coalesce.
        publish_and_wait_applied(pub, view, names, positions, sent)
        for k, v in rejections.items():
            expected[k] = expected.get(k, 0) + v
    summary = stop_when_stale(view, 0)  # every message is applied (waited for above): any stale event will do
    counts = summary["controllers"]["RttJointStateMonitor"]
    assert counts["received"] == len(HOSTILE)
    assert counts["applied"] == len(HOSTILE), "messages coalesced: the pacing was too fast for this machine"
    assert counts["rejected"] == dict(sorted(expected.items()))
    assert counts["last_positions"] == {"TURRET_Y": 0.5, "TURRET_P": 0.25}
    assert summary["bodies"]["Tank"]["joint_positions"] == {"TURRET_Y": 0.5, "TURRET_P": 0.25}
    status = view.records("status")[-1]
    assert status["rejected"] == counts["rejected"]


def test_viewer_reports_publishers_that_come_and_go(procs, node):
    from sensor_msgs.msg import JointState

    from tutorial.interfaces.joint_state import joint_state_qos

    view = viewer(procs)
    pub = node.create_publisher(JointState, "/Tank/joint_state", joint_state_qos())
    assert wait_until(lambda: publishers_seen(view) == 1, timeout=30), view.out
    node.destroy_publisher(pub)
    assert wait_until(lambda: publishers_seen(view) == 0, timeout=30), view.out
    view.p.send_signal(signal.SIGINT)
    assert view.wait(30) == 0, view.err
    assert [r["topic"] for r in view.records("publishers")] == ["/Tank/joint_state"] * 2


def test_a_second_node_with_the_same_name_is_warned_about(procs):
    a = viewer(procs, "project/step3.yaml", "rtt", "--duration", "30")  # checks at 2, 4, 6, 8 s
    b = viewer(procs, "project/step3.yaml", "rtt", "--duration", "30")
    for p in (a, b):  # the first warning each prints is the one (a process's first lines may come late)
        first = p.wait_for_line(lambda line: '"event": "warning"' in line, timeout=30)
        assert "2 nodes are named /rtt" in json.loads(first)["message"], p.out


@pytest.mark.more  # make test: two learners' distinct names, no warning (test_hub), and the same name's warning
def test_distinct_names_give_no_warning(procs):
    a = viewer(procs, "project/step3.yaml", "rtt_a", "--duration", "5")
    b = viewer(procs, "project/step3.yaml", "rtt_b", "--duration", "5")
    assert a.wait(60) == 0 and b.wait(60) == 0
    assert a.records("warning") == [] and b.records("warning") == []


@pytest.mark.more  # make test: gymnasium's ant across processes, test_third_party_models
def test_any_model_publishes_and_shows_its_own_joints(procs):
    view = viewer(procs, "tests/fixtures/crane_view.yaml")
    # 5 s: long enough that the two nodes have found each other well before the final
    # state is sent, even when discovery takes one of Fast DDS's ~3 s announcement periods.
    sim = procs(
        module_command(
            "tutorial.tools.rtt_run", "tests/fixtures/crane_sim.yaml", "--headless", "--duration", "5", "--json"
        )
    )
    stale_before = view.count(is_stale)
    assert sim.wait(60) == 0, sim.err
    final = sim.summary()["bodies"]["Crane"]["joint_positions"]
    assert list(final) == ["SLEW", "LUFF", "TROLLEY"]  # hinge, hinge, slide; the ball joint is not numbered
    shown = stop_when_stale(view, stale_before)["controllers"]["RttJointStateMonitor"]
    assert shown["topic"] == "/Crane/joint_state"
    assert shown["rejected"] == {}
    for name, q in final.items():
        assert abs(shown["last_positions"][name] - q) <= 1e-6
    assert max(abs(q) for q in final.values()) > 0.05  # it moved


def test_publishers_record_reads_as_a_line():
    from tutorial.tools.rtt_run import format_record

    line = format_record({"event": "publishers", "node": "/rtt_viewer", "topic": "/Tank/joint_state", "count": 1})
    assert line == "[/rtt_viewer] /Tank/joint_state: matched with 1 publisher"
    assert format_record({"event": "publishers", "topic": "/Tank/joint_state", "count": 0}).endswith(
        "with 0 publishers"
    )
