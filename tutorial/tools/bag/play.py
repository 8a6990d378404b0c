"""Replay a bag: republish its messages with the recorded timing, as ``ros2 bag play`` does.

    from tutorial.tools.bag.play import BagPlayer
    BagPlayer("drive.mcap", rate=2.0).play()              # blocking, in this thread
    player = BagPlayer("drive.mcap", loop=True).start()   # on a background thread (a notebook)
    player.close()

Each topic gets one publisher, of the recorded type, offering the QoS
rosbag2's player would offer from the file's ``offered_qos_profiles``
(:func:`tutorial.tools.bag.qos.offer_for_recorded`).  Messages go out as the
recorded CDR bytes (``Publisher.publish(bytes)``), never deserialized, in
log-time order: message *i* leaves ``(log_time[i] - start) / rate`` s after
playback began, so the gaps between messages are the recorded ones.

When the last message has gone out, the player waits (at most
:data:`ACK_TIMEOUT` s) until every reliable subscriber acknowledged it, so
a process that exits right after playing does not take the final state
with it.
"""

from __future__ import annotations

import contextlib
import threading
import time
from dataclasses import dataclass, field

from tutorial.interfaces.definitions import UnknownMessageType, message_class
from tutorial.tools.bag.info import bag_info
from tutorial.tools.bag.qos import offer_for_recorded, to_qos_profile
from tutorial.tools.bag.reader import BagError, iter_raw

NODE_NAME = "rtt_bag_play"
ACK_TIMEOUT = 2.0  # s to wait for reliable subscribers to acknowledge the last messages
_SLICE = 0.05  # s: the longest sleep between two looks at the stop request


@dataclass
class PlayStats:
    """What a playback published: messages per topic, loops completed, whether it was stopped."""

    published: dict[str, int] = field(default_factory=dict)
    loops: int = 0
    stopped: bool = False

    @property
    def messages(self) -> int:
        return sum(self.published.values())


class BagPlayer:
    """Republishes a bag's messages with their recorded timing.

    Args:
        path: the ``.mcap`` file.
        rate: playback speed factor (2.0: twice as fast); > 0.
        loop: start again from ``start_offset`` after the last message, until stopped.
        topics: play only these topics (None: all).
        start_offset: skip the first this many seconds of the bag; >= 0.
        delay: wait this long (s) before playing, e.g. for subscribers to
            discover the player's publishers (``ros2 bag play --delay``).
        node: an ``rclpy`` node to publish from; None: create node ``node_name``
            (publishing needs no spinning).
        output: called with each status line (default ``print``).

    Raises:
        ValueError: a bad ``rate``, ``start_offset`` or ``delay``.
        BagError: the file is not a whole MCAP file, a requested topic is
            not in it, or a topic's type is not installed here (its message
            class is needed to publish).

    The file is checked, and every type resolved, before anything is
    published.  :meth:`play` runs in the calling thread; :meth:`start` runs
    it on a background thread, stopped by :meth:`close` from the owner.
    """

    def __init__(
        self,
        path,
        *,
        rate: float = 1.0,
        loop: bool = False,
        topics=None,
        start_offset: float = 0.0,
        delay: float = 0.0,
        node=None,
        node_name: str = NODE_NAME,
        output=print,
    ):
        if not rate > 0:
            raise ValueError("rate must be > 0")
        if start_offset < 0 or delay < 0:
            raise ValueError("start_offset and delay must be >= 0")
        self.rate, self.loop, self.start_offset, self.delay = rate, loop, start_offset, delay
        self.info = bag_info(path)
        self.path = self.info.path
        names = [t.topic for t in self.info.topics if t.count > 0]
        if topics is not None:
            wanted = [t if t.startswith("/") else "/" + t for t in topics]
            missing = [t for t in wanted if t not in names]
            if missing:
                raise BagError(
                    f"{self.path}: no messages on {', '.join(missing)} (it has: {', '.join(names) or 'none'})"
                )
            names = [n for n in names if n in wanted]
        self.selected = [self.info.topic(n) for n in names]
        self.classes = {}
        for t in self.selected:
            try:
                self.classes[t.topic] = message_class(t.type)
            except UnknownMessageType as exc:
                raise BagError(f"{self.path}: cannot play {t.topic}: {exc}") from None
        self.node = node
        self._given_node = node
        self.node_name = node_name
        self.output = output
        self.publishers: dict[str, object] = {}
        self.stats = PlayStats({n: 0 for n in names})
        self._stop = False  # a plain flag: also set from a signal handler (see tutorial/ros/launch.py)
        self._thread: threading.Thread | None = None
        self.error: BaseException | None = None

    def _create_publishers(self) -> None:
        import rclpy

        if self.node is None:
            self.node = rclpy.create_node(self.node_name)
        for t in self.selected:
            profile, warning = offer_for_recorded(t.offered_qos_profiles)
            if warning:
                self._say(f"WARNING: {t.topic}: {warning}")
            self.publishers[t.topic] = self.node.create_publisher(
                self.classes[t.topic], t.topic, to_qos_profile(profile)
            )
            self._say(f"publishing {t.topic} ({t.type}; {profile['reliability']}, {profile['durability']})")

    def request_stop(self) -> None:
        """Ask :meth:`play` to stop before its next message (any thread, signal handlers too)."""
        self._stop = True

    def _sleep_until(self, deadline: float) -> bool:
        """Sleep until ``deadline`` (monotonic s) in short slices; False if a stop was requested."""
        while not self._stop:
            left = deadline - time.monotonic()
            if left <= 0:
                return True
            time.sleep(min(left, _SLICE))
        return False

    def play(self) -> PlayStats:
        """Publish the bag (looped if asked) until its end or :meth:`request_stop`; the counts.

        Runs in the calling thread.  Creates the publishers on first use.
        """
        if not self.publishers:
            self._create_publishers()
        begin_ns = (self.info.first_ns or 0) + int(self.start_offset * 1e9)
        topics = [t.topic for t in self.selected]
        try:
            while not self._stop:
                if self.delay and not self._sleep_until(time.monotonic() + self.delay):
                    break
                t0 = time.monotonic()
                sent = 0
                with contextlib.closing(iter_raw(self.path, topics=topics, start_time=begin_ns)) as messages:
                    for msg in messages:
                        if not self._sleep_until(t0 + (msg.log_time - begin_ns) * 1e-9 / self.rate):
                            break
                        self.publishers[msg.topic].publish(msg.data)
                        self.stats.published[msg.topic] += 1
                        sent += 1
                    else:
                        self.stats.loops += 1
                if not self.loop or sent == 0:  # nothing after start_offset: looping would spin
                    break
        finally:
            self.stats.stopped = self._stop
            self._wait_for_acks()
        self._say(
            f"published {self.stats.messages} messages ("
            + ", ".join(f"{t} {n}" for t, n in self.stats.published.items())
            + f"){', stopped' if self.stats.stopped else ''}"
        )
        return self.stats

    def _wait_for_acks(self) -> None:
        from rclpy.duration import Duration

        for pub in self.publishers.values():
            pub.wait_for_all_acked(Duration(seconds=ACK_TIMEOUT))

    def start(self) -> BagPlayer:
        """Play on a background thread (its error, if any, is kept in :attr:`error`); returns self."""
        self._create_publishers()

        def run():
            try:
                self.play()
            except BaseException as exc:  # noqa: BLE001 - kept for the owner to report
                self.error = exc

        self._thread = threading.Thread(target=run, name="rtt-bag-play", daemon=True)
        self._thread.start()
        return self

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for a :meth:`start` ed playback to end; True when it has."""
        if self._thread is not None:
            self._thread.join(timeout)
            return not self._thread.is_alive()
        return True

    def close(self) -> PlayStats:
        """Stop playing, release the publishers (and the node it created); the counts. Owner thread."""
        self.request_stop()
        self.wait(5.0)
        if self.node is not None:
            for pub in self.publishers.values():
                self.node.destroy_publisher(pub)
            self.publishers.clear()
            if self._given_node is None:
                self.node.destroy_node()
                self.node = None
        return self.stats

    def _say(self, text: str) -> None:
        if self.output is not None:
            name = self.node.get_fully_qualified_name() if self.node is not None else "/" + self.node_name
            self.output(f"[{name}] {text}")
