"""Record topics to an MCAP file as ``ros2 bag record -s mcap`` does.

    from tutorial.tools.bag.record import BagRecorder
    rec = BagRecorder("drive.mcap", ["/joy", "/Tank/joint_state"]).start()
    ...                      # the drive runs; callbacks write on the recorder's spin thread
    stats = rec.close()      # the file is complete: indexes, summary, metadata
    stats.per_topic          # {'/joy': 120, '/Tank/joint_state': 301}

What it does, and where rosbag2 (Jazzy's ``rosbag2_transport::Recorder``)
does the same:

* Topics are found by polling the ROS graph every 0.1 s (rosbag2's
  ``topic_polling_interval``).  A topic is recorded once it has a publisher
  and exactly one type, and that type is installed here; hidden topics
  (a name part starting with ``_``) are left out, as rosbag2 leaves them.
* Each subscription is *raw*: the callback gets the CDR bytes, which go to
  the file unchanged, never deserialized.  Its callback also takes rmw's
  message info, so ``log_time`` is the middleware's receive time and
  ``publish_time`` the publisher's source time, as rosbag2 writes them.
* QoS requested: reliable only if every publisher offers reliable,
  transient local only if every publisher offers it
  (:func:`tutorial.tools.bag.qos.request_for_offers`), so it matches them all.
  History: keep last :data:`SUBSCRIPTION_DEPTH` (rosbag2 asks for 10).
  History does not affect matching; the deeper queue lets a Python
  executor that stalls for a few milliseconds at 1 kHz catch up instead of
  losing the overwritten messages.
* The publishers' offered QoS and the type hash are stored as the
  channel's ``offered_qos_profiles`` and ``topic_type_hash``.  Publishers
  that appear later are not added to the stored list (rosbag2's limit too).
* Write-through (:mod:`tutorial.tools.bag.writer`): a timer every 0.1 s, beside
  the check at each message, closes a chunk that is 0.5 s old and flushes
  and fsyncs it, so a killed recorder loses less than the last second.
  A write that fails (a full disk, a file-size limit) stops the recording:
  :attr:`BagRecorder.failure` says why in one line, and the file keeps
  everything written through before (``rtt-bag info`` reads it,
  ``rtt-bag recover`` closes a copy).
"""

from __future__ import annotations

import threading
import time

from tutorial.interfaces.definitions import UnknownMessageType, full_text, message_class
from tutorial.tools.bag.qos import profile_dict, request_for_offers, serialize_profiles, to_qos_profile
from tutorial.tools.bag.writer import WRITE_THROUGH_CHECK, BagWriter, WriteStats

NODE_NAME = "rtt_bag"
POLL_PERIOD = 0.1  # s between looks at the ROS graph for new topics (rosbag2's default)
SUBSCRIPTION_DEPTH = 1000  # keep last: 1 s at 1 kHz (see the module docstring)


def normalize_topic(name: str) -> str:
    """``joy`` -> ``/joy``: topic names as the graph reports them (no namespace remapping here)."""
    return name if name.startswith("/") else "/" + name


def is_hidden(topic: str) -> bool:
    """Whether a topic is hidden (a name part starts with ``_``), as rclpy and rosbag2 define it."""
    return any(part.startswith("_") for part in topic.split("/"))


class BagRecorder:
    """Records topics to an MCAP file that the ROS 2 tools open.

    Args:
        path: the ``.mcap`` file to create.
        topics: topic names to record (they may appear later).
        all_topics: record every (non-hidden) topic that has a publisher, now or later.
        node: an ``rclpy`` node to use, spun by its owner; None (default):
            the recorder creates node ``node_name`` and spins it on its own
            :class:`tutorial.ros.spin.SpinThread`.
        node_name: the name of the node it creates.
        compression: chunk compression, ``zstd`` (default), ``lz4`` or ``none``.
        overwrite: replace an existing file (default: refuse).
        output: called with each status line (default ``print``).
        tf: also record every body's robot description, odometry and joint
            states, and write ``/tf``, ``/tf_static`` and ``/robot_description``
            computed from them (:mod:`tutorial.tools.bag.record_tf`).
        tf_frame_prefix: with ``tf``, put before every frame of a body;
            ``{body}`` in it is the body's name (``"{body}/"`` for several robots).
        write_through: the writer's policy (:class:`~tutorial.tools.bag.writer.BagWriter`);
            False only for the benchmark's baseline.

    Raises:
        ValueError: no topics, ``all_topics`` nor ``tf``, a bad ``compression`` or ``tf_frame_prefix``.
        tutorial.tools.bag.writer.BagWriteError: the file cannot be created.

    The file is created by the constructor; :meth:`start` subscribes.
    ``rclpy`` must be initialised first (``tutorial.ros.env.init`` or, in a
    notebook, ``init_ros()``).

    Threads: construct, :meth:`start` and :meth:`close` on one owner thread
    (the main thread, or the notebook kernel's).  Discovery and the
    subscription callbacks run on the spin thread; they hand each message
    straight to the :class:`~tutorial.tools.bag.writer.BagWriter`, whose lock
    keeps :meth:`close` from finishing the file in the middle of a write.
    """

    def __init__(
        self,
        path,
        topics=(),
        *,
        all_topics: bool = False,
        node=None,
        node_name: str = NODE_NAME,
        compression: str = "zstd",
        overwrite: bool = False,
        output=print,
        tf: bool = False,
        tf_frame_prefix: str = "",
        write_through: bool = True,
    ):
        self.topics_wanted = [normalize_topic(t) for t in topics]
        if not self.topics_wanted and not all_topics and not tf:
            raise ValueError("name the topics to record, or record all topics")
        if tf:
            from tutorial.tools.bag.record_tf import check_frame_prefix

            check_frame_prefix(tf_frame_prefix)  # before the file is made
        self.all_topics = all_topics
        self.output = output
        self.writer = BagWriter(path, compression=compression, overwrite=overwrite, write_through=write_through)
        self.path = self.writer.path
        self.tf = None
        if tf:  # the TF computation is its own module's; the recorder only feeds it
            from tutorial.tools.bag.record_tf import TfRecording

            self.tf = TfRecording(self.writer, self._say, tf_frame_prefix)
        self._given_node = node
        self.node = node
        self.node_name = node_name
        self._spin = None
        self._timer = None
        self._write_through_timer = None
        self._subscriptions: dict[str, object] = {}
        # Discovery (spin thread) adds subscriptions, close() (owner thread) removes them: with a
        # node spun by its owner the two can overlap, so both hold this lock, and discovery
        # stops for good once close() has set _closing.
        self._graph_lock = threading.Lock()
        self._closing = False
        self._skipped: set[str] = set()  # topics reported once as not recordable
        self.received: dict[str, int] = {}  # per topic, counted on the spin thread
        self.started_at: float | None = None

    # ------------------------------------------------------------ owner thread
    def start(self) -> BagRecorder:
        """Create the node if needed, subscribe to what exists now, keep polling for the rest; returns self."""
        import rclpy

        from tutorial.ros import spin as ros_spin

        if self.node is None:
            self.node = rclpy.create_node(self.node_name)
        self.started_at = time.monotonic()
        wanted = "all topics" if self.all_topics else " ".join(self.topics_wanted) or "no topic"
        wanted += ", and TF from every robot description" if self.tf is not None else ""
        self._say(f"recording {wanted} to {self.path}")
        self._discover()
        self._timer = self.node.create_timer(POLL_PERIOD, self._discover)
        if self.writer.write_through:
            self._write_through_timer = self.node.create_timer(WRITE_THROUGH_CHECK, self.writer.write_through_due)
        if self._given_node is None:
            self._spin = ros_spin.SpinThread(self.node).start()
        return self

    @property
    def error(self) -> BaseException | None:
        """An exception that ended the recorder's own spin thread (a bug: a failed write is :attr:`failure`)."""
        return self._spin.error if self._spin is not None else None

    @property
    def failure(self) -> str | None:
        """Why the recording stopped by itself, in one line (a failed write: a full disk...), else None (any thread)."""
        if self.writer.error is not None:
            return f"{self.writer.error}; the file was not closed: rtt-bag info and play read it as it is"
        if self.error is not None:
            return f"the recorder's spin thread stopped: {self.error!r}"
        return None

    def stats(self) -> WriteStats:
        """Messages written so far, by topic (any thread)."""
        return self.writer.stats()

    def close(self) -> WriteStats:
        """Stop recording and finish the file (indexes, summary, metadata); what was written.

        Safe to call twice, and after a failed :meth:`start`.  A node the
        recorder created is destroyed; a given node keeps living, without
        the recorder's subscriptions and timer.
        """
        if self._spin is not None:
            self._spin.stop()
        if self.node is not None:
            with self._graph_lock:
                self._closing = True
                for timer in (self._timer, self._write_through_timer):
                    if timer is not None:
                        self.node.destroy_timer(timer)
                self._timer = self._write_through_timer = None
                for sub in self._subscriptions.values():
                    self.node.destroy_subscription(sub)
                self._subscriptions.clear()
            if self._given_node is None:
                self.node.destroy_node()
                self.node = None
        if self.writer.closed:
            return self.writer.stats()
        stats = self.writer.close()
        per_topic = ", ".join(f"{t} {n}" for t, n in stats.per_topic.items()) or "no topics"
        computed = sum(self.tf.written.values()) if self.tf is not None else 0
        if self.writer.error is None:
            self._say(
                f"wrote {stats.messages - computed} of {sum(self.received.values())} messages received"
                + (f" and {computed} computed for TF" if computed else "")
                + f" ({per_topic}) to {self.path}, {stats.size_bytes} bytes"
            )
        else:
            self._say(
                f"stopped: {stats.written_through} of {sum(self.received.values())} messages received are in "
                f"{self.path} ({stats.size_bytes} bytes, not closed)"
            )
        return stats

    def __enter__(self) -> BagRecorder:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close()

    # ------------------------------------------------------------ spin thread
    def _discover(self) -> None:
        """Subscribe to every wanted topic that now has a publisher (timer callback, spin thread)."""
        with self._graph_lock:
            if not self._closing:
                self._discover_locked()

    def _discover_locked(self) -> None:
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self._subscriptions or topic in self._skipped:
                continue
            if self.all_topics:
                if is_hidden(topic):
                    continue
            elif topic not in self.topics_wanted and not (self.tf is not None and self.tf.wants(topic, types[0])):
                continue
            if len(types) != 1:
                self._skip(topic, f"it has {len(types)} types ({', '.join(types)})")
                continue
            endpoints = self.node.get_publishers_info_by_topic(topic)
            if not endpoints:
                continue  # rosbag2 waits for a publisher too: it says which QoS to request
            self._subscribe(topic, types[0], endpoints)

    def _subscribe(self, topic: str, type_name: str, endpoints) -> None:
        try:
            msg_type = message_class(type_name)
        except UnknownMessageType as exc:
            self._skip(topic, str(exc))
            return
        try:
            definition = full_text(type_name)
        except UnknownMessageType as exc:
            definition = ("unknown", "")  # what rosbag2 writes when it finds no definition
            self._say(f"WARNING: {topic}: no message definition stored ({exc})")
        offers = [profile_dict(e.qos_profile) for e in endpoints]
        # rosbag2 stores the publishers' common type hash, or "" when they disagree or give none.
        hashes = {str(e.topic_type_hash) for e in endpoints if str(e.topic_type_hash).startswith("RIHS")}
        type_hash = hashes.pop() if len(hashes) == 1 else ""
        self.writer.add_topic(topic, type_name, definition, serialize_profiles(offers), type_hash)
        request = request_for_offers(offers, SUBSCRIPTION_DEPTH)
        self.received[topic] = 0

        tf = self.tf

        def on_message(data: bytes, info: dict, topic=topic) -> None:
            # rmw's receive time (ns since the epoch); 0 where a middleware does not give it.
            received = info.get("received_timestamp") or time.time_ns()
            self.received[topic] += 1
            self.writer.write(topic, received, info.get("source_timestamp") or received, data)
            if tf is not None:
                tf.on_message(topic, type_name, data, received)

        self._subscriptions[topic] = self.node.create_subscription(
            msg_type, topic, on_message, to_qos_profile(request), raw=True
        )
        self._say(
            f"subscribed to {topic} ({type_name}; {request['reliability']}, {request['durability']}, "
            f"{len(endpoints)} publisher{'s' if len(endpoints) != 1 else ''})"
        )

    def _skip(self, topic: str, why: str) -> None:
        self._skipped.add(topic)
        self._say(f"WARNING: not recording {topic}: {why}")

    def _say(self, text: str) -> None:
        if self.output is not None:
            name = self.node.get_fully_qualified_name() if self.node is not None else "/" + self.node_name
            self.output(f"[{name}] {text}")
