"""``rtt-bag info``: what a bag holds, per topic: type, message count, time span, rate, QoS.

No ROS needed.  The counts and times come from reading the messages' log
times (the summary's statistics give counts but not a time span per topic),
so every chunk is read and CRC-checked: a damaged file is found here, not
half-way through a replay.  A file that was not closed (no summary) is
read record by record (:func:`tutorial.tools.bag.reader.scan_records`): its
:class:`BagInfo` says ``closed = False`` and what was recovered.
"""

from __future__ import annotations

import datetime
from dataclasses import asdict, dataclass, field
from pathlib import Path

from tutorial.tools.bag.qos import QosFormatError, describe, parse_profiles
from tutorial.tools.bag.reader import BagError, Recovery, _reading, inspect_file, scan_records


@dataclass
class TopicInfo:
    """One topic of a bag.

    Attributes:
        topic, type: e.g. ``/Tank/joint_state``, ``sensor_msgs/msg/JointState``.
        count: messages recorded.
        first_ns, last_ns: first and last log (receive) time, ns since the epoch (None if no message).
        offered_qos_profiles: the publishers' offers (dicts, see :mod:`tutorial.tools.bag.qos`).
        schema_encoding: ``ros2msg`` (or ``ros2idl``, or ``unknown`` when the recorder had no definition).
        type_hash: ``RIHS01_...`` or ``""``.
    """

    topic: str
    type: str
    count: int = 0
    first_ns: int | None = None
    last_ns: int | None = None
    offered_qos_profiles: list = field(default_factory=list)
    schema_encoding: str = ""
    type_hash: str = ""

    @property
    def span_s(self) -> float:
        """Last minus first log time, s (0 for fewer than two messages)."""
        return (self.last_ns - self.first_ns) * 1e-9 if self.count > 1 else 0.0

    @property
    def rate_hz(self) -> float | None:
        """Mean message rate, (count - 1) / span, Hz; None for fewer than two messages."""
        return (self.count - 1) / self.span_s if self.count > 1 and self.span_s > 0 else None


@dataclass
class BagInfo:
    """A bag's summary: file, size (bytes), profile, library, first/last log time (ns), topics.

    ``closed`` is False for a file that was not closed (a killed recorder, a
    full disk); then ``recovery`` says what its complete records held, and
    every count and time here is of those.
    """

    path: Path
    size_bytes: int
    profile: str
    library: str
    count: int
    first_ns: int | None
    last_ns: int | None
    topics: list[TopicInfo]
    closed: bool = True
    recovery: Recovery | None = None

    @property
    def duration_s(self) -> float:
        return (self.last_ns - self.first_ns) * 1e-9 if self.count > 0 else 0.0

    def topic(self, name: str) -> TopicInfo:
        """The :class:`TopicInfo` of one topic; KeyError if the bag has none of that name."""
        for t in self.topics:
            if t.topic == name:
                return t
        raise KeyError(name)

    def as_dict(self) -> dict:
        """JSON-ready: every field, plus each topic's ``span_s`` and ``rate_hz``."""
        d = asdict(self)
        d["path"] = str(self.path)
        d["duration_s"] = self.duration_s
        for t, td in zip(self.topics, d["topics"]):
            td["span_s"], td["rate_hz"] = t.span_s, t.rate_hz
        return d


def bag_info(path) -> BagInfo:
    """Read a bag's summary (any thread; no ROS).

    Raises:
        BagError: the file is not a readable MCAP file, or a channel's
            ``offered_qos_profiles`` is not rosbag2's format.
    """
    p, closed = inspect_file(path)
    return _closed_info(p) if closed else _unclosed_info(p)


def _closed_info(p: Path) -> BagInfo:
    from mcap.reader import make_reader

    topics: dict[int, TopicInfo] = {}
    with open(p, "rb") as f, _reading(p):
        reader = make_reader(f, validate_crcs=True)
        header = reader.get_header()
        summary = reader.get_summary()
        if summary is not None:  # channels without messages appear in the summary only
            for cid, channel in summary.channels.items():
                topics[cid] = _topic_info(p, channel, summary.schemas.get(channel.schema_id))
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            _count(topics, p, schema, channel, message)
    return _info(p, header.profile, header.library, topics)


def _unclosed_info(p: Path) -> BagInfo:
    """What the complete records of a file that was not closed hold, in one pass (:func:`scan_records`)."""
    from mcap.records import Channel, Header, Message, Schema

    recovery = Recovery()
    topics: dict[int, TopicInfo] = {}
    header = Header(profile="", library="")
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    with _reading(p):
        for record in scan_records(p, recovery):
            if isinstance(record, Header):
                header = record
            elif isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
                if record.id not in topics:
                    topics[record.id] = _topic_info(p, record, schemas.get(record.schema_id))
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is None:
                    recovery.orphans += 1
                    continue
                recovery.messages += 1
                _count(topics, p, schemas.get(channel.schema_id), channel, record)
    info = _info(p, header.profile, header.library, topics)
    info.closed, info.recovery = False, recovery
    return info


def _count(topics: dict, p: Path, schema, channel, message) -> None:
    t = topics.get(channel.id)
    if t is None:
        t = topics[channel.id] = _topic_info(p, channel, schema)
    t.count += 1
    t.first_ns = message.log_time if t.first_ns is None else min(t.first_ns, message.log_time)
    t.last_ns = message.log_time if t.last_ns is None else max(t.last_ns, message.log_time)


def _info(p: Path, profile: str, library: str, topics: dict[int, TopicInfo]) -> BagInfo:
    firsts = [t.first_ns for t in topics.values() if t.count]
    lasts = [t.last_ns for t in topics.values() if t.count]
    return BagInfo(
        p,
        p.stat().st_size,
        profile,
        library,
        sum(t.count for t in topics.values()),
        min(firsts) if firsts else None,
        max(lasts) if lasts else None,
        sorted(topics.values(), key=lambda t: t.topic),
    )


def _topic_info(path: Path, channel, schema) -> TopicInfo:
    try:
        profiles = parse_profiles(channel.metadata.get("offered_qos_profiles", ""))
    except QosFormatError as exc:
        raise BagError(f"{path}: topic {channel.topic}: {exc}") from None
    return TopicInfo(
        channel.topic,
        schema.name if schema else "",
        offered_qos_profiles=profiles,
        schema_encoding=schema.encoding if schema else "",
        type_hash=channel.metadata.get("topic_type_hash", ""),
    )


def _time(ns: int | None) -> str:
    if ns is None:
        return "-"
    stamp = datetime.datetime.fromtimestamp(ns * 1e-9).strftime("%b %d %Y %H:%M:%S.%f")[:-3]
    return f"{stamp} ({ns // 1_000_000_000}.{ns % 1_000_000_000:09d})"


def _size(n: int) -> str:
    for unit in ("B", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    raise AssertionError("unreachable")


def format_info(info: BagInfo) -> str:
    """The text ``rtt-bag info`` prints (``ros2 bag info``'s layout, plus span and rate per topic)."""
    lines = [
        f"Files:             {info.path}",
        f"Bag size:          {_size(info.size_bytes)}",
        f"Storage id:        mcap (profile {info.profile or '-'}, written by {info.library or '-'})",
        f"Duration:          {info.duration_s:.3f} s",
        f"Start:             {_time(info.first_ns)}",
        f"End:               {_time(info.last_ns)}",
        f"Messages:          {info.count}",
    ]
    if not info.closed:
        lines.append(f"Not closed:        {info.recovery.describe() if info.recovery else ''}")
    lines.append("Topic information:")
    width = max((len(t.topic) for t in info.topics), default=0)
    twidth = max((len(t.type) for t in info.topics), default=0)
    for t in info.topics:
        # The span as offsets from the bag's first message, and its length.
        span = (
            f"{(t.first_ns - info.first_ns) * 1e-9:7.3f} s to {(t.last_ns - info.first_ns) * 1e-9:7.3f} s "
            f"({t.span_s:.3f} s)"
            if t.count
            else "no messages"
        )
        rate = f"{t.rate_hz:.2f} Hz" if t.rate_hz is not None else "- Hz"
        lines.append(
            f"  {t.topic:<{width}}  {t.type or '?':<{twidth}}  {t.count:7d} msgs  {span}  {rate:>11}  "
            f"QoS {describe(t.offered_qos_profiles)}"
        )
    if not info.topics:
        lines.append("  (none)")
    return "\n".join(lines)
