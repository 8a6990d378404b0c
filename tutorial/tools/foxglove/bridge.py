"""Serve the ROS 2 topics, and the robot in 3D, to Foxglove over its WebSocket protocol.

Foxglove connects to a live robot through a server that speaks its
WebSocket protocol; on a ROS 2 installation that is ``foxglove_bridge``.
:class:`FoxgloveBridge` is its stand-in here, built on the ``foxglove-sdk``
package's server, which names the protocol ``foxglove.sdk.v1`` on the
WebSocket and refuses a client that offers only the older name
``foxglove.websocket.v1`` (the Foxglove app offers both; a viewer that does
not, such as Lichtblick before December 2025, can still open the recordings):

* every topic of the ROS graph (hidden ones aside) whose type is installed
  is advertised as a channel of encoding ``cdr`` with its ``ros2msg``
  schema (the full definition text, as rosbag2 stores it), and each message
  is forwarded as it came, the CDR bytes unchanged: the ROS 2 messages as
  they are;
* the robot in 3D: from each body's robot description, odometry and joint
  states it computes ``/tf``, ``/tf_static`` and ``/robot_description``
  exactly as ``rtt-bag record --tf`` writes them (the same
  :class:`tutorial.tools.bag.record_tf.TfRecording`), and serves them as
  channels too.  Foxglove's 3D panel draws the URDF from
  ``/robot_description`` at the frames TF gives.

The protocol has no "transient local": a client that subscribes later than
a message was sent never gets it.  So the newest ``/tf_static`` and
``/robot_description`` (sent once) are sent again whenever a client
subscribes to them.

It binds to 127.0.0.1 by default: only programs on this machine connect.

Threads: the owner thread calls :meth:`FoxgloveBridge.start` and
:meth:`FoxgloveBridge.close`; discovery and the subscription callbacks run on
the bridge's spin thread; the SDK's server runs its own threads and calls
:class:`_Listener` from them (it only sets flags, read on the spin thread).
"""

from __future__ import annotations

import threading
import time

from tutorial.interfaces.definitions import UnknownMessageType, full_text, message_class
from tutorial.tools.bag.qos import profile_dict, request_for_offers, to_qos_profile
from tutorial.tools.bag.record import is_hidden

NODE_NAME = "rtt_foxglove"
DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8765
POLL_PERIOD = 0.2  # s between looks at the ROS graph, and at clients that subscribed
SUBSCRIPTION_DEPTH = 10
LATCHED = ("/tf_static", "/robot_description")  # sent once, sent again to each new subscriber


class _Listener:
    """The server's callbacks (its threads): note which latched channels a client subscribed to."""

    def __init__(self):
        self.lock = threading.Lock()  # the server's threads set, the spin thread takes
        self.resend: set[str] = set()
        self.subscriptions = 0

    def on_subscribe(self, client, channel) -> None:
        with self.lock:
            self.subscriptions += 1
            if channel.topic in LATCHED:
                self.resend.add(channel.topic)

    def take(self) -> set[str]:
        with self.lock:
            out, self.resend = self.resend, set()
            return out


class _ChannelSink:
    """A :class:`tutorial.tools.bag.writer.BagWriter` look-alike that logs to Foxglove channels (spin thread).

    :class:`tutorial.tools.bag.record_tf.TfRecording` writes through it: ``add_topic``
    advertises a channel, ``write`` logs a message (and keeps the newest of a
    latched topic).
    """

    def __init__(self, bridge: FoxgloveBridge):
        self.bridge = bridge

    def add_topic(self, topic, type_name, definition, offered_qos_profiles, type_hash="") -> None:
        self.bridge._channel(topic, type_name, definition)

    def write(self, topic: str, log_time: int, publish_time: int, data: bytes) -> bool:
        self.bridge._log(topic, data, log_time)
        return True


class FoxgloveBridge:
    """A Foxglove WebSocket server fed from the ROS 2 graph.

    Args:
        host: the address to bind (127.0.0.1: this machine only).
        port: the TCP port (0: any free one; :attr:`port` says which).
        topics: serve only these ROS topics (None: every one); the robot's
            TF is computed in any case, from the bodies' descriptions.
        node_name: the ROS node's name.
        output: called with each status line.
        tf_frame_prefix: put before every frame of a body on ``/tf`` and
            ``/tf_static``; ``{body}`` in it is the body's name
            (:class:`tutorial.tools.bag.record_tf.TfRecording`).

    Raises:
        RuntimeError: the server cannot listen there (the port is taken).
        ValueError: a ``tf_frame_prefix`` with a ``{...}`` other than ``{body}``.

    ``rclpy`` must be initialised first.  Construct, :meth:`start` and
    :meth:`close` on one owner thread.
    """

    def __init__(
        self,
        host: str = DEFAULT_HOST,
        port: int = DEFAULT_PORT,
        topics=None,
        node_name: str = NODE_NAME,
        output=print,
        tf_frame_prefix: str = "",
    ):
        from tutorial.tools.bag.record_tf import check_frame_prefix

        self.tf_frame_prefix = check_frame_prefix(tf_frame_prefix)
        self.host, self.requested_port = host, port
        self.topics = None if topics is None else {t if t.startswith("/") else "/" + t for t in topics}
        self.node_name = node_name
        self.output = output
        self.node = None
        self.server = None
        self.context = None
        self._spin = None
        self._timer = None
        self._listener = _Listener()
        self._channels: dict[str, object] = {}
        self._latest: dict[str, bytes] = {}  # newest message of each latched topic
        self._subscriptions: dict[str, object] = {}
        self._skipped: set[str] = set()
        self.forwarded: dict[str, int] = {}
        self.tf = None
        self.port: int | None = None

    # ---- owner thread -------------------------------------------------------------------
    def start(self) -> FoxgloveBridge:
        """Start the server, the node, and discovery; returns self."""
        import foxglove
        import rclpy

        from tutorial.ros.spin import SpinThread
        from tutorial.tools.bag.record_tf import TfRecording

        self.context = foxglove.Context()
        try:
            self.server = foxglove.start_server(
                name="rtt-foxglove",
                host=self.host,
                port=self.requested_port,
                server_listener=self._listener,
                supported_encodings=["cdr"],
                context=self.context,
            )
        except Exception as exc:  # noqa: BLE001 - the SDK raises its own error type
            raise RuntimeError(f"cannot serve on {self.host}:{self.requested_port}: {exc}") from None
        self.port = self.server.port
        self.tf = TfRecording(_ChannelSink(self), self._say, self.tf_frame_prefix)
        self.node = rclpy.create_node(self.node_name)
        self._say(f"serving ws://{self.host}:{self.port} (foxglove.sdk.v1): open it in Foxglove")
        self._discover()
        self._timer = self.node.create_timer(POLL_PERIOD, self._discover)
        self._spin = SpinThread(self.node).start()
        return self

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    @property
    def error(self) -> BaseException | None:
        """What ended the spin thread (a callback raised), else None."""
        return self._spin.error if self._spin is not None else None

    def close(self) -> None:
        """Stop discovery and the subscriptions, the node and the server.  Safe to call twice."""
        if self._spin is not None:
            self._spin.stop()
            self._spin = None
        if self.node is not None:
            self.node.destroy_node()
            self.node = None
        if self.server is not None:
            self.server.stop()
            self.server = None

    # ---- spin thread ----------------------------------------------------------------------
    def _discover(self) -> None:
        for topic in self._listener.take():
            if topic in self._latest:
                self._channels[topic].log(self._latest[topic], log_time=time.time_ns())
        for topic, types in self.node.get_topic_names_and_types():
            if topic in self._subscriptions or topic in self._skipped or is_hidden(topic):
                continue
            wanted = self.topics is None or topic in self.topics
            if len(types) != 1 or not (wanted or self.tf.wants(topic, types[0])):
                continue
            endpoints = self.node.get_publishers_info_by_topic(topic)
            if endpoints:
                self._subscribe(topic, types[0], endpoints, forward=wanted)

    def _subscribe(self, topic: str, type_name: str, endpoints, forward: bool) -> None:
        try:
            msg_type = message_class(type_name)
            definition = full_text(type_name)
        except UnknownMessageType as exc:
            self._skipped.add(topic)
            self._say(f"WARNING: not serving {topic}: {exc}")
            return
        if forward:
            self._channel(topic, type_name, definition)
        request = request_for_offers([profile_dict(e.qos_profile) for e in endpoints], SUBSCRIPTION_DEPTH)
        tf = self.tf

        def on_message(data: bytes, topic=topic) -> None:
            now = time.time_ns()
            if forward:
                self._log(topic, data, now)
            tf.on_message(topic, type_name, data, now)

        self._subscriptions[topic] = self.node.create_subscription(
            msg_type, topic, on_message, to_qos_profile(request), raw=True
        )
        self._say(f"serving {topic} ({type_name})" if forward else f"reading {topic} for TF ({type_name})")

    def _channel(self, topic: str, type_name: str, definition: tuple[str, str]) -> None:
        import foxglove

        if topic in self._channels:
            return
        encoding, text = definition
        schema = foxglove.Schema(name=type_name, encoding=encoding, data=text.encode())
        self._channels[topic] = foxglove.Channel(topic, schema=schema, message_encoding="cdr", context=self.context)
        self.forwarded[topic] = 0

    def _log(self, topic: str, data: bytes, log_time: int) -> None:
        if topic in LATCHED:
            self._latest[topic] = bytes(data)
        self._channels[topic].log(bytes(data), log_time=log_time)
        self.forwarded[topic] += 1

    def _say(self, text: str) -> None:
        if self.output is not None:
            self.output(f"[/{self.node_name}] {text}")
