"""The fault matrix across real processes (issue 18): kill a node, the rest keep working and say what happened.

Each case starts the tutorial's programs as separate processes, injects one
fault and waits, with a deadline, for the line that must report it; no wait
is a sleep.  Killed nodes leave Fast DDS's shared-memory files in /dev/shm;
the ``nodes`` fixture removes what the processes it started left (as the
launcher does for a launch), and the launch cases check that nothing of
theirs is left.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest
from test_launch import processes_with_marker

from tutorial.ros.shm import SHM_DIR, fast_dds_shm_files, new_leftovers_removed, remove_unused_fast_dds_shm

from conftest import ROOT, module_command, publishers_seen, wait_until

RTT_BAG = "tutorial.tools.rtt_bag"  # rtt-bag, run as python -m

pytestmark = pytest.mark.cross_process

STALE_DEADLINE = 1.5  # s from a SIGKILLed simulation to the viewer's stale line (issue 18)
MAX_SLIDE = 0.1  # m the tank's root may move after the joy timeout (issue 18)


def event_is(event: str, **fields):
    """A line predicate: a JSON record of ``event`` whose ``fields`` have these values."""

    def match(line: str) -> bool:
        if not line.startswith("{"):
            return False
        record = json.loads(line)
        return record.get("event") == event and all(record.get(k) == v for k, v in fields.items())

    return match


def next_record(proc, event: str, timeout: float, **fields) -> dict:
    """The first ``event`` record ``proc`` prints from now on (waits at most ``timeout`` s)."""
    match = event_is(event, **fields)
    return json.loads(proc.wait_for_count(match, proc.count(match) + 1, timeout=timeout))


class Nodes:
    """The tutorial's programs started as processes (conftest's ``procs``), stopped or killed by the test.

    At the end every node still running gets Ctrl-C (SIGINT), and the Fast DDS
    files in /dev/shm that the nodes used and nobody uses any more are removed:
    a SIGKILLed node leaves its own behind.  Main thread only.
    """

    def __init__(self, procs):
        self.procs = procs
        self.started = []
        self.shm_files: set[str] = set()

    def start(self, module: str, *args: str, **kw):
        proc = self.procs(module_command(module, *args), **kw)
        self.started.append(proc)
        return proc

    def simulation(self, name: str = "rtt"):
        """Step 2's simulation (``rtt-run project/step2.yaml``): Joy in, joint state out at 50 Hz."""
        return self.start(
            "tutorial.tools.rtt_run",
            "project/step2.yaml",
            "--headless",
            "--json",
            "--ros-args",
            "-r",
            f"__node:={name}",
        )

    def viewer(self, name: str = "rtt_viewer"):
        """Step 3's viewer (``rtt-run project/step3.yaml``), under its own node name."""
        return self.start(
            "tutorial.tools.rtt_run",
            "project/step3.yaml",
            "--headless",
            "--json",
            "--ros-args",
            "-r",
            f"__node:={name}",
        )

    def note_shared_memory(self, proc) -> None:
        self.shm_files |= fast_dds_shm_files(proc.p.pid)

    def kill(self, proc) -> float:
        """SIGKILL ``proc`` and reap it; the monotonic time of the kill."""
        self.note_shared_memory(proc)
        killed_at = time.monotonic()
        proc.p.kill()
        proc.p.wait(10)
        return killed_at

    def stop(self, proc, timeout: float = 15) -> int:
        """Ctrl-C (SIGINT) ``proc``; its exit status (fails after ``timeout`` s)."""
        self.note_shared_memory(proc)
        proc.p.send_signal(signal.SIGINT)
        return proc.wait(timeout)

    def close(self) -> None:
        for proc in self.started:
            if proc.p.poll() is None:
                self.note_shared_memory(proc)
                proc.p.send_signal(signal.SIGINT)
        for proc in self.started:
            try:
                proc.p.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
        remove_unused_fast_dds_shm(self.shm_files)


@pytest.fixture
def nodes(procs):
    started = Nodes(procs)
    yield started
    started.close()


# make test keeps the recorder killed; a stale viewer only at the end of a playback (test_bag_replay) and the
# stale timer alone (test_step3_monitor), not after a kill
@pytest.mark.more
def test_simulation_killed_the_viewer_says_stale_and_recovers_with_a_new_one(nodes):
    view = nodes.viewer()
    sim = nodes.simulation()
    view.wait_for_line(event_is("first_state"), timeout=30)
    stale = event_is("stale")
    stale_before = view.count(stale)
    killed_at = nodes.kill(sim)
    record = json.loads(view.wait_for_count(stale, stale_before + 1, timeout=10))
    said_after = time.monotonic() - killed_at
    print(f"stale said {said_after:.3f} s after the SIGKILL ({record['silent_s']} s of silence)")
    assert said_after <= STALE_DEADLINE, f"stale said {said_after:.2f} s after the kill: {record}"
    assert next_record(view, "status", timeout=5)["stale"] is True  # the viewer lives on and says so

    nodes.simulation()  # a new simulation: the viewer mirrors it
    next_record(view, "recovered", timeout=30)
    status = next_record(view, "status", timeout=5)
    assert status["stale"] is False and status["rate_hz"] > 0, status
    assert nodes.stop(view) == 0, view.err


@pytest.mark.more  # make test: a monitor joining a running publisher, test_step3_cross_process
def test_viewer_killed_and_restarted_mirrors_again(nodes):
    sim = nodes.simulation()
    first = nodes.viewer()
    first.wait_for_line(event_is("first_state"), timeout=30)
    nodes.kill(first)
    second = nodes.viewer()
    second.wait_for_line(event_is("first_state"), timeout=30)
    status = second.wait_for_line(
        lambda line: event_is("status", stale=False)(line) and json.loads(line)["received"] >= 25, timeout=30
    )
    assert json.loads(status)["matched"] == 2, status
    assert sim.p.poll() is None, sim.err  # the simulation went on without its viewer

    # Mirrors: once the simulation has stopped, the new viewer shows its final state.
    stale_before = second.count(event_is("stale"))
    assert nodes.stop(sim) == 0, sim.err
    second.wait_for_count(event_is("stale"), stale_before + 1, timeout=30)  # the final state has been applied
    assert nodes.stop(second) == 0, second.err
    final = sim.summary()["bodies"]["Tank"]["joint_positions"]
    shown = second.summary()["controllers"]["RttJointStateMonitor"]["last_positions"]
    assert shown == pytest.approx(final, abs=1e-6)
    assert final["TURRET_P"] != 0.0  # the barrel's sag under gravity: the state came from the simulation


def test_two_publishers_on_the_topic_are_warned_about(nodes):
    view = nodes.viewer()
    nodes.simulation()
    second = nodes.simulation("rtt_second")
    warning = json.loads(
        view.wait_for_line(
            lambda line: event_is("warning")(line) and "publishers on /Tank/joint_state" in line, timeout=30
        )
    )
    assert "cannot tell which robot it is showing" in warning["message"], warning
    assert publishers_seen(view) == 2
    assert nodes.stop(second) == 0, second.err
    assert wait_until(lambda: publishers_seen(view) == 1, timeout=30), view.out


def test_joy_killed_mid_drive_the_tank_stops(nodes, node):
    """SIGKILL ``rtt-joy`` while the demo drives forward at 0.8 m/s: after the
    joy timeout (0.5 s of simulated time) the tank's root moves less than 0.1 m."""
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import JointState

    from tutorial.interfaces.joint_state import joint_state_qos

    # The demo drives forward (0.8 m/s) exactly while the turret turns (0.8 or 0.5 rad/s):
    # the joint states say when.  newest: the newest state's stamp (s of simulated time),
    # and since when TURRET_Y has been turning.  The callback runs inside
    # executor.spin_once() below, on this thread: no lock needed.
    newest = {"stamp": None, "yaw": None, "turning_since": None}

    def on_state(msg):
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        yaw = dict(zip(msg.name, msg.position))["TURRET_Y"]
        if newest["stamp"] is not None and 0 < stamp - newest["stamp"] <= 0.1:
            if abs(yaw - newest["yaw"]) / (stamp - newest["stamp"]) >= 0.3:  # rad/s
                newest["turning_since"] = newest["turning_since"] or newest["stamp"]
            else:
                newest["turning_since"] = None
        newest.update(stamp=stamp, yaw=yaw)

    node.create_subscription(JointState, "/Tank/joint_state", on_state, joint_state_qos())
    executor = SingleThreadedExecutor()
    executor.add_node(node)

    def spun_and(predicate):
        def check():
            executor.spin_once(timeout_sec=0.02)
            return newest["stamp"] is not None and predicate(newest)

        return check

    try:
        sim = nodes.simulation()
        # The joy node only once this test receives the states: it sees the demo's first drive.
        assert wait_until(spun_and(lambda s: True), timeout=30), sim.out
        joy = nodes.start("tutorial.tools.rtt_joy", "--demo")
        # Killed 0.4 s into a drive (2.5 s long): at full speed, 2 s before the drive ends.
        assert wait_until(
            spun_and(lambda s: s["turning_since"] is not None and s["stamp"] - s["turning_since"] >= 0.4), timeout=30
        ), (sim.out, joy.out)
        nodes.kill(joy)
        stopped = next_record(sim, "joy_timeout", timeout=10)
        assert "tracks stopped" in stopped["line"]
        # 1 s of simulated time after the timeout: braking from 0.8 m/s takes about 0.2 s.
        assert wait_until(spun_and(lambda s: s["stamp"] >= stopped["t"] + 1.0), timeout=10), sim.out
    finally:
        executor.remove_node(node)
        executor.shutdown()
    assert nodes.stop(sim) == 0, sim.err
    summary = sim.summary()
    at_timeout, at_end = stopped["root_position"], summary["bodies"]["Tank"]["root_position"]
    slide = math.dist(at_timeout[:2], at_end[:2])
    print(f"root at the joy timeout {at_timeout}, at the end {at_end}: slid {slide:.3f} m")
    # The first drive goes straight ahead along +x from the origin.
    assert at_timeout[0] > 0.3 and abs(at_timeout[1]) < 0.05, "not killed in the first drive"
    assert slide < MAX_SLIDE, f"the tank moved {slide:.3f} m after the joy timeout"
    assert summary["controllers"]["RttTankController"]["joy_timeouts"] == 1


def used_by_live_processes() -> set[str]:
    """Every Fast DDS file in /dev/shm that some live process (readable to us) maps or holds open."""
    used: set[str] = set()
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            used |= fast_dds_shm_files(int(entry))
    return used


def left_behind(locks: set[str]) -> list[str]:
    """The files of these segments and ports (named by their lock files) still in /dev/shm, unless in use.

    A port number is free for any process once its owner is gone; one that
    a live process has opened again since is in use, not left behind.
    """
    in_use = used_by_live_processes()
    left = []
    for lock in sorted(locks):
        base = lock.removesuffix("_el").removesuffix("_sl")
        if {base, base + "_el", base + "_sl"} & in_use:
            continue
        files = [base, base + "_el", base + "_sl"] + ([f"sem.{base}_mutex"] if "_port" in base else [])
        left += [name for name in files if os.path.exists(os.path.join(SHM_DIR, name))]
    return left


@pytest.fixture
def step3_launch(procs):
    """Starts ``launch_py/step3_launch.py --demo --headless``; returns ``(Proc, marker)``.

    Every process of the launch has ``RTT_TEST_MARKER=marker`` in its
    environment.  At the end a launch still running gets SIGTERM (it stops
    its nodes, with SIGKILL after 5 s), and any process of it still left gets
    SIGKILL: a failed test leaves none behind.
    """
    started = []

    def start():
        marker = uuid.uuid4().hex
        launch = procs(
            [sys.executable, "-u", str(ROOT / "launch_py" / "step3_launch.py"), "--demo", "--headless"],
            env=dict(os.environ, RTT_TEST_MARKER=marker),
        )
        started.append((launch, marker))
        return launch, marker

    yield start
    for launch, marker in started:
        if launch.p.poll() is None:
            launch.p.send_signal(signal.SIGTERM)
            with contextlib.suppress(subprocess.TimeoutExpired):
                launch.p.wait(10)
        for pid in processes_with_marker(marker):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)


@pytest.mark.parametrize(
    "fault",
    # make test: a node killed; make test-more: the launch stopped
    ["sigkill-to-a-node", pytest.param("sigterm-to-the-launch", marks=pytest.mark.more)],
)
def test_launch_leaves_no_process_and_no_shared_memory(step3_launch, fault):
    """SIGTERM to a launch, or SIGKILL to one of its nodes (the launch then stops, failed):
    no process is left, and no Fast DDS file in /dev/shm that its nodes used and nobody uses now."""
    launch, marker = step3_launch()
    launch.wait_for_line(lambda line: line.startswith("[rtt_viewer]") and "first joint state" in line, timeout=60)
    launch.wait_for_line(lambda line: line.startswith("[rtt_joy]") and "the demo starts" in line, timeout=30)
    ours: set[str] = set()  # the lock files of the segments and ports the launch's processes own
    for pid in processes_with_marker(marker):
        ours |= fast_dds_shm_files(pid, mapped=False)
    owned_segments = {name for name in ours if re.fullmatch(r"fastrtps_[0-9a-z]{16}_el", name)}
    assert len(owned_segments) >= 3, f"Fast DDS's shared memory is not in use as expected: {sorted(ours)}"

    if fault == "sigterm-to-the-launch":
        launch.p.send_signal(signal.SIGTERM)
        assert launch.wait(15) == 0, launch.out
        assert "[launch] all nodes stopped cleanly" in launch.out
    else:
        joy_pid = int(re.search(r"\[launch\] started rtt_joy \(pid (\d+)\)", launch.out).group(1))
        joy_segment = fast_dds_shm_files(joy_pid, mapped=False) & owned_segments
        assert joy_segment, "rtt_joy holds no segment of its own"
        os.kill(joy_pid, signal.SIGKILL)
        assert launch.wait(15) == 1, launch.out
        assert "[launch] failed: rtt_joy (killed by SIGKILL)" in launch.out
        assert "(rtt_joy killed)" in launch.out  # the launcher says it removed what the killed node left
        assert not any(
            os.path.exists(os.path.join(SHM_DIR, name))
            for lock in joy_segment
            for name in (lock, lock.removesuffix("_el"))
        )
    assert wait_until(lambda: processes_with_marker(marker) == [], timeout=2.0), processes_with_marker(marker)
    assert left_behind(ours) == [], f"the launch left these in {SHM_DIR}"


def test_shared_memory_clean_up_keeps_what_a_live_owner_locks():
    """The launcher's clean-up on stand-in files: a locked segment or port stays, an unlocked one goes whole."""
    import fcntl

    tag = uuid.uuid4().hex
    segment, port = f"fastrtps_{tag[:16]}", f"fastrtps_port{100000 + int(tag[16:21], 16)}"  # no real port is > 65535
    files = [segment, segment + "_el", port, port + "_el"]
    for name in files:
        (Path(SHM_DIR) / name).touch()
    try:
        owner = os.open(os.path.join(SHM_DIR, port + "_el"), os.O_RDONLY)
        fcntl.flock(owner, fcntl.LOCK_EX)  # as a live Fast DDS owner holds its port
        assert remove_unused_fast_dds_shm({segment, port}) == [segment, segment + "_el"]
        assert os.path.exists(os.path.join(SHM_DIR, port)) and os.path.exists(os.path.join(SHM_DIR, port + "_el"))
        os.close(owner)  # the owner is gone
        assert remove_unused_fast_dds_shm({port + "_el"}) == [port, port + "_el", f"sem.{port}_mutex"]
    finally:
        for name in files + [f"sem.{port}_mutex"]:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(os.path.join(SHM_DIR, name))


def test_a_run_removes_only_the_unused_leftovers_that_appeared_while_it_ran():
    """make bench's clean-up (new_leftovers_removed) on stand-in segments: what was there before stays, what a
    live owner locks stays, an unused segment that appeared during the run goes, also when the run fails."""
    import fcntl

    def segment() -> str:
        return f"fastrtps_{uuid.uuid4().hex[:16]}"

    before, locked, dropped = segment(), segment(), segment()
    files = [name + suffix for name in (before, locked, dropped) for suffix in ("", "_el")]
    here = lambda name: os.path.exists(os.path.join(SHM_DIR, name))  # noqa: E731
    owner = None
    try:
        for name in (before, before + "_el"):
            Path(SHM_DIR, name).touch()
        with pytest.raises(RuntimeError, match="an experiment failed"), new_leftovers_removed():
            for name in files[2:]:
                Path(SHM_DIR, name).touch()
            owner = os.open(os.path.join(SHM_DIR, locked + "_el"), os.O_RDONLY)
            fcntl.flock(owner, fcntl.LOCK_EX)  # as a live Fast DDS participant holds its segment
            raise RuntimeError("an experiment failed")
        assert here(before) and here(before + "_el"), "a file from before the run was removed"
        assert here(locked) and here(locked + "_el"), "a segment its live owner locks was removed"
        assert not here(dropped) and not here(dropped + "_el"), "an unused leftover of the run stayed"
    finally:
        if owner is not None:
            os.close(owner)
        for name in files:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(os.path.join(SHM_DIR, name))


# ------------------------------------------------------------ the recorder (issue 26)
RECORD_SECONDS = 10.0  # s the recorder runs before its SIGKILL
MAX_LOST = 1.0  # s of messages a killed recorder may lose (issue 26)


def run_bag(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    """``rtt-bag ARGS`` as a process; its exit status and output."""
    return subprocess.run(module_command(RTT_BAG, *args), capture_output=True, text=True, timeout=timeout, cwd=ROOT)


@pytest.mark.more  # make test: the recorder stopped by a full disk, its file still read (below)
def test_recorder_killed_loses_less_than_a_second_and_its_file_is_read_played_and_recovered(nodes, tmp_path):
    """SIGKILL ``rtt-bag record`` 10 s into a Step 2 run: ``info`` reports at least 9 s of messages, the
    newest less than 1 s before the kill; ``play`` plays them; ``recover`` writes a file both stock readers
    read whole."""
    from test_bag import recovered_by_stock_readers

    sim = nodes.simulation()
    path = tmp_path / "killed.mcap"
    rec = nodes.start(RTT_BAG, "record", "/Tank/joint_state", "-o", str(path))
    rec.wait_for_line(lambda line: "subscribed to /Tank/joint_state" in line, timeout=60)
    time.sleep(RECORD_SECONDS)  # the fault's timing: the recording runs this long, then the kill
    killed_ns = time.time_ns()
    nodes.kill(rec)
    assert sim.p.poll() is None, sim.err

    info = run_bag("info", str(path), "--json")
    assert info.returncode == 0, info.stderr
    [line] = info.stderr.splitlines()
    assert line.startswith(f"rtt-bag: info: {path}: not closed (") and "messages recovered" in line, line
    summary = json.loads(info.stdout)
    lost_s = (killed_ns - summary["last_ns"]) * 1e-9
    print(
        f"killed after {RECORD_SECONDS} s: {summary['count']} messages over {summary['duration_s']:.3f} s in the "
        f"file ({path.stat().st_size} bytes); the newest {lost_s:.3f} s before the kill"
    )
    assert summary["closed"] is False
    assert summary["duration_s"] >= RECORD_SECONDS - MAX_LOST, summary
    assert lost_s < MAX_LOST
    assert summary["count"] >= 45 * (RECORD_SECONDS - MAX_LOST)  # 50 Hz: none missing in between (a little slack)

    played = run_bag("play", str(path), "--rate", "20")
    assert played.returncode == 0, played.stderr
    assert played.stderr.splitlines()[0].startswith(f"rtt-bag: play: {path}: not closed (")
    assert f"published {summary['count']} messages" in played.stdout

    whole = tmp_path / "whole.mcap"
    recovered = run_bag("recover", str(path), "-o", str(whole))
    assert recovered.returncode == 0, recovered.stderr
    assert f"wrote {summary['count']} messages" in recovered.stdout
    assert recovered_by_stock_readers(whole) == {"/Tank/joint_state": summary["count"]}


@pytest.fixture
def small_disk(tmp_path):
    """A 2 MiB tmpfs mounted for the test (root only), unmounted afterwards, also on failure."""
    folder = tmp_path / "disk"
    folder.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(folder)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode().strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=False)


def limit_file_size(limit: int):
    """A ``preexec_fn``: files this process writes stop at ``limit`` bytes, a write past it fails with EFBIG.

    SIGXFSZ, which the kernel sends then, must be ignored for ``write()`` to
    return the error (Python ignores it anyway; said here so it holds for any program).
    """
    import resource

    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return apply


@pytest.mark.parametrize(
    "fault",
    ["disk-full", pytest.param("file-size-limit", marks=pytest.mark.more)],  # make test: the disk full
)
def test_recorder_stops_with_one_line_when_the_disk_is_full_and_its_file_stays_readable(
    nodes, node, request, tmp_path, fault
):
    """A 2 MiB tmpfs (ENOSPC) or a 2 MiB file-size limit (EFBIG) fills while recording 8 MB/s: the
    recorder stops by itself with one line and exit status 1; the file keeps what was written through."""
    import random

    from sensor_msgs.msg import JointState

    from tutorial.tools.bag.info import bag_info

    from test_bag import recovered_by_stock_readers

    if fault == "disk-full":
        path = request.getfixturevalue("small_disk") / "full.mcap"
        extra = {}
    else:
        path = tmp_path / "limited.mcap"
        extra = {"preexec_fn": limit_file_size(2 * 1024 * 1024)}
    pub = node.create_publisher(JointState, "/bag_test/flood", 10)
    rec = nodes.start(
        "tutorial.tools.rtt_bag", "record", "/bag_test/flood", "-o", str(path), "--compression", "none", **extra
    )
    rec.wait_for_line(lambda line: "subscribed to /bag_test/flood" in line, timeout=60)
    assert wait_until(lambda: pub.get_subscription_count() >= 1, timeout=30)
    rng = random.Random(26)
    msg = JointState(name=["J"], position=[rng.random() for _ in range(2000)])  # 16 KB that do not compress
    deadline = time.monotonic() + 60
    sent = 0
    while rec.p.poll() is None and time.monotonic() < deadline:
        msg.header.stamp.sec = sent
        pub.publish(msg)
        sent += 1
        time.sleep(0.002)  # the flood's pace (about 8 MB/s), not a synchronisation
    assert rec.wait(30) == 1, (rec.out, rec.err)
    [line] = rec.err.splitlines()
    reason = "the disk is full (ENOSPC)" if fault == "disk-full" else "file-size limit) (EFBIG)"
    assert line.startswith(f"rtt-bag: record: stopped: {path}: writing failed: ") and reason in line, line
    written = int(re.search(r"after (\d+) messages were written through", line).group(1))
    print(f"{fault}: stopped after {sent} sent; {line}")

    info = bag_info(path)
    assert not info.closed and info.count == written > 0  # every chunk written through, and no more
    whole = tmp_path / "whole.mcap"  # beside the full disk
    run = run_bag("recover", str(path), "-o", str(whole))
    assert run.returncode == 0, run.stderr
    assert recovered_by_stock_readers(whole) == {"/bag_test/flood": info.count}
