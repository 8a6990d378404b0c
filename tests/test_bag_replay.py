"""A recorded demo drive, replayed into a fresh Step 3 viewer, ends where the recording ends."""

import signal

import pytest

from tutorial.tools.bag.info import bag_info
from tutorial.tools.bag.qos import offer_for_recorded
from tutorial.tools.bag.series import joint_series

from conftest import module_command, publishers_seen, wait_until

RTT_BAG = "tutorial.tools.rtt_bag"  # rtt-bag, run as python -m


def is_stale(line: str) -> bool:
    return '"event": "stale"' in line


# make test: notebook 07 (nbval) records a drive and replays it into a Step 3 viewer, which ends on the recording's
# last joint state; this case does the same with the rtt-bag, rtt-joy and rtt-run programs.
@pytest.mark.more
def test_a_replayed_drive_drives_the_viewer_as_the_live_one_did(procs, tmp_path):
    bag = tmp_path / "drive.mcap"
    # 1. Record a demo drive: the recorder first, so it is in the graph when the publishers appear.
    rec = procs(module_command(RTT_BAG, "record", "/joy", "/Tank/joint_state", "-o", str(bag)))
    rec.wait_for_line(lambda line: "recording /joy /Tank/joint_state" in line, timeout=30)
    joy = procs(module_command("tutorial.tools.rtt_joy", "--demo", "--duration", "9"))
    sim = procs(
        module_command("tutorial.tools.rtt_run", "project/step2.yaml", "--headless", "--duration", "10", "--json")
    )
    assert sim.wait(60) == 0, sim.err
    assert joy.wait(30) == 0, joy.err
    rec.p.send_signal(signal.SIGINT)
    assert rec.wait(30) == 0, rec.err
    info = bag_info(bag)
    states = info.topic("/Tank/joint_state")
    # Discovery can take one of Fast DDS's 3 s announcement periods here (a plain subscriber
    # waits as long), or a little more on a loaded machine: at least the last 6 s of the 10 s
    # drive are in the file.  The rate is taken over the times the recorder received the
    # messages, so delivery late at the start shortens the span: once (CI, 2026-11-22) 134
    # messages spanned 2.33 s instead of 2.66 s, 57 Hz; over 6 s, 0.33 s short is 52.9 Hz.
    assert states.count > 100 and info.topic("/joy").count > 10, rec.out
    assert abs(states.rate_hz - 50.0) < 5.0
    recorded = joint_series(bag, "/Tank/joint_state")  # read without ROS
    last = {name: float(q[-1]) for name, q in recorded.positions.items()}
    assert set(last) == {"TURRET_Y", "TURRET_P"}
    assert max(abs(q).max() for q in recorded.positions.values()) > 0.05  # the demo moved the turret

    # 2. Play it, twice as fast, into a fresh viewer.
    view = procs(
        module_command(
            "tutorial.tools.rtt_run",
            "project/step3.yaml",
            "--headless",
            "--json",
            "--ros-args",
            "-r",
            "__node:=rtt_viewer",
        )
    )
    play = procs(module_command(RTT_BAG, "play", str(bag), "--rate", "2", "--delay", "1"))
    assert wait_until(lambda: publishers_seen(view) >= 1, timeout=30), view.out
    stale_before = view.count(is_stale)  # the player is still playing
    assert play.wait(60) == 0, play.err
    offer, _ = offer_for_recorded(states.offered_qos_profiles)  # the QoS the file says the simulation offered
    assert (
        f"publishing /Tank/joint_state (sensor_msgs/msg/JointState; {offer['reliability']}, "
        f"{offer['durability']})" in play.out
    )
    # The data stopped: every state delivered has been applied. Then stop the viewer.
    view.wait_for_count(is_stale, stale_before + 1, timeout=30)
    view.p.send_signal(signal.SIGINT)
    assert view.wait(30) == 0, view.err
    # The viewer's joint-state controller (whatever its name): the one reporting last_positions.
    [shown] = [c for c in view.summary()["controllers"].values() if "last_positions" in c]
    assert shown["rejected"] == {}
    assert shown["received"] > 50
    # The recording's last message (the viewer's summary rounds to 9 decimals).
    assert shown["last_positions"] == pytest.approx(last, abs=1e-9)
