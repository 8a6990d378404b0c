"""rtt-bag: files laid out as rosbag2 writes them, opened by stock MCAP readers; one clear line for a bad file."""

import json
import signal
import sys

import pytest
import yaml

from tutorial.interfaces import definitions
from tutorial.interfaces.definitions import UnknownMessageType
from tutorial.tools import rtt_bag
from tutorial.tools.bag import qos
from tutorial.tools.bag.info import bag_info, format_info
from tutorial.tools.bag.reader import BagError, check_file, iter_raw
from tutorial.tools.bag.series import joint_series
from tutorial.tools.bag.writer import BagWriter

from conftest import ROOT, module_command, wait_until

RTT_BAG = "tutorial.tools.rtt_bag"  # rtt-bag, run as python -m

SEP = "\n" + "=" * 80 + "\n"
INFINITE = {"sec": 9223372036, "nsec": 854775807}


def msg_text(package: str, name: str) -> str:
    for share in definitions.share_directories():
        path = share / package / "msg" / f"{name}.msg"
        if path.is_file():
            return path.read_text()
    raise AssertionError(f"{package}/{name}.msg is not installed")


# ------------------------------------------------------------ message definitions
def test_definition_is_the_installed_msg_files_joined_as_rosbag2_joins_them():
    encoding, text = definitions.full_text("sensor_msgs/msg/JointState")
    assert encoding == "ros2msg"
    assert text == (
        msg_text("sensor_msgs", "JointState")
        + SEP
        + "MSG: std_msgs/Header\n"
        + msg_text("std_msgs", "Header")
        + SEP
        + "MSG: builtin_interfaces/Time\n"
        + msg_text("builtin_interfaces", "Time")
    )
    assert "# This is a message that holds data" in text  # comments kept, as rosbag2 keeps them


def test_dependencies_come_depth_first_in_sorted_order_each_once():
    """And an independent parser (rosbags) reads every type in the text as its own Jazzy store has it."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    _, text = definitions.full_text("sensor_msgs/msg/MultiDOFJointState")
    assert [line for line in text.splitlines() if line.startswith("MSG: ")] == [
        "MSG: geometry_msgs/Transform",
        "MSG: geometry_msgs/Quaternion",
        "MSG: geometry_msgs/Vector3",
        "MSG: geometry_msgs/Twist",
        "MSG: geometry_msgs/Wrench",
        "MSG: std_msgs/Header",
        "MSG: builtin_interfaces/Time",
    ]  # Vector3 is used three times, written once
    parsed = get_types_from_msg(text, "sensor_msgs/msg/MultiDOFJointState")
    store = get_typestore(Stores.ROS2_JAZZY)
    assert len(parsed) == 8
    for name, fields in parsed.items():
        assert fields == store.fielddefs[name], name


def test_unknown_types_are_named_in_the_error():
    with pytest.raises(UnknownMessageType, match="nope_msgs"):
        definitions.full_text("nope_msgs/msg/Thing")
    with pytest.raises(UnknownMessageType, match=r"nope_msgs/msg/Thing is not installed"):
        definitions.message_class("nope_msgs/msg/Thing")
    with pytest.raises(UnknownMessageType, match="not a message type name"):
        definitions.message_class("JointState")
    assert definitions.message_class("sensor_msgs/msg/JointState").__name__ == "JointState"


# ------------------------------------------------------------ QoS metadata
EXPECTED_OFFER = """- history: unknown
  depth: 0
  reliability: reliable
  durability: volatile
  deadline:
    sec: 9223372036
    nsec: 854775807
  lifespan:
    sec: 9223372036
    nsec: 854775807
  liveliness: automatic
  liveliness_lease_duration:
    sec: 9223372036
    nsec: 854775807
  avoid_ros_namespace_conventions: false"""


def reliable_keep_last_1():
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)


def test_offered_qos_is_written_in_rosbag2s_yaml(node):
    """A reliable, keep last 1, volatile publisher, as discovery reports it, in rosbag2's format version 9."""
    from sensor_msgs.msg import JointState

    node.create_publisher(JointState, "/bag_test/qos", reliable_keep_last_1())
    assert wait_until(lambda: node.get_publishers_info_by_topic("/bag_test/qos"), timeout=5)
    offers = [qos.profile_dict(e.qos_profile) for e in node.get_publishers_info_by_topic("/bag_test/qos")]
    text = qos.serialize_profiles(offers)
    assert text == EXPECTED_OFFER
    assert qos.parse_profiles(text) == offers
    assert qos.serialize_profiles([]) == "[]" and qos.parse_profiles("[]") == []


def test_older_formats_are_read_as_rosbag2_reads_them():
    # rosbag2's own test string for bags of format version 4 (policies as integers).
    v4 = (
        "- history: 1\n  depth: 10\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 0\n    nsec: 0\n"
        "  lifespan:\n    sec: 0\n    nsec: 0\n  liveliness: 0\n  liveliness_lease_duration:\n    sec: 0\n"
        "    nsec: 0\n  avoid_ros_namespace_conventions: false\n"
    )
    [p] = qos.parse_profiles(v4)
    assert p == {**qos.DEFAULT_PROFILE}
    # Foxy-era Fast DDS wrote "infinite" as {2147483647, 4294967295}.
    foxy = EXPECTED_OFFER.replace("sec: 9223372036\n    nsec: 854775807", "sec: 2147483647\n    nsec: 4294967295", 1)
    assert qos.parse_profiles(foxy)[0]["deadline"] == INFINITE
    for bad in ("- [1, 2", "just text", "- history: keep_last"):
        with pytest.raises(qos.QosFormatError):
            qos.parse_profiles(bad)


def test_player_and_recorder_adapt_qos_as_rosbag2_does():
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, ReliabilityPolicy

    [reliable] = qos.parse_profiles(EXPECTED_OFFER)
    best_effort = {**reliable, "reliability": "best_effort"}
    latched = {**reliable, "durability": "transient_local"}
    # Player: one common offer is kept (history becomes keep last 10) ...
    offer, warning = qos.offer_for_recorded([reliable, {**reliable, "lifespan": {"sec": 1, "nsec": 0}}])
    assert warning is None and offer == {**reliable, "history": "keep_last", "depth": 10}
    # ... differing offers give rosbag2's default, with a warning.
    offer, warning = qos.offer_for_recorded([reliable, best_effort])
    assert offer == qos.DEFAULT_PROFILE and "different" in warning
    assert qos.offer_for_recorded([]) == (qos.DEFAULT_PROFILE, None)
    profile = qos.to_qos_profile(qos.offer_for_recorded([latched])[0])
    assert (profile.reliability, profile.durability, profile.history, profile.depth) == (
        ReliabilityPolicy.RELIABLE,
        DurabilityPolicy.TRANSIENT_LOCAL,
        HistoryPolicy.KEEP_LAST,
        10,
    )
    assert profile.deadline.nanoseconds == qos.INFINITE_NS

    # Recorder: reliable / transient local only when every publisher offers it.
    def request(*offers):
        r = qos.request_for_offers(list(offers), 1000)
        return r["reliability"], r["durability"], r["depth"]

    assert request(reliable, reliable) == ("reliable", "volatile", 1000)
    assert request(reliable, best_effort) == ("best_effort", "volatile", 1000)
    assert request(latched, latched) == ("reliable", "transient_local", 1000)
    assert request(latched, reliable) == ("reliable", "volatile", 1000)


# ------------------------------------------------------------ recording
def test_recorded_file_is_what_rosbag2_writes_and_stock_readers_open_it(ros, node, tmp_path):
    import time

    from mcap.reader import make_reader
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rclpy.serialization import deserialize_message
    from rosbags.highlevel import AnyReader
    from sensor_msgs.msg import JointState, Joy

    from tutorial.tools.bag.record import BagRecorder

    path = tmp_path / "drive.mcap"
    states = node.create_publisher(JointState, "/bag_test/joint_state", reliable_keep_last_1())
    joy = node.create_publisher(Joy, "/bag_test/joy", QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
    recorder = BagRecorder(path, ["/bag_test/joint_state", "bag_test/joy"], output=None).start()
    try:
        assert wait_until(lambda: len(recorder.received) == 2, timeout=10), recorder.received
        assert wait_until(lambda: states.get_subscription_count() and joy.get_subscription_count(), timeout=10)
        before = time.time_ns()
        sent_states, sent_joys = [], []
        for i in range(20):
            s = JointState(name=["TURRET_Y", "TURRET_P"], position=[0.01 * i, -0.02 * i])
            s.header.stamp.sec, s.header.stamp.nanosec = i, 500_000_000
            j = Joy(axes=[0.05 * i, 0.0], buttons=[i % 2])
            states.publish(s)
            joy.publish(j)
            sent_states.append(s)
            sent_joys.append(j)
            # Keep last 1 on the publisher: the next state would replace one not yet sent.
            assert wait_until(lambda n=i + 1: recorder.received["/bag_test/joint_state"] >= n, timeout=5)
        # Best effort on one machine: none of 20 slow messages is expected to be lost.
        assert wait_until(lambda: recorder.received["/bag_test/joy"] == 20, timeout=5), recorder.received
        after = time.time_ns()
    finally:
        stats = recorder.close()
    assert stats.per_topic == {"/bag_test/joint_state": 20, "/bag_test/joy": 20}
    assert recorder.close().messages == 40  # closing twice is harmless

    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        assert reader.get_header().profile == "ros2"
        summary = reader.get_summary()
        assert summary.statistics.message_count == 40
        channels = {c.topic: c for c in summary.channels.values()}
        for topic, type_name, reliability in (
            ("/bag_test/joint_state", "sensor_msgs/msg/JointState", "reliable"),
            ("/bag_test/joy", "sensor_msgs/msg/Joy", "best_effort"),
        ):
            channel = channels[topic]
            schema = summary.schemas[channel.schema_id]
            assert (schema.name, schema.encoding) == (type_name, "ros2msg")
            assert schema.data.decode() == definitions.full_text(type_name)[1]
            assert channel.message_encoding == "cdr"
            assert set(channel.metadata) == {"offered_qos_profiles", "topic_type_hash"}
            [offer] = qos.parse_profiles(channel.metadata["offered_qos_profiles"])
            assert (offer["reliability"], offer["durability"]) == (reliability, "volatile")
            assert channel.metadata["topic_type_hash"].startswith("RIHS01_")
            assert len(channel.metadata["topic_type_hash"]) == len("RIHS01_") + 64
        [meta] = list(reader.iter_metadata())
        bag = yaml.safe_load(meta.metadata["serialized_metadata"])
        assert meta.name == "rosbag2" and bag["version"] == 9 and bag["storage_identifier"] == "mcap"
        assert {
            t["topic_metadata"]["name"]: t["message_count"] for t in bag["topics_with_message_count"]
        } == stats.per_topic
        got = {"/bag_test/joint_state": [], "/bag_test/joy": []}
        for _schema, channel, message in reader.iter_messages(log_time_order=True):
            assert before <= message.log_time <= after
            assert message.publish_time <= message.log_time  # source time, then receive time
            got[channel.topic].append(message.data)
    # The CDR bytes as published (compared decoded: CDR's alignment padding bytes are unspecified).
    assert [deserialize_message(d, JointState) for d in got["/bag_test/joint_state"]] == sent_states
    assert [deserialize_message(d, Joy) for d in got["/bag_test/joy"]] == sent_joys

    # A second, independent reader: rosbags.
    with AnyReader([path]) as other:
        assert sorted((c.topic, c.msgtype, c.msgcount) for c in other.connections) == [
            ("/bag_test/joint_state", "sensor_msgs/msg/JointState", 20),
            ("/bag_test/joy", "sensor_msgs/msg/Joy", 20),
        ]
        last = [
            other.deserialize(raw, c.msgtype) for c, _t, raw in other.messages() if c.topic == "/bag_test/joint_state"
        ][-1]
        assert list(last.name) == ["TURRET_Y", "TURRET_P"] and list(last.position) == [0.19, -0.38]

    # Our own ROS-free reading.
    series = joint_series(path, "/bag_test/joint_state")
    assert list(series.positions) == ["TURRET_Y", "TURRET_P"]
    assert series.positions["TURRET_P"].tolist() == [-0.02 * i for i in range(20)]
    assert series.stamp.tolist() == [i + 0.5 for i in range(20)]
    info = bag_info(path)
    assert [(t.topic, t.count) for t in info.topics] == [("/bag_test/joint_state", 20), ("/bag_test/joy", 20)]
    assert info.topic("/bag_test/joy").rate_hz > 0
    text = format_info(info)
    assert "/bag_test/joy" in text and "sensor_msgs/msg/Joy" in text and "best_effort, volatile" in text


def test_all_topics_takes_late_publishers_but_not_hidden_topics(ros, node, tmp_path):
    """Here on a node the caller owns and spins (a notebook's), which outlives the recorder."""
    from std_msgs.msg import String

    from tutorial.ros.spin import SpinThread
    from tutorial.tools.bag.record import BagRecorder

    own = ros.create_node("test_bag_own_node")
    spin = SpinThread(own).start()
    recorder = BagRecorder(tmp_path / "all.mcap", all_topics=True, node=own, output=None).start()
    try:
        node.create_publisher(String, "/_bag_test_hidden", 10)
        late = node.create_publisher(String, "/bag_test/late", 10)  # after the recorder started
        assert wait_until(lambda: "/bag_test/late" in recorder.received, timeout=10)
        assert wait_until(lambda: late.get_subscription_count() >= 1, timeout=10)
        late.publish(String(data="hello"))
        assert wait_until(lambda: recorder.received["/bag_test/late"] == 1, timeout=5)
        assert "/_bag_test_hidden" not in recorder.received  # both were in the graph at once
        recorder.close()
        assert own.get_subscriptions_info_by_topic("/bag_test/late") == []  # the node lives on, without them
    finally:
        recorder.close()
        spin.stop()
        own.destroy_node()
    [msg] = [m for m in iter_raw(tmp_path / "all.mcap") if m.topic == "/bag_test/late"]
    assert msg.type == "std_msgs/msg/String"


# ------------------------------------------------------------ playing
def timed_bag(path):
    """/bag_test/a (recorded transient local) and /bag_test/b: Joy messages 0..9, 50 ms apart, written without ROS."""
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import Joy

    latched = EXPECTED_OFFER.replace("durability: volatile", "durability: transient_local")
    writer = BagWriter(path)
    for topic, offer in (("/bag_test/a", latched), ("/bag_test/b", EXPECTED_OFFER)):
        writer.add_topic(topic, "sensor_msgs/msg/Joy", definitions.full_text("sensor_msgs/msg/Joy"), offer)
    for i in range(10):
        for topic in ("/bag_test/a", "/bag_test/b"):
            t = 1_000_000_000 + i * 50_000_000
            writer.write(topic, t, t, serialize_message(Joy(axes=[float(i)])))
    writer.close()
    return path


def test_player_keeps_the_timing_and_honours_rate_offset_topics_and_loop(ros, node, tmp_path):
    import threading
    import time

    from sensor_msgs.msg import Joy

    from tutorial.ros.spin import SpinThread
    from tutorial.tools.bag.play import BagPlayer

    bag = timed_bag(tmp_path / "timed.mcap")
    lock = threading.Lock()  # the spin thread appends, the test thread reads
    got: dict[str, list] = {"/bag_test/a": [], "/bag_test/b": []}

    def keep(topic):
        def on_message(msg):
            with lock:
                got[topic].append((int(msg.axes[0]), time.monotonic()))

        return on_message

    for topic in got:
        node.create_subscription(Joy, topic, keep(topic), 100)
    spin = SpinThread(node).start()
    try:
        # Twice as fast, from 0.2 s into the bag, one topic only.
        player = BagPlayer(bag, rate=2.0, start_offset=0.2, topics=["bag_test/a"], delay=0.5, output=None)
        stats = player.play()
        [offer] = node.get_publishers_info_by_topic("/bag_test/a")
        assert (offer.qos_profile.reliability.short_key, offer.qos_profile.durability.short_key) == (
            "reliable",
            "transient_local",
        )  # as recorded
        player.close()
        assert stats.published == {"/bag_test/a": 6} and stats.loops == 1 and not stats.stopped
        assert wait_until(lambda: len(got["/bag_test/a"]) == 6, timeout=5), got
        with lock:
            numbers = [i for i, _t in got["/bag_test/a"]]
            gap = got["/bag_test/a"][-1][1] - got["/bag_test/a"][0][1]
        assert numbers == [4, 5, 6, 7, 8, 9] and got["/bag_test/b"] == []
        assert 0.1 <= gap < 1.0  # 0.25 s of recording at rate 2: 0.125 s (measured on arrival: jitter)
        # Looped, on a background thread, until closed.
        looping = BagPlayer(bag, loop=True, topics=["/bag_test/b"], delay=0.2, output=None).start()
        assert wait_until(lambda: len(got["/bag_test/b"]) >= 25, timeout=10), got["/bag_test/b"]
        stats = looping.close()
        assert looping.error is None
        assert stats.loops >= 2 and stats.stopped
        with lock:
            assert [i for i, _t in got["/bag_test/b"]][:20] == list(range(10)) * 2
    finally:
        spin.stop()


# ------------------------------------------------------------ bad files: one line, exit status 2
def good_bag(path, type_name="sensor_msgs/msg/JointState", n=2000):
    """A bag written without ROS: ``n`` JointState messages on /Tank/joint_state, 1 ms apart.

    The writer's clock runs 2**-10 s (about 1 ms) a message, exactly in binary, so its
    write-through closes a chunk after every 512 of them, as a recorder's would:
    2000 make 4 chunks (see :func:`chunk_ends`).
    """
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import JointState

    now = [0.0]
    writer = BagWriter(path, compression="zstd", clock=lambda: now[0])
    definition = definitions.full_text(type_name) if type_name.startswith("sensor_msgs") else ("ros2msg", "int32 x")
    writer.add_topic("/Tank/joint_state", type_name, definition, EXPECTED_OFFER)
    for i in range(n):
        now[0] = i * 2**-10
        data = serialize_message(JointState(name=["TURRET_Y"], position=[i * 1e-3]))
        writer.write("/Tank/joint_state", 1_000_000_000 + i * 1_000_000, 1_000_000_000 + i * 1_000_000, data)
    writer.close()
    return path


def bad_bags(tmp_path) -> dict:
    data = good_bag(tmp_path / "good.mcap").read_bytes()
    files = {"garbage": b"\x00not an mcap file at all" * 50, "empty": b"", "magic cut short": data[:5]}
    with open(tmp_path / "good.mcap", "rb") as f:
        from mcap.reader import make_reader

        chunk = make_reader(f).get_summary().chunk_indexes[1]
    corrupt = bytearray(data)
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2  # zstd data: no longer decompresses or matches its CRC
    corrupt[middle : middle + 64] = bytes(64)
    files["corrupt"] = bytes(corrupt)
    paths = {}
    for name, content in files.items():
        paths[name] = tmp_path / f"{name.replace(' ', '_')}.mcap"
        paths[name].write_bytes(content)
    paths["missing"] = tmp_path / "missing.mcap"
    paths["a folder"] = tmp_path
    return paths


REASONS = {
    "garbage": "not an MCAP file",
    "magic cut short": "not an MCAP file",
    "empty": "empty",
    "corrupt": "corrupt MCAP file",
    "missing": "no such file",
    "a folder": "not a file",
}


@pytest.mark.parametrize("command", ["info", "play", "recover"])
def test_a_bad_file_gives_one_clear_line_and_status_2(tmp_path, capsys, command):
    for name, path in bad_bags(tmp_path).items():
        if command == "recover" and name == "corrupt":
            continue  # recover reads around a damaged chunk: below
        extra = ["-o", str(tmp_path / "out.mcap")] if command == "recover" else []
        assert rtt_bag.main(["rtt-bag", command, str(path), *extra]) == 2, name
        out, err = capsys.readouterr()
        assert out == "", (name, out)
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"rtt-bag: {command}: {path}: "), (name, err)
        assert REASONS[name] in lines[0], (name, err)
        assert not (tmp_path / "out.mcap").exists()


@pytest.mark.cross_process
def test_a_bad_file_is_one_line_from_the_real_program_too(tmp_path):
    import subprocess

    path = bad_bags(tmp_path)["garbage"]
    done = subprocess.run(
        module_command(RTT_BAG, "info", str(path)),
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
    )
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [f"rtt-bag: info: {path}: not an MCAP file (no MCAP magic at its start)"]


# ------------------------------------------------------------ files that were not closed: read, not refused
def cut(path, dest, fraction: float):
    """A copy of the first ``fraction`` of ``path``'s bytes: what a killed recorder or a full disk leaves."""
    data = path.read_bytes()
    dest.write_bytes(data[: int(len(data) * fraction)])
    return dest


def chunk_ends(path) -> list[tuple[int, int]]:
    """``(byte where the chunk ends, messages up to and including it)`` for each chunk of a closed good_bag file."""
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        chunks = sorted(make_reader(f).get_summary().chunk_indexes, key=lambda c: c.chunk_start_offset)
    return [
        (c.chunk_start_offset + c.chunk_length, (c.message_end_time - 1_000_000_000) // 1_000_000 + 1) for c in chunks
    ]


def whole_chunk_messages(path, size: int, ends=None) -> int:
    """How many messages the chunks that end within the first ``size`` bytes hold."""
    return max([n for end, n in (ends or chunk_ends(path)) if end <= size], default=0)


def test_write_through_closes_a_chunk_every_half_second_of_messages(tmp_path):
    """good_bag's writer sees a message every 2**-10 s: a chunk is closed by the message 0.5 s after its first."""
    path = good_bag(tmp_path / "good.mcap")
    assert [n for _end, n in chunk_ends(path)] == [513, 1026, 1539, 2000]
    assert BagWriter(tmp_path / "x.mcap").close().write_throughs == 0  # no message: no chunk


def test_a_file_that_was_not_closed_is_read_to_its_last_whole_chunk(tmp_path, capsys):
    good = good_bag(tmp_path / "good.mcap")
    killed = cut(good, tmp_path / "killed.mcap", 2 / 3)  # the summary and the last chunks are gone
    n = whole_chunk_messages(good, killed.stat().st_size)
    assert n == 1539  # three whole chunks
    info = bag_info(killed)
    assert not info.closed and info.recovery.damaged_chunks == 0
    assert info.count == info.recovery.messages == n
    assert info.topic("/Tank/joint_state").span_s == pytest.approx((n - 1) * 1e-3)
    assert "the file ends inside the record at byte" in info.recovery.stop
    assert [m.log_time for m in iter_raw(killed)] == [1_000_000_000 + i * 1_000_000 for i in range(n)]
    series = joint_series(killed)
    assert series.positions["TURRET_Y"].tolist() == [i * 1e-3 for i in range(n)]
    with pytest.raises(BagError, match="truncated MCAP file"):
        check_file(killed)  # not whole: who needs a whole file is told

    assert rtt_bag.main(["rtt-bag", "info", str(killed)]) == 0
    out, err = capsys.readouterr()
    assert err.splitlines() == [
        f"rtt-bag: info: {killed}: not closed (the recording was cut short: killed, or the disk filled): "
        f"{n} messages recovered from its complete records ({info.recovery.stop}); rtt-bag recover writes a closed copy"
    ]
    assert f"Messages:          {n}" in out and "Not closed:" in out
    assert rtt_bag.main(["rtt-bag", "info", str(killed), "--json"]) == 0
    reported = json.loads(capsys.readouterr().out)
    assert reported["closed"] is False and reported["recovery"]["messages"] == n


def test_a_file_cut_anywhere_gives_its_whole_chunks_never_an_error(tmp_path):
    good = good_bag(tmp_path / "good.mcap", n=1200)
    data, ends = good.read_bytes(), chunk_ends(good)
    for size in range(9, len(data) - 8, len(data) // 60):  # 60 cuts, header to summary
        (tmp_path / "cut.mcap").write_bytes(data[:size])
        n = whole_chunk_messages(good, size, ends)
        assert bag_info(tmp_path / "cut.mcap").count == n, size
        assert [m.log_time for m in iter_raw(tmp_path / "cut.mcap")] == [
            1_000_000_000 + i * 1_000_000 for i in range(n)
        ], size


def recovered_by_stock_readers(path) -> dict[str, int]:
    """Messages per topic as ``mcap`` (its summary and its messages) and ``rosbags`` read ``path``; all must agree."""
    from mcap.reader import make_reader
    from rosbags.highlevel import AnyReader

    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        by_summary = {summary.channels[c].topic: n for c, n in summary.statistics.channel_message_counts.items()}
        by_reading: dict[str, int] = {}
        for _s, channel, _m in reader.iter_messages():
            by_reading[channel.topic] = by_reading.get(channel.topic, 0) + 1
    with AnyReader([path]) as other:
        by_rosbags = {c.topic: c.msgcount for c in other.connections}
        read = sum(1 for _ in other.messages())
    assert by_summary == by_reading == by_rosbags, (by_summary, by_reading, by_rosbags)
    assert read == sum(by_rosbags.values())
    return by_summary


def test_recover_writes_a_whole_indexed_file_of_what_could_be_read(tmp_path, capsys):
    good = good_bag(tmp_path / "good.mcap")
    killed = cut(good, tmp_path / "killed.mcap", 2 / 3)
    before = killed.read_bytes()
    out = tmp_path / "whole.mcap"
    assert rtt_bag.main(["rtt-bag", "recover", str(killed), "-o", str(out)]) == 0
    line = capsys.readouterr().out.strip()
    assert line.startswith(f"[rtt-bag] {killed} (not closed): 1539 messages recovered") and "closed and indexed" in line
    assert killed.read_bytes() == before  # the input is only read
    check_file(out)
    assert recovered_by_stock_readers(out) == {"/Tank/joint_state": 1539}
    assert [m.data for m in iter_raw(out)] == [m.data for m in iter_raw(good)][:1539]
    with open(out, "rb") as f:
        from mcap.reader import make_reader

        reader = make_reader(f)
        [meta] = list(reader.iter_metadata())
        [channel] = reader.get_summary().channels.values()
    bag = yaml.safe_load(meta.metadata["serialized_metadata"])  # rosbag2's own record counts what was recovered
    assert bag["message_count"] == 1539 and bag["topics_with_message_count"][0]["message_count"] == 1539
    assert channel.metadata["offered_qos_profiles"] == EXPECTED_OFFER  # the channel's QoS kept
    # Once more over an existing file: refused, then allowed.
    assert rtt_bag.main(["rtt-bag", "recover", str(killed), "-o", str(out)]) == 2
    assert "exists already" in capsys.readouterr().err
    assert rtt_bag.main(["rtt-bag", "recover", str(killed), "-o", str(killed)]) == 2
    assert "the copy must go to another file" in capsys.readouterr().err
    assert rtt_bag.main(["rtt-bag", "recover", str(killed), "-o", str(out), "--overwrite"]) == 0


def test_recover_skips_a_damaged_chunk_and_keeps_the_rest(tmp_path, capsys):
    corrupt = bad_bags(tmp_path)["corrupt"]  # the second of four chunks is damaged
    assert rtt_bag.main(["rtt-bag", "info", str(corrupt)]) == 2  # a closed file that lies is refused ...
    assert "rtt-bag recover copies what can still be read" in capsys.readouterr().err
    out = tmp_path / "whole.mcap"
    assert rtt_bag.main(["rtt-bag", "recover", str(corrupt), "-o", str(out)]) == 0  # ... and recovered
    assert "1 damaged chunk skipped" in capsys.readouterr().out
    assert recovered_by_stock_readers(out) == {"/Tank/joint_state": 2000 - (1026 - 513)}
    assert [m.log_time for m in iter_raw(out)][512:514] == [1_512_000_000, 2_026_000_000]  # the second chunk gone


def test_an_unknown_message_type_is_listed_but_not_played(tmp_path, capsys):
    path = good_bag(tmp_path / "unknown.mcap", type_name="nope_msgs/msg/Thing", n=3)
    assert rtt_bag.main(["rtt-bag", "info", str(path)]) == 0
    assert "nope_msgs/msg/Thing" in capsys.readouterr().out
    assert rtt_bag.main(["rtt-bag", "info", str(path), "--json"]) == 0
    [topic] = json.loads(capsys.readouterr().out)["topics"]
    assert (topic["topic"], topic["type"], topic["count"], topic["rate_hz"]) == (
        "/Tank/joint_state",
        "nope_msgs/msg/Thing",
        3,
        pytest.approx(1000.0),
    )
    assert rtt_bag.main(["rtt-bag", "play", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [
        f"rtt-bag: play: {path}: cannot play /Tank/joint_state: message type "
        "nope_msgs/msg/Thing is not installed here (no Python module nope_msgs.msg)"
    ]
    assert rtt_bag.main(["rtt-bag", "play", str(tmp_path / "unknown.mcap"), "--topics", "/nothing"]) == 2
    assert "no messages on /nothing" in capsys.readouterr().err


def test_record_refuses_an_existing_file(tmp_path, capsys):
    path = good_bag(tmp_path / "kept.mcap", n=3)
    before = path.read_bytes()
    assert rtt_bag.main(["rtt-bag", "record", "/joy", "-o", str(path)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"rtt-bag: record: {path} exists already; choose another name, or replace it (rtt-bag record --overwrite, "
        "overwrite=True)"
    ]
    assert path.read_bytes() == before


# ------------------------------------------------------------ stopping a recording
@pytest.mark.parametrize(  # make test: Ctrl-C, as a learner stops it
    "sig", [signal.SIGINT, pytest.param(signal.SIGTERM, marks=pytest.mark.more)], ids=["ctrl-c", "sigterm"]
)
def test_a_stopped_recording_is_a_whole_file(procs, node, tmp_path, sig):
    """Stopped while messages still arrive, the file is closed whole: summary, indexes, every message counted."""
    from sensor_msgs.msg import JointState

    path = tmp_path / "stopped.mcap"
    rec = procs(module_command(RTT_BAG, "record", "/bag_test/stop", "-o", str(path)))
    pub = node.create_publisher(JointState, "/bag_test/stop", 100)
    rec.wait_for_line(lambda line: "subscribed to /bag_test/stop" in line, timeout=30)
    assert wait_until(lambda: pub.get_subscription_count() >= 1, timeout=10)
    for i in range(300):
        pub.publish(JointState(name=["A"], position=[float(i)]))
    rec.p.send_signal(sig)  # messages are still on their way
    assert rec.wait(30) == 0, rec.err
    assert "Traceback" not in rec.err
    line = rec.wait_for_line(lambda line: "] wrote " in line, timeout=1)
    written, received = (int(n) for n in line.split("] wrote ")[1].split(" messages")[0].split(" of "))
    assert written == received >= 1  # nothing received was lost to the writer
    check_file(path)
    assert bag_info(path).count == written
    with open(path, "rb") as f:
        from mcap.reader import make_reader

        assert make_reader(f).get_summary().statistics.message_count == written


def test_duration_ends_a_recording_by_itself(procs, tmp_path):
    path = tmp_path / "short.mcap"
    rec = procs(module_command(RTT_BAG, "record", "/bag_test/nothing", "-o", str(path), "--duration", "1"))
    assert rec.wait(30) == 0, rec.err
    assert "wrote 0 of 0 messages received" in rec.out
    assert bag_info(path).count == 0


@pytest.mark.cross_process
def test_reading_needs_no_ros():
    """The reading half imports neither rclpy nor a message package (a notebook can read a bag anywhere)."""
    import subprocess

    code = (
        "import sys; import tutorial.tools.bag; from tutorial.tools.bag import joint_series, bag_info, format_info; "
        "import tutorial.tools.bag.reader, tutorial.tools.bag.info; "
        "bad = [m for m in sys.modules if m.startswith(('rclpy', 'sensor_msgs'))]; print(bad)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert done.stdout.strip() == "[]", done.stderr
