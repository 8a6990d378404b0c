"""``rtt-bag recover``: copy what can be read of a damaged or unclosed MCAP file into a whole, closed one.

    from tutorial.tools.bag.recover import recover
    result = recover("killed.mcap", "whole.mcap")
    result.recovery.describe()   # '4513 messages recovered from its complete records (the file ends ...)'

It does what the ``mcap recover`` command (the MCAP project's CLI) does,
with the ``mcap`` library's own record-level reader
(:func:`tutorial.tools.bag.reader.scan_records`): read the input record by
record from its start; keep every schema, channel, message, metadata and
attachment record it can read; check each chunk against its CRC and skip
one that is damaged; stop at the first record that cannot be read (where
a killed recorder's file ends) or at the end of the data section.  What
was read is written to a new file by :class:`tutorial.tools.bag.writer.BagWriter`,
so the copy is laid out as rosbag2 lays out a bag: chunks with their
message indexes, the summary, statistics, and a ``rosbag2`` metadata record
counting what was recovered (the input's own ``rosbag2`` record, if it has
one, counts what it had, and is not copied).  Both stock readers
(``mcap``, ``rosbags``) read the copy whole.

A closed, healthy file is copied whole (a fresh index); the input is
never changed.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from tutorial.tools.bag.reader import BagError, Recovery, inspect_file, scan_records
from tutorial.tools.bag.writer import BagWriteError, BagWriter, WriteStats


@dataclass
class RecoverResult:
    """What :func:`recover` did.

    Attributes:
        source, target: the input and the file written.
        closed: whether the input was closed (had its closing magic).
        recovery: what reading the input found (:class:`tutorial.tools.bag.reader.Recovery`).
        stats: what was written (:class:`tutorial.tools.bag.writer.WriteStats`).
        skipped_channels: channels not copied, each with why (a topic given two types).
    """

    source: Path
    target: Path
    closed: bool
    recovery: Recovery
    stats: WriteStats
    skipped_channels: list[str] = field(default_factory=list)


def recover(source, target, *, compression: str = "zstd", overwrite: bool = False) -> RecoverResult:
    """Copy every readable record of ``source`` into a new, closed, indexed MCAP file ``target``.

    Args:
        source: the damaged or unclosed ``.mcap`` file (read only).
        target: the file to write; it must not exist unless ``overwrite``.
        compression: the copy's chunk compression, ``zstd`` (default), ``lz4`` or ``none``.
        overwrite: replace ``target`` if it exists.

    Returns:
        A :class:`RecoverResult`.

    Raises:
        BagError: ``source`` is missing or not MCAP at all, or is ``target`` itself.
        BagWriteError: ``target`` cannot be created, or writing it failed (a full disk).
        ValueError: unknown ``compression``.

    Any thread; it blocks until the copy is closed.
    """
    from mcap.records import Attachment, Channel, Header, Message, Metadata, Schema

    src, closed = inspect_file(source)
    dst = Path(target)
    if dst.exists() and _same_file(src, dst):
        raise BagError(f"{src}: the copy must go to another file")
    recovery = Recovery()
    records = scan_records(src, recovery)  # it stops at what it cannot read, and says so in recovery
    first = next(records, None)  # the header, when the file has one: its profile goes on the copy
    profile = first.profile if isinstance(first, Header) and first.profile else "ros2"
    writer = BagWriter(dst, compression=compression, overwrite=overwrite, write_through=False, profile=profile)
    result = RecoverResult(src, dst, closed, recovery, WriteStats(dst))
    schemas: dict[int, Schema] = {}
    topics: dict[int, str] = {}  # the input's channel id -> its topic in the copy
    try:
        pending = [first] if first is not None and not isinstance(first, Header) else []
        for record in _chain(pending, records):
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                _add_channel(writer, record, schemas.get(record.schema_id), topics, result)
            elif isinstance(record, Message):
                topic = topics.get(record.channel_id)
                if topic is None:
                    recovery.orphans += 1
                    continue
                recovery.messages += 1
                writer.write(topic, record.log_time, record.publish_time, bytes(record.data), record.sequence)
            elif isinstance(record, Metadata) and record.name != "rosbag2":
                writer.add_metadata(record.name, dict(record.metadata))
            elif isinstance(record, Attachment):
                writer.add_attachment(
                    record.log_time, record.create_time, record.name, record.media_type, bytes(record.data)
                )
    finally:
        result.stats = writer.close()
    if writer.error is not None:
        raise writer.error
    return result


def _chain(first: list, rest):
    yield from first
    yield from rest


def _add_channel(writer: BagWriter, channel, schema, topics: dict[int, str], result: RecoverResult) -> None:
    """Register the input's channel on the copy (one per topic, as rosbag2 writes)."""
    metadata = channel.metadata
    definition = None if schema is None else (schema.encoding, bytes(schema.data).decode("utf-8", "replace"))
    try:
        writer.add_topic(
            channel.topic,
            schema.name if schema is not None else "",
            definition,
            metadata.get("offered_qos_profiles", ""),
            metadata.get("topic_type_hash", ""),
            channel.message_encoding,
        )
    except ValueError as exc:  # the topic came before with another type: the first one is kept
        result.skipped_channels.append(f"channel {channel.id}: {exc}")
        return
    topics[channel.id] = channel.topic


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


__all__ = ["RecoverResult", "recover", "BagWriteError"]
