"""Read a bag without ROS: raw CDR messages, decoded messages, a joint's series.

    from tutorial.bag.reader import joint_series
    series = joint_series("drive.mcap", "/Tank/joint_state")
    series.positions["TURRET_Y"]      # (n,) array, rad
    series.stamp                      # (n,) array, s: the messages' header stamps

Everything here uses the ``mcap`` library's reader, and the
``mcap-ros2-support`` decoder for the messages' contents: it builds the
deserializer from the ``ros2msg`` schema stored in the file, so a bag can be
read on a machine with neither ROS nor the message packages.

A file that is not a whole MCAP file gives one :class:`BagError` with a
one-line reason: not an MCAP file, truncated (no closing magic: the
recorder was killed, or the copy is incomplete), or corrupt (the parser's
or a chunk CRC's complaint).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

MAGIC = b"\x89MCAP0\r\n"  # MCAP's opening and closing magic


class BagError(Exception):
    """A bag that cannot be read: its message is one line naming the file and the reason."""


@dataclass(frozen=True)
class RawMessage:
    """One recorded message: ``topic``, ``type`` (``pkg/msg/Name``), ``log_time`` and
    ``publish_time`` (ns since the epoch) and ``data`` (the CDR bytes)."""

    topic: str
    type: str
    log_time: int
    publish_time: int
    data: bytes


def check_file(path) -> Path:
    """``path`` as a Path if it looks like a whole MCAP file (magic at both ends).

    Raises:
        BagError: missing, not a file, not MCAP, or truncated.
    """
    p = Path(path)
    if not p.exists():
        raise BagError(f"{p}: no such file")
    if not p.is_file():
        raise BagError(f"{p}: not a file")
    size = p.stat().st_size
    with open(p, "rb") as f:
        head = f.read(len(MAGIC))
        if head != MAGIC:
            what = "empty" if size == 0 else "not an MCAP file (no MCAP magic at its start)"
            raise BagError(f"{p}: {what}")
        f.seek(max(0, size - len(MAGIC)))
        tail = f.read(len(MAGIC))
    if size < 2 * len(MAGIC) or tail != MAGIC:
        raise BagError(
            f"{p}: truncated MCAP file (no closing magic at its end): "
            "the recording was not closed, or the copy is incomplete"
        )
    return p


@contextlib.contextmanager
def _reading(path: Path):
    """Turn any failure of the MCAP parser or the CDR decoder into one :class:`BagError`.

    The parser fails in many ways on damaged bytes (its own ``McapError``s,
    ``struct.error``, zstd/lz4 errors, ``UnicodeDecodeError``...); each is
    a property of the file, not a bug here, so each becomes "corrupt".
    """
    try:
        yield
    except BagError:
        raise
    except Exception as exc:  # noqa: BLE001 - see the docstring: the file's fault, reported as one line
        detail = str(exc).splitlines()[0] if str(exc) else ""
        raise BagError(f"{path}: corrupt MCAP file ({type(exc).__name__}{': ' + detail if detail else ''})") from None


@contextlib.contextmanager
def open_reader(path, decode: bool = False):
    """An ``mcap.reader.McapReader`` on a checked file, closed on exit (chunk CRCs are validated).

    Args:
        path: the ``.mcap`` file.
        decode: add the ROS 2 decoder, for ``iter_decoded_messages``.

    Raises:
        BagError: see :func:`check_file`; parser failures inside the ``with``
            block become :class:`BagError` too.
    """
    from mcap.reader import make_reader

    p = check_file(path)
    factories = []
    if decode:
        from mcap_ros2.decoder import DecoderFactory

        factories.append(DecoderFactory())
    with open(p, "rb") as f, _reading(p):
        yield make_reader(f, validate_crcs=True, decoder_factories=factories)


def iter_raw(path, topics=None, start_time: int | None = None) -> Iterator[RawMessage]:
    """The recorded messages in log-time order, undecoded.

    Args:
        path: the ``.mcap`` file.
        topics: only these topics (None: all).
        start_time: skip messages logged before this time (ns since the epoch).

    Raises:
        BagError: the file is not a whole, readable MCAP file.
    """
    with open_reader(path) as reader:
        for schema, channel, message in reader.iter_messages(
            topics=topics, starting_at=start_time, log_time_order=True
        ):
            yield RawMessage(
                channel.topic,
                schema.name if schema else "",
                message.log_time,
                message.publish_time,
                bytes(message.data),
            )


def read_messages(path, topics=None) -> Iterator[tuple[str, int, object]]:
    """``(topic, log_time_ns, message)`` in log-time order, each message decoded without ROS.

    The message is an object with the type's fields as attributes (the
    ``mcap-ros2-support`` decoder's), e.g. ``msg.header.stamp.sec``,
    ``msg.position``.

    Raises:
        BagError: unreadable file, or a schema the decoder cannot parse.
    """
    with open_reader(path, decode=True) as reader:
        for _schema, channel, message, decoded in reader.iter_decoded_messages(topics=topics, log_time_order=True):
            yield channel.topic, message.log_time, decoded


@dataclass
class JointSeries:
    """A ``sensor_msgs/JointState`` topic's positions over time, as numpy arrays.

    Attributes:
        topic: the topic read.
        stamp: (n,) header stamps, s (simulation time for the tutorial's publisher).
        log_time: (n,) receive times, s since the first message of the topic.
        positions: joint name -> (n,) positions (rad or m); NaN where a
            message did not carry that joint.
    """

    topic: str
    stamp: np.ndarray
    log_time: np.ndarray
    positions: dict[str, np.ndarray] = field(default_factory=dict)


def joint_series(path, topic: str = "/Tank/joint_state") -> JointSeries:
    """Read the joint positions of a JointState topic from a bag, without ROS.

    Joints are matched by name in every message (the order may change from
    one message to the next).

    Raises:
        BagError: unreadable file, or no such topic in it.
    """
    stamps: list[float] = []
    logs: list[int] = []
    rows: list[dict[str, float]] = []
    names: dict[str, None] = {}  # insertion-ordered set: joints in the order first seen
    for _topic, log_time, msg in read_messages(path, topics=[topic]):
        stamps.append(msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9)
        logs.append(log_time)
        row = {n: float(q) for n, q in zip(msg.name, msg.position)}
        rows.append(row)
        names.update(dict.fromkeys(row))
    if not rows:
        from tutorial.bag.info import bag_info

        topics = [t.topic for t in bag_info(path).topics]
        if topic not in topics:
            raise BagError(f"{path}: no topic {topic} (it has: {', '.join(topics) or 'none'})")
    t0 = logs[0] if logs else 0
    return JointSeries(
        topic,
        np.array(stamps),
        (np.array(logs, dtype=np.int64) - t0) * 1e-9,
        {n: np.array([r.get(n, np.nan) for r in rows]) for n in names},
    )
