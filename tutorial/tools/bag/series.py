"""A joint's positions over a recording, without ROS: numpy arrays by joint name.

    from tutorial.tools.bag.series import joint_series
    series = joint_series("drive.mcap", "/Tank/joint_state")
    series.positions["TURRET_Y"]      # (n,) array, rad
    series.stamp                      # (n,) array, s: the messages' header stamps

Built on :func:`tutorial.tools.bag.reader.read_messages`; a topic the file does
not have is named with the ones it has (:func:`tutorial.tools.bag.info.bag_info`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tutorial.tools.bag.info import bag_info
from tutorial.tools.bag.reader import BagError, read_messages


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
    one message to the next).  A file that was not closed is read as far
    as its complete records go.

    Raises:
        BagError: unreadable file, no such topic in it, or not JointStates on it.
    """
    stamps: list[float] = []
    logs: list[int] = []
    rows: list[dict[str, float]] = []
    names: dict[str, None] = {}  # insertion-ordered set: joints in the order first seen
    for _topic, log_time, msg in read_messages(path, topics=[topic]):
        try:
            stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
            row = {str(n): float(q) for n, q in zip(msg.name, msg.position)}
        except (AttributeError, TypeError, ValueError):
            raise BagError(f"{path}: {topic} does not hold sensor_msgs/msg/JointState messages") from None
        stamps.append(stamp)
        logs.append(log_time)
        rows.append(row)
        names.update(dict.fromkeys(row))
    if not rows:
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
