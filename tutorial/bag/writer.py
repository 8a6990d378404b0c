"""Write an MCAP file the way rosbag2's MCAP storage plugin (Jazzy) does, with the ``mcap`` library.

The file is what ``ros2 bag record -s mcap`` writes: the ``ros2`` profile;
one schema per message type (encoding ``ros2msg``, the full definition
text, see :mod:`tutorial.bag.definitions`); one channel per topic (message
encoding ``cdr``, metadata ``offered_qos_profiles`` and ``topic_type_hash``);
each message's CDR bytes as received, with ``log_time`` = receive time and
``publish_time`` = the publisher's source time (ns since the epoch); and,
at close, a ``rosbag2`` metadata record whose ``serialized_metadata`` is
the bag's ``metadata.yaml`` content (format version 9).

The ``mcap`` library does the format: chunks (zstd-compressed by default,
1 MiB), message indexes, chunk indexes, statistics and the summary section
that lets a reader seek and list a file without reading it all.
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from tutorial.bag.qos import parse_profiles

BAG_FORMAT_VERSION = 9  # rosbag2's metadata version in Jazzy
COMPRESSIONS = ("zstd", "lz4", "none")


class BagWriteError(OSError):
    """The output file cannot be created (exists, no such folder, no permission)."""


@dataclass
class _Topic:
    name: str
    type: str
    channel_id: int
    offered_qos_profiles: str
    type_hash: str
    count: int = 0


@dataclass
class WriteStats:
    """What a :class:`BagWriter` wrote: message counts by topic, first/last log time (ns), file size (bytes)."""

    path: Path
    messages: int = 0
    per_topic: dict[str, int] = field(default_factory=dict)
    first_ns: int | None = None
    last_ns: int | None = None
    size_bytes: int = 0


class BagWriter:
    """One MCAP file being written.

    Args:
        path: the file to create, e.g. ``drive.mcap``.
        compression: chunk compression, ``zstd`` (default), ``lz4`` or ``none``.
        overwrite: replace an existing file (default: refuse, as rosbag2 does).

    Raises:
        BagWriteError: the file exists (and ``overwrite`` is false) or cannot be created.
        ValueError: unknown ``compression``.

    Thread use: :meth:`add_topic` and :meth:`write` are called from a ROS
    spin thread (discovery timer, subscription callbacks) while
    :meth:`close` comes from the owner's thread; one lock serialises them,
    because the ``mcap`` writer keeps its chunk and indexes in plain Python
    objects.  After :meth:`close`, :meth:`write` drops messages and returns
    False, so a callback already running when the recorder stops cannot
    write past the file's end.
    """

    def __init__(self, path, compression: str = "zstd", overwrite: bool = False):
        from mcap.writer import CompressionType, Writer

        if compression not in COMPRESSIONS:
            raise ValueError(f"compression {compression!r}: use one of {', '.join(COMPRESSIONS)}")
        self.path = Path(path)
        try:
            self._stream = open(self.path, "wb" if overwrite else "xb")  # noqa: SIM115 - closed in close()
        except FileExistsError:
            raise BagWriteError(f"{self.path} exists already; choose another name or pass --overwrite") from None
        except OSError as exc:
            raise BagWriteError(f"cannot create {self.path}: {exc.strerror}") from None
        kind = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4, "none": CompressionType.NONE}[compression]
        self._writer = Writer(self._stream, compression=kind)
        self._writer.start(profile="ros2", library=f"rtt-bag (python mcap {_mcap_version()})")
        self._lock = threading.Lock()
        self._schemas: dict[str, int] = {}
        self._topics: dict[str, _Topic] = {}
        self._stats = WriteStats(self.path)
        self.closed = False

    def add_topic(
        self, topic: str, type_name: str, definition: tuple[str, str], offered_qos_profiles: str, type_hash: str = ""
    ) -> int:
        """Register a topic (once); its channel id.

        Args:
            topic: full topic name, e.g. ``/Tank/joint_state``.
            type_name: e.g. ``sensor_msgs/msg/JointState``.
            definition: ``(encoding, text)`` of its schema (``("unknown", "")`` when not found).
            offered_qos_profiles: the publishers' offers (:func:`tutorial.bag.qos.serialize_profiles`).
            type_hash: ``RIHS01_...`` of the type, or ``""``.

        Raises:
            ValueError: the topic was added before with another type.
        """
        with self._lock:
            known = self._topics.get(topic)
            if known is not None:
                if known.type != type_name:
                    raise ValueError(f"{topic} was added as {known.type}, not {type_name}")
                return known.channel_id
            schema_id = self._schemas.get(type_name)
            if schema_id is None:
                encoding, text = definition
                schema_id = self._writer.register_schema(type_name, encoding, text.encode())
                self._schemas[type_name] = schema_id
            channel_id = self._writer.register_channel(
                topic, "cdr", schema_id, {"offered_qos_profiles": offered_qos_profiles, "topic_type_hash": type_hash}
            )
            self._topics[topic] = _Topic(topic, type_name, channel_id, offered_qos_profiles, type_hash)
            self._stats.per_topic[topic] = 0
            return channel_id

    def write(self, topic: str, log_time: int, publish_time: int, data: bytes) -> bool:
        """Append one message's CDR bytes; False (nothing written) once closed.

        Args:
            topic: a topic given to :meth:`add_topic`.
            log_time: receive time, ns since the epoch.
            publish_time: the publisher's send time, ns since the epoch.
            data: the serialized message (CDR), as received.

        Raises:
            KeyError: the topic was never added.
        """
        with self._lock:
            if self.closed:
                return False
            entry = self._topics[topic]
            self._writer.add_message(entry.channel_id, log_time, data, publish_time)
            entry.count += 1
            stats = self._stats
            stats.messages += 1
            stats.per_topic[topic] = entry.count
            stats.first_ns = log_time if stats.first_ns is None else min(stats.first_ns, log_time)
            stats.last_ns = log_time if stats.last_ns is None else max(stats.last_ns, log_time)
            return True

    def stats(self) -> WriteStats:
        """A copy of the counts so far (any thread)."""
        with self._lock:
            s = self._stats
            return WriteStats(s.path, s.messages, dict(s.per_topic), s.first_ns, s.last_ns, s.size_bytes)

    def close(self) -> WriteStats:
        """Write the ``rosbag2`` metadata record, the indexes and the summary; close the file.

        Calling it again does nothing.  Owner thread.
        """
        with self._lock:
            if self.closed:
                return self._stats
            self.closed = True
            try:
                self._writer.add_metadata("rosbag2", {"serialized_metadata": self._serialized_metadata()})
                self._writer.finish()
            finally:
                self._stream.close()
            self._stats.size_bytes = os.path.getsize(self.path)
            return self._stats

    def _serialized_metadata(self) -> str:
        """The bag's ``metadata.yaml`` content, in rosbag2's key order (``rosbag2_storage/yaml.hpp``)."""
        s = self._stats
        start = s.first_ns or 0
        duration = (s.last_ns - s.first_ns) if s.messages else 0
        topics = [
            {
                "topic_metadata": {
                    "name": t.name,
                    "type": t.type,
                    "serialization_format": "cdr",
                    "offered_qos_profiles": parse_profiles(t.offered_qos_profiles),
                    "type_description_hash": t.type_hash,
                },
                "message_count": t.count,
            }
            for t in self._topics.values()
        ]
        metadata = {
            "version": BAG_FORMAT_VERSION,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": duration},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": s.messages,
            "topics_with_message_count": topics,
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [self.path.name],
            "files": [
                {
                    "path": self.path.name,
                    "starting_time": {"nanoseconds_since_epoch": start},
                    "duration": {"nanoseconds": duration},
                    "message_count": s.messages,
                }
            ],
            "custom_data": {},
            "ros_distro": os.environ.get("ROS_DISTRO", "jazzy"),
        }
        return yaml.safe_dump(metadata, sort_keys=False, default_flow_style=False).rstrip("\n")


def _mcap_version() -> str:
    import mcap

    return mcap.__version__
