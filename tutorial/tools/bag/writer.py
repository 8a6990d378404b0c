"""Write an MCAP file the way rosbag2's MCAP storage plugin (Jazzy) does, with the ``mcap`` library.

The file is what ``ros2 bag record -s mcap`` writes: the ``ros2`` profile;
one schema per message type (encoding ``ros2msg``, the full definition
text, see :mod:`tutorial.interfaces.definitions`); one channel per topic (message
encoding ``cdr``, metadata ``offered_qos_profiles`` and ``topic_type_hash``);
each message's CDR bytes as received, with ``log_time`` = receive time and
``publish_time`` = the publisher's source time (ns since the epoch); and,
at close, a ``rosbag2`` metadata record whose ``serialized_metadata`` is
the bag's ``metadata.yaml`` content (format version 9).

The ``mcap`` library does the format: chunks (zstd-compressed by default),
message indexes, chunk indexes, statistics and the summary section that
lets a reader seek and list a file without reading it all.

Write-through: what a crash can lose
------------------------------------
The summary (the index) is written only at :meth:`BagWriter.close`, so a
recorder that is killed leaves a file without one; what a reader can still
get from it is every *chunk* that reached the file (``rtt-bag info`` and
``play`` read them, ``rtt-bag recover`` writes a closed copy).  So the
policy is about chunks:

* a chunk is closed when its messages reach :data:`CHUNK_SIZE` bytes **or**
  when its oldest message is :data:`CHUNK_PERIOD` (0.5 s) old, whichever
  comes first, and either way it is written through.  The age is checked at every message and, for a topic that went
  quiet, by :meth:`BagWriter.write_through_due`, which the recorder calls
  every :data:`WRITE_THROUGH_CHECK` (0.1 s); so a message is in the file at
  most about 0.6 s after it arrived: a crash loses less than 1 s;
* closing a chunk *writes it through*: the chunk and its message indexes
  are written, Python's buffer is **flushed** to the kernel (then the
  data survives the process: SIGKILL, a crash, the OOM killer), and the
  file is **fsync**'ed (then it survives the machine: a power cut, a kernel
  panic, a USB disk pulled out).  rosbag2's ``resilient`` MCAP preset
  stops at the flush; we fsync as well because it is cheap at this pace:
  at most twice a second, a few KiB each (``python -m benchmarks.bag``
  measures the whole policy at 1 kHz against the same recorder without it);
* the file's first bytes (magic and header) are written through at once,
  and the folder is fsync'ed once, so even a recorder killed in its first
  half second leaves an MCAP file, not a 0-byte one.

Smaller chunks compress a little less well (zstd has less to work with);
at 1 kHz a half-second chunk is still a few hundred messages.

A write that fails (a full disk, ``ENOSPC``; the process's file-size limit,
``EFBIG``) stops the writer: :attr:`BagWriter.error` says why in one line,
later messages are dropped, and the file is left as it is, every chunk
written through before still readable.

Why one module of over 400 lines: it is one class, :class:`BagWriter`, and
one job, the file as rosbag2 lays it out.  The write-through policy decides
when a chunk closes, which is the layout, so the two are not separable.
"""

from __future__ import annotations

import errno
import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from tutorial.tools.bag.qos import QosFormatError, parse_profiles

BAG_FORMAT_VERSION = 9  # rosbag2's metadata version in Jazzy
COMPRESSIONS = ("zstd", "lz4", "none")
CHUNK_SIZE = 1024 * 1024  # bytes of messages: a chunk is closed at this size (the mcap library's default) ...
_MESSAGE_RECORD = 31  # bytes of a message record besides its data: opcode, length, channel, sequence, two times
_NEVER = 2**62  # the mcap writer's own size limit when this writer closes chunks itself
CHUNK_PERIOD = 0.5  # s: ... or when its oldest message is this old (see the module's docstring)
WRITE_THROUGH_CHECK = 0.1  # s: how often a recorder calls write_through_due()


class BagWriteError(OSError):
    """The output file cannot be created (exists, no such folder, no permission), or a write to it failed."""


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
    """What a :class:`BagWriter` wrote.

    Attributes:
        path: the file.
        messages, per_topic: messages accepted, in all and by topic.
        first_ns, last_ns: first and last log time (ns since the epoch), None before any message.
        size_bytes: the file's size once closed (or failed), bytes.
        written_through: messages in chunks that were written through (flushed and fsync'ed).
        write_throughs: how many times a chunk was written through.
        sync_s, max_sync_s: time spent in ``fsync``, in all and the longest one, s.
    """

    path: Path
    messages: int = 0
    per_topic: dict[str, int] = field(default_factory=dict)
    first_ns: int | None = None
    last_ns: int | None = None
    size_bytes: int = 0
    written_through: int = 0
    write_throughs: int = 0
    sync_s: float = 0.0
    max_sync_s: float = 0.0


def describe_write_error(exc: OSError) -> str:
    """A failed write in a few words a person acts on, e.g. ``the disk is full (ENOSPC)``."""
    code = errno.errorcode.get(exc.errno or 0, "")
    if exc.errno == errno.ENOSPC:
        what = "the disk is full"
    elif exc.errno == errno.EFBIG:
        what = "the file reached the largest size this process may write (its file-size limit)"
    elif exc.errno == errno.EDQUOT:
        what = "the disk quota is used up"
    else:
        what = exc.strerror or str(exc) or type(exc).__name__
    return f"{what} ({code})" if code else what


class BagWriter:
    """One MCAP file being written.

    Args:
        path: the file to create, e.g. ``drive.mcap``.
        compression: chunk compression, ``zstd`` (default), ``lz4`` or ``none``.
        overwrite: replace an existing file (default: refuse, as rosbag2 does).
        write_through: close a chunk at least every :data:`CHUNK_PERIOD` s and
            flush and fsync it (default, see the module's docstring); False
            writes 1 MiB chunks only, and a crash loses what was not yet in one
            (the policy before issue 26, kept for the benchmark's baseline).
        profile: the MCAP profile written in the header (``ros2``).
        clock: monotonic time in s, for the age of a chunk (a test may pass its own).

    Raises:
        BagWriteError: the file exists (and ``overwrite`` is false) or cannot be created.
        ValueError: unknown ``compression``.

    Thread use: :meth:`add_topic`, :meth:`write` and :meth:`write_through_due`
    are called from a ROS spin thread (discovery timer, subscription
    callbacks, the write-through timer) while :meth:`close` comes from the
    owner's thread; one lock serialises them, because the ``mcap`` writer
    keeps its chunk and indexes in plain Python objects.  After
    :meth:`close`, or once a write failed (:attr:`error`), :meth:`write`
    drops messages and returns False, so a callback already running when
    the recorder stops cannot write past the file's end.
    """

    def __init__(
        self,
        path,
        compression: str = "zstd",
        overwrite: bool = False,
        *,
        write_through: bool = True,
        profile: str = "ros2",
        clock=time.monotonic,
    ):
        from mcap.writer import CompressionType, Writer

        if compression not in COMPRESSIONS:
            raise ValueError(f"compression {compression!r}: use one of {', '.join(COMPRESSIONS)}")
        self.path = Path(path)
        try:
            self._stream = open(self.path, "wb" if overwrite else "xb")  # noqa: SIM115 - closed in close()
        except FileExistsError:
            raise BagWriteError(
                f"{self.path} exists already; choose another name, or replace it (rtt-bag record --overwrite, "
                "overwrite=True)"
            ) from None
        except OSError as exc:
            raise BagWriteError(f"cannot create {self.path}: {exc.strerror or exc}") from None
        except ValueError as exc:  # a NUL byte in the name
            raise BagWriteError(f"cannot create {self.path!r}: {exc}") from None
        kind = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4, "none": CompressionType.NONE}[compression]
        # With write-through this writer closes each chunk itself (by size or age), so every chunk is
        # flushed and fsync'ed; without it, the mcap writer closes chunks at CHUNK_SIZE, as before.
        self._writer = Writer(self._stream, chunk_size=_NEVER if write_through else CHUNK_SIZE, compression=kind)
        self.write_through = write_through
        self._clock = clock
        self._lock = threading.Lock()
        self._schemas: dict[str, int] = {}
        self._topics: dict[str, _Topic] = {}
        self._stats = WriteStats(self.path)
        self._oldest_pending: float | None = None  # clock() when the open chunk got its first message
        self._pending_bytes = 0  # bytes of the open chunk's messages
        self.closed = False
        self.error: BagWriteError | None = None
        try:
            self._writer.start(profile=profile, library=f"rtt-bag (python mcap {_mcap_version()})")
            if write_through:  # a file killed at once is an MCAP file, not 0 bytes
                self._sync()
                _sync_folder(self.path)
        except OSError as exc:
            self._fail(exc)
            raise self.error from None

    def add_topic(
        self,
        topic: str,
        type_name: str,
        definition: tuple[str, str] | None,
        offered_qos_profiles: str,
        type_hash: str = "",
        message_encoding: str = "cdr",
    ) -> int:
        """Register a topic (once); its channel id (0 once the writer failed).

        Args:
            topic: full topic name, e.g. ``/Tank/joint_state``.
            type_name: e.g. ``sensor_msgs/msg/JointState``.
            definition: ``(encoding, text)`` of its schema (``("unknown", "")`` when
                not found); None: a channel without a schema (only a foreign
                file that ``rtt-bag recover`` copies has one).
            offered_qos_profiles: the publishers' offers (:func:`tutorial.tools.bag.qos.serialize_profiles`).
            type_hash: ``RIHS01_...`` of the type, or ``""``.
            message_encoding: the channel's message encoding (``cdr`` for ROS 2).

        Raises:
            ValueError: the topic was added before with another type.
        """
        with self._lock:
            known = self._topics.get(topic)
            if known is not None:
                if known.type != type_name:
                    raise ValueError(f"{topic} was added as {known.type}, not {type_name}")
                return known.channel_id
            if self.error is not None or self.closed:
                return 0
            try:
                schema_id = self._schemas.get(type_name, 0)
                if definition is not None and not schema_id:
                    encoding, text = definition
                    schema_id = self._writer.register_schema(type_name, encoding, text.encode())
                    self._schemas[type_name] = schema_id
                channel_id = self._writer.register_channel(
                    topic,
                    message_encoding,
                    schema_id,
                    {"offered_qos_profiles": offered_qos_profiles, "topic_type_hash": type_hash},
                )
            except OSError as exc:  # registering may close a full chunk
                self._fail(exc)
                return 0
            self._topics[topic] = _Topic(topic, type_name, channel_id, offered_qos_profiles, type_hash)
            self._stats.per_topic[topic] = 0
            return channel_id

    def write(self, topic: str, log_time: int, publish_time: int, data: bytes, sequence: int = 0) -> bool:
        """Append one message's CDR bytes; False (nothing written) once closed or failed.

        Args:
            topic: a topic given to :meth:`add_topic`.
            log_time: receive time, ns since the epoch.
            publish_time: the publisher's send time, ns since the epoch.
            data: the serialized message (CDR), as received.
            sequence: the message's sequence number (0: none, as rosbag2 writes).

        Raises:
            KeyError: the topic was never added.
        """
        with self._lock:
            if self.closed or self.error is not None:
                return False
            entry = self._topics[topic]
            try:
                self._writer.add_message(entry.channel_id, log_time, data, publish_time, sequence)
            except OSError as exc:  # a chunk that reached CHUNK_SIZE was being written
                self._fail(exc)
                return False
            entry.count += 1
            stats = self._stats
            stats.messages += 1
            stats.per_topic[topic] = entry.count
            stats.first_ns = log_time if stats.first_ns is None else min(stats.first_ns, log_time)
            stats.last_ns = log_time if stats.last_ns is None else max(stats.last_ns, log_time)
            if self.write_through:
                now = self._clock()
                self._pending_bytes += len(data) + _MESSAGE_RECORD
                if self._oldest_pending is None:
                    self._oldest_pending = now
                if self._pending_bytes >= CHUNK_SIZE or now - self._oldest_pending >= CHUNK_PERIOD:
                    self._write_through()
            return True

    def write_through_due(self) -> bool:
        """Write the open chunk through if its oldest message is :data:`CHUNK_PERIOD` old; True if it did.

        Called every :data:`WRITE_THROUGH_CHECK` s by a timer, so the last
        messages of a topic that went quiet do not wait for the next one.
        """
        with self._lock:
            if self.closed or self.error is not None or self._oldest_pending is None:
                return False
            if self._clock() - self._oldest_pending < CHUNK_PERIOD:
                return False
            return self._write_through()

    def _write_through(self) -> bool:
        """Close the open chunk, write it and its indexes, flush, fsync (under the lock)."""
        try:
            self._writer.flush()  # the chunk, its message indexes, then the stream's own flush
            self._sync()
        except OSError as exc:
            self._fail(exc)
            return False
        self._oldest_pending = None
        self._pending_bytes = 0
        self._stats.written_through = self._stats.messages
        self._stats.write_throughs += 1
        return True

    def _sync(self) -> None:
        self._stream.flush()
        t0 = time.perf_counter()
        os.fsync(self._stream.fileno())
        took = time.perf_counter() - t0
        self._stats.sync_s += took
        self._stats.max_sync_s = max(self._stats.max_sync_s, took)

    def _fail(self, exc: OSError) -> None:
        """A write failed: keep one line saying why, close the file as it is (under the lock)."""
        self.error = BagWriteError(
            f"{self.path}: writing failed: {describe_write_error(exc)}, after "
            f"{self._stats.written_through} messages were written through"
        )
        try:
            self._stream.close()  # tries to flush what is buffered once more, then closes the descriptor
        except OSError:
            pass
        self._stats.size_bytes = _size(self.path)

    def stats(self) -> WriteStats:
        """A copy of the counts so far (any thread)."""
        with self._lock:
            s = self._stats
            return WriteStats(**{**s.__dict__, "per_topic": dict(s.per_topic)})

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        """Write one metadata record (``rtt-bag recover`` copies them); nothing once closed or failed."""
        with self._lock:
            if self.closed or self.error is not None:
                return
            try:
                self._writer.add_metadata(name, data)
            except OSError as exc:
                self._fail(exc)

    def add_attachment(self, log_time: int, create_time: int, name: str, media_type: str, data: bytes) -> None:
        """Write one attachment record (``rtt-bag recover`` copies them); nothing once closed or failed."""
        with self._lock:
            if self.closed or self.error is not None:
                return
            try:
                self._writer.add_attachment(create_time, log_time, name, media_type, data)
            except OSError as exc:
                self._fail(exc)

    def close(self) -> WriteStats:
        """Write the ``rosbag2`` metadata record, the indexes and the summary; fsync; close the file.

        Calling it again does nothing.  After a failed write it only
        reports: the file stays as it was (readable, not closed).  A write
        that fails here sets :attr:`error` too; nothing is raised.  Owner thread.
        """
        with self._lock:
            if self.closed:
                return self._stats
            self.closed = True
            if self.error is not None:
                return self._stats
            try:
                self._writer.add_metadata("rosbag2", {"serialized_metadata": self._serialized_metadata()})
                self._writer.finish()
                self._sync()
            except OSError as exc:
                self._fail(exc)
                return self._stats
            try:
                self._stream.close()
            except OSError as exc:
                self._fail(exc)
                return self._stats
            self._stats.written_through = self._stats.messages
            self._stats.size_bytes = _size(self.path)
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
                    "offered_qos_profiles": _profiles_or_none(t.offered_qos_profiles),
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


def _profiles_or_none(text: str) -> list:
    """The offers as rosbag2's metadata lists them; none for a text that is not rosbag2's (a recovered foreign file)."""
    try:
        return parse_profiles(text)
    except QosFormatError:
        return []


def _size(path: Path) -> int:
    try:
        return os.path.getsize(path)
    except OSError:
        return 0


def _sync_folder(path: Path) -> None:
    """fsync the folder holding ``path``, so the new file's name survives a power cut too (where supported)."""
    try:
        fd = os.open(path.resolve().parent, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass  # some file systems do not sync folders; the file's own data is synced anyway
    finally:
        os.close(fd)


def _mcap_version() -> str:
    import mcap

    return mcap.__version__
