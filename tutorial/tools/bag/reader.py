"""Read a bag without ROS: raw CDR messages and decoded messages (a joint's series: :mod:`tutorial.tools.bag.series`).

Everything here uses the ``mcap`` library's reader, and the
``mcap-ros2-support`` decoder for the messages' contents: it builds the
deserializer from the ``ros2msg`` schema stored in the file, so a bag can be
read on a machine with neither ROS nor the message packages.

A file that was **not closed** (the recorder was killed, the machine lost
power, the disk filled) has no summary and no closing magic.  It is read,
not refused: :func:`scan_records` walks it record by record with the
``mcap`` library's own record-level reader (``StreamReader``, chunks
checked against their CRCs one by one, as the ``mcap recover`` command
does), and every complete chunk's messages are used; a :class:`Recovery`
says how far it got and why it stopped.  :func:`iter_raw`,
:func:`read_messages` and :func:`tutorial.tools.bag.info.bag_info` do this by
themselves; ``rtt-bag recover`` (:mod:`tutorial.tools.bag.recover`) writes a
closed, indexed copy.

Anything else that is not a readable MCAP file gives one
:class:`BagError` with a one-line reason: missing, not an MCAP file, or
corrupt (the parser's or a chunk CRC's complaint).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

MAGIC = b"\x89MCAP0\r\n"  # MCAP's opening and closing magic
NOT_CLOSED = "the recording was not closed (the recorder was killed, or the disk filled), or the copy is incomplete"


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


@dataclass
class Recovery:
    """What reading a file that was not closed found (filled in by :func:`scan_records`).

    Attributes:
        messages: messages read from complete records (and known channels).
        chunks: chunks read whole; ``damaged_chunks``: chunks skipped (bad CRC, would not decompress).
        orphans: messages of a channel the file never defined (skipped).
        read_bytes: where the last complete record ends, bytes from the start.
        size_bytes: the file's size.
        stop: why reading stopped, one phrase (e.g. ``the file ends inside a record at byte 10341``).
    """

    messages: int = 0
    chunks: int = 0
    damaged_chunks: int = 0
    orphans: int = 0
    read_bytes: int = 0
    size_bytes: int = 0
    stop: str = ""

    def describe(self) -> str:
        """One line: how many messages were recovered, and what was lost."""
        lost = []
        if self.damaged_chunks:
            lost.append(f"{self.damaged_chunks} damaged chunk{'s' if self.damaged_chunks != 1 else ''} skipped")
        if self.orphans:
            lost.append(f"{self.orphans} messages of undefined channels skipped")
        if self.stop:
            lost.append(self.stop)
        return f"{self.messages} messages recovered from its complete records" + (
            f" ({'; '.join(lost)})" if lost else ""
        )


def inspect_file(path) -> tuple[Path, bool]:
    """``(path, closed)``: the file as a Path, and whether it ends in MCAP's closing magic.

    Raises:
        BagError: missing, not a regular file, empty, or not MCAP (no magic at its start).
    """
    p = Path(path)
    try:
        if not p.exists():
            raise BagError(f"{p}: no such file")
        if not p.is_file():
            raise BagError(f"{p}: not a file")
        size = p.stat().st_size
        with open(p, "rb") as f:
            head = f.read(len(MAGIC))
            f.seek(max(0, size - len(MAGIC)))
            tail = f.read(len(MAGIC))
    except OSError as exc:
        raise BagError(f"{p}: cannot read it: {exc.strerror or exc}") from None
    except ValueError as exc:  # a NUL byte in the name
        raise BagError(f"{p!r}: not a usable file name ({exc})") from None
    if size == 0:
        raise BagError(f"{p}: empty")
    if head != MAGIC[: len(head)] or len(head) < len(MAGIC):
        raise BagError(f"{p}: not an MCAP file (no MCAP magic at its start)")
    return p, size >= 2 * len(MAGIC) and tail == MAGIC


def check_file(path) -> Path:
    """``path`` as a Path if it is a whole (closed) MCAP file (magic at both ends).

    Raises:
        BagError: missing, not a file, not MCAP, or not closed.
    """
    p, closed = inspect_file(path)
    if not closed:
        raise BagError(f"{p}: truncated MCAP file (no closing magic at its end): {NOT_CLOSED}")
    return p


@contextlib.contextmanager
def _reading(path: Path):
    """Turn any failure of the MCAP parser or the CDR decoder into one :class:`BagError`.

    The parser fails in many ways on damaged bytes (its own ``McapError``s,
    ``struct.error``, zstd/lz4 errors, ``UnicodeDecodeError``, ``MemoryError``
    for an absurd length...); each is a property of the file, not a bug
    here, so each becomes "corrupt".
    """
    try:
        yield
    except BagError:
        raise
    except Exception as exc:  # noqa: BLE001 - see the docstring: the file's fault, reported as one line
        detail = str(exc).splitlines()[0] if str(exc) else ""
        raise BagError(
            f"{path}: corrupt MCAP file ({type(exc).__name__}{': ' + detail[:200] if detail else ''}); "
            "rtt-bag recover copies what can still be read"
        ) from None


def scan_records(path, recovery: Recovery | None = None) -> Iterator[object]:
    """The records of an MCAP file in file order, chunks opened, as far as they can be read.

    For a file that was not closed (or is damaged): yields ``mcap.records``
    ``Header``, ``Schema``, ``Channel``, ``Message``, ``Metadata`` and
    ``Attachment`` records.  Each chunk is checked against its CRC and
    decompressed whole before any of its records is yielded, so a chunk
    cut short or damaged gives nothing (it is counted); its messages are
    yielded in log-time order.  Reading stops at the first record that
    cannot be read (the file's end, usually in the middle of a record) or
    at the end of the data section; ``recovery`` tells where and why.

    Raises:
        BagError: the file is missing or not MCAP at all.
    """
    from mcap.exceptions import EndOfFile, RecordLengthLimitExceeded
    from mcap.records import Chunk, DataEnd, Footer, Message
    from mcap.stream_reader import StreamReader, breakup_chunk

    p, _closed = inspect_file(path)
    report = recovery if recovery is not None else Recovery()
    report.size_bytes = p.stat().st_size
    with open(p, "rb") as f:
        # No record can be longer than the file: a damaged length is caught before anything is allocated.
        records = StreamReader(f, emit_chunks=True, record_size_limit=report.size_bytes).records
        report.read_bytes = len(MAGIC)
        while True:
            start = f.tell()
            try:
                record = next(records)
            except StopIteration:
                return
            except (EndOfFile, RecordLengthLimitExceeded):
                report.stop = f"the file ends inside the record at byte {start}"
                return
            except Exception as exc:  # noqa: BLE001 - damaged bytes: the parser's many complaints
                ends_early = f.tell() >= report.size_bytes
                report.stop = (
                    f"the file ends inside the record at byte {start}"
                    if ends_early
                    else f"a damaged record at byte {start} ({type(exc).__name__})"
                )
                return
            report.read_bytes = f.tell()
            if isinstance(record, (DataEnd, Footer)):
                return  # the data section is over: what follows is the summary
            if isinstance(record, Chunk):
                try:
                    inner = breakup_chunk(record, validate_crc=True)
                except Exception:  # noqa: BLE001 - a bad CRC, a damaged compressed stream
                    report.damaged_chunks += 1
                    continue
                report.chunks += 1
                messages = [r for r in inner if isinstance(r, Message)]
                yield from (r for r in inner if not isinstance(r, Message))
                yield from sorted(messages, key=lambda m: m.log_time)
            else:
                yield record


def _scan_messages(path, recovery: Recovery | None) -> Iterator[tuple[object, object, object]]:
    """``(schema or None, channel, message)`` of a file that was not closed, in file order (:func:`scan_records`)."""
    from mcap.records import Channel, Message, Schema

    report = recovery if recovery is not None else Recovery()
    schemas: dict[int, object] = {}
    channels: dict[int, object] = {}
    p, _closed = inspect_file(path)
    with _reading(p):
        for record in scan_records(p, report):
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is None:
                    report.orphans += 1
                    continue
                report.messages += 1
                yield schemas.get(channel.schema_id), channel, record


@contextlib.contextmanager
def open_reader(path, decode: bool = False):
    """An ``mcap.reader.McapReader`` on a whole, closed file, closed on exit (chunk CRCs are validated).

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


def _messages(path, topics=None, start_time: int | None = None, recovery: Recovery | None = None):
    """``(schema, channel, message)``: indexed and in log-time order for a closed file, else scanned."""
    p, closed = inspect_file(path)
    if closed:
        with open_reader(p) as reader:
            yield from reader.iter_messages(topics=topics, starting_at=start_time, log_time_order=True)
        return
    wanted = None if topics is None else set(topics)
    for schema, channel, message in _scan_messages(p, recovery):
        if (wanted is None or channel.topic in wanted) and (start_time is None or message.log_time >= start_time):
            yield schema, channel, message


def iter_raw(
    path, topics=None, start_time: int | None = None, recovery: Recovery | None = None
) -> Iterator[RawMessage]:
    """The recorded messages, undecoded.

    In log-time order for a closed file; for a file that was not closed,
    in the order they were written (each chunk's in log-time order: the
    recorder writes them as they arrive), and only those of complete
    records (``recovery``, if given, says what was found).

    Args:
        path: the ``.mcap`` file.
        topics: only these topics (None: all).
        start_time: skip messages logged before this time (ns since the epoch).
        recovery: filled in when the file was not closed.

    Raises:
        BagError: the file is not a readable MCAP file.
    """
    for schema, channel, message in _messages(path, topics, start_time, recovery):
        yield RawMessage(
            channel.topic,
            schema.name if schema else "",
            message.log_time,
            message.publish_time,
            bytes(message.data),
        )


def read_messages(path, topics=None, recovery: Recovery | None = None) -> Iterator[tuple[str, int, object]]:
    """``(topic, log_time_ns, message)``, each message decoded without ROS (order as :func:`iter_raw`).

    The message is an object with the type's fields as attributes (the
    ``mcap-ros2-support`` decoder's), e.g. ``msg.header.stamp.sec``,
    ``msg.position``.

    Raises:
        BagError: unreadable file, or a schema or message the decoder cannot parse.
    """
    p, closed = inspect_file(path)
    if closed:
        with open_reader(p, decode=True) as reader:
            for _schema, channel, message, decoded in reader.iter_decoded_messages(topics=topics, log_time_order=True):
                yield channel.topic, message.log_time, decoded
        return
    from mcap_ros2.decoder import DecoderFactory

    factory = DecoderFactory()
    decoders: dict[int, object] = {}
    for schema, channel, message in _messages(p, topics, None, recovery):
        with _reading(p):
            decoder = decoders.get(channel.id)
            if decoder is None:
                decoder = decoders[channel.id] = factory.decoder_for(channel.message_encoding, schema)
                if decoder is None:
                    raise BagError(f"{p}: no decoder for {channel.topic} ({channel.message_encoding})")
            decoded = decoder(message.data)
        yield channel.topic, message.log_time, decoded
