"""QoS in a bag: the ``offered_qos_profiles`` channel metadata, as rosbag2 writes and reads it.

A recorder stores, for each topic, the QoS every publisher offered when it
subscribed.  rosbag2 (Jazzy, bag format version 9) writes them as a YAML
list, one map per publisher, in this order (``rosbag2_storage/src/qos.cpp``,
``YAML::Dump``, no trailing newline)::

    - history: unknown
      depth: 0
      reliability: reliable
      durability: volatile
      deadline:
        sec: 9223372036
        nsec: 854775807
      lifespan:
        ...
      liveliness: automatic
      liveliness_lease_duration:
        ...
      avoid_ros_namespace_conventions: false

Discovery does not tell a publisher's history, so it reads ``unknown``,
depth 0.  Format version 8 and older wrote the policies as integers;
:func:`parse_profiles` reads both, as rosbag2 does.

The two adaptations rosbag2 makes, reproduced here:

* recording (:func:`request_for_offers`, ``Rosbag2QoS::adapt_request_to_offers``):
  subscribe reliable only if *every* publisher offers reliable, transient
  local only if every publisher offers it; otherwise best effort / volatile,
  which matches every publisher.
* playing (:func:`offer_for_recorded`, ``Rosbag2QoS::adapt_offer_to_recorded_offers``):
  if all recorded publishers offered the same profile (history and lifespan
  aside, they do not affect matching), offer that profile with history
  keep last 10; if they differed, offer rosbag2's default (reliable,
  volatile, keep last 10).

Profiles travel as plain dicts (the YAML's keys); only :func:`to_qos_profile`
and :func:`profile_dict` touch rclpy.
"""

from __future__ import annotations

import yaml

INFINITE_NS = 2**63 - 1  # RMW_DURATION_INFINITE: {sec: 9223372036, nsec: 854775807}
# "Infinity" as Foxy-era middlewares wrote it; rosbag2 reads each as RMW_DURATION_INFINITE.
_FOXY_INFINITIES = {(0x7FFFFFFF, 0xFFFFFFFF), (0x7FFFFFFF, 0x7FFFFFFF)}
DEFAULT_DEPTH = 10  # rmw_qos_profile_default.depth, rosbag2's default history

# Policy names in the order of their rmw enum values (format version <= 8 wrote the values).
_POLICY_VALUES = {
    "history": ["system_default", "keep_last", "keep_all", "unknown"],
    "reliability": ["system_default", "reliable", "best_effort", "unknown", "best_available"],
    "durability": ["system_default", "transient_local", "volatile", "unknown", "best_available"],
    "liveliness": ["system_default", "automatic", "manual_by_node", "manual_by_topic", "unknown", "best_available"],
}
_DURATIONS = ("deadline", "lifespan", "liveliness_lease_duration")
_KEYS = (
    "history",
    "depth",
    "reliability",
    "durability",
    "deadline",
    "lifespan",
    "liveliness",
    "liveliness_lease_duration",
    "avoid_ros_namespace_conventions",
)
_COMPATIBILITY_KEYS = ("reliability", "durability", "deadline", "liveliness", "liveliness_lease_duration")


class QosFormatError(ValueError):
    """``offered_qos_profiles`` text that is not a list of rosbag2 QoS profiles."""


def _duration(ns: int) -> dict:
    sec, nsec = divmod(int(ns), 1_000_000_000)
    return {"sec": sec, "nsec": nsec}


DEFAULT_PROFILE = {  # rosbag2's Rosbag2QoS{}: rmw_qos_profile_default
    "history": "keep_last",
    "depth": DEFAULT_DEPTH,
    "reliability": "reliable",
    "durability": "volatile",
    "deadline": _duration(0),
    "lifespan": _duration(0),
    "liveliness": "system_default",
    "liveliness_lease_duration": _duration(0),
    "avoid_ros_namespace_conventions": False,
}


def profile_dict(qos) -> dict:
    """One rclpy ``QoSProfile`` (e.g. ``TopicEndpointInfo.qos_profile``) as rosbag2's YAML map."""
    return {
        "history": qos.history.short_key,
        "depth": int(qos.depth),
        "reliability": qos.reliability.short_key,
        "durability": qos.durability.short_key,
        "deadline": _duration(qos.deadline.nanoseconds),
        "lifespan": _duration(qos.lifespan.nanoseconds),
        "liveliness": qos.liveliness.short_key,
        "liveliness_lease_duration": _duration(qos.liveliness_lease_duration.nanoseconds),
        "avoid_ros_namespace_conventions": bool(qos.avoid_ros_namespace_conventions),
    }


def serialize_profiles(profiles: list[dict]) -> str:
    """The ``offered_qos_profiles`` text of a list of profile dicts (rosbag2's format version 9).

    An empty list gives ``[]``, as ``YAML::Dump`` of an empty sequence does.
    """
    if not profiles:
        return "[]"
    ordered = [{key: p[key] for key in _KEYS} for p in profiles]
    return yaml.safe_dump(ordered, sort_keys=False, default_flow_style=False).rstrip("\n")


def parse_profiles(text: str) -> list[dict]:
    """The profiles of an ``offered_qos_profiles`` text, normalized to version 9 dicts.

    Accepts version 9 (policy names) and version 4-8 (integers).  Foxy's
    ways of writing "infinite" become :data:`INFINITE_NS`'s ``{sec, nsec}``.

    Raises:
        QosFormatError: the text is not such a list.
    """
    if not text or not text.strip():
        return []
    try:
        loaded = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise QosFormatError(f"offered_qos_profiles is not YAML: {exc}".splitlines()[0]) from None
    if loaded is None:
        return []
    if not isinstance(loaded, list) or not all(isinstance(p, dict) for p in loaded):
        raise QosFormatError("offered_qos_profiles is not a list of QoS profiles")
    out = []
    for p in loaded:
        try:
            profile = {}
            for key, names in _POLICY_VALUES.items():
                value = p[key]
                profile[key] = names[value] if isinstance(value, int) else str(value)
                if profile[key] not in names:
                    raise QosFormatError(f"offered_qos_profiles: unknown {key} {value!r}")
            profile["depth"] = int(p["depth"])
            for key in _DURATIONS:
                sec, nsec = int(p[key]["sec"]), int(p[key]["nsec"])
                if (sec, nsec) in _FOXY_INFINITIES:
                    sec, nsec = divmod(INFINITE_NS, 1_000_000_000)
                profile[key] = {"sec": sec, "nsec": nsec}
            profile["avoid_ros_namespace_conventions"] = bool(p["avoid_ros_namespace_conventions"])
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            if isinstance(exc, QosFormatError):
                raise
            raise QosFormatError(f"offered_qos_profiles: bad or missing field ({exc!r})") from None
        out.append({key: profile[key] for key in _KEYS})
    return out


def offer_for_recorded(profiles: list[dict]) -> tuple[dict, str | None]:
    """The profile a player offers for a topic recorded with these publishers' ``profiles``.

    Returns:
        ``(profile, warning)``: the warning (None when there is none) says
        the publishers disagreed and the default was taken, as rosbag2 warns.
    """
    if not profiles:
        return dict(DEFAULT_PROFILE), None
    first = profiles[0]
    if all(all(p[k] == first[k] for k in _COMPATIBILITY_KEYS) for p in profiles[1:]):
        return {**first, "history": "keep_last", "depth": DEFAULT_DEPTH}, None
    return dict(DEFAULT_PROFILE), (
        "the recorded publishers offered different QoS profiles; "
        "offering the default (reliable, volatile, keep last 10)"
    )


def request_for_offers(profiles: list[dict], depth: int) -> dict:
    """The profile a recorder requests to match every publisher offering one of ``profiles``.

    Args:
        profiles: the offered profiles (dicts, e.g. from :func:`profile_dict`).
        depth: the subscription's keep-last depth (history does not affect
            matching; see :class:`tutorial.tools.bag.record.BagRecorder` for ours).
    """
    request = dict(DEFAULT_PROFILE, depth=depth)
    if profiles:
        request["reliability"] = "reliable" if all(p["reliability"] == "reliable" for p in profiles) else "best_effort"
        request["durability"] = (
            "transient_local" if all(p["durability"] == "transient_local" for p in profiles) else "volatile"
        )
    return request


def to_qos_profile(profile: dict):
    """An rclpy ``QoSProfile`` from a profile dict (any thread)."""
    from rclpy.duration import Duration
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy

    def policy(enum, key):
        by_name = {e.short_key: e for e in enum}
        if profile[key] not in by_name:
            raise QosFormatError(f"{key} {profile[key]!r} is not a policy rclpy knows")
        return by_name[profile[key]]

    def duration(key):
        d = profile[key]
        return Duration(nanoseconds=min(INFINITE_NS, d["sec"] * 1_000_000_000 + d["nsec"]))

    history = policy(HistoryPolicy, "history")
    if history == HistoryPolicy.UNKNOWN:
        history = HistoryPolicy.KEEP_LAST
    return QoSProfile(
        history=history,
        depth=max(1, profile["depth"]),
        reliability=policy(ReliabilityPolicy, "reliability"),
        durability=policy(DurabilityPolicy, "durability"),
        deadline=duration("deadline"),
        lifespan=duration("lifespan"),
        liveliness=policy(LivelinessPolicy, "liveliness"),
        liveliness_lease_duration=duration("liveliness_lease_duration"),
        avoid_ros_namespace_conventions=profile["avoid_ros_namespace_conventions"],
    )


def describe(profiles: list[dict]) -> str:
    """A short text of the recorded offers, e.g. ``reliable, volatile (1 publisher)``."""
    if not profiles:
        return "no QoS recorded"
    kinds = sorted({f"{p['reliability']}, {p['durability']}" for p in profiles})
    n = len(profiles)
    return f"{' / '.join(kinds)} ({n} publisher{'s' if n != 1 else ''})"
