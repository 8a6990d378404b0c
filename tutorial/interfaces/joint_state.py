"""``/<body>/joint_state`` (``sensor_msgs/JointState``): a body's numbered joints.

One entry per numbered joint (:mod:`tutorial.core.body`): ``position`` in
rad (hinge) or m (slide), ``velocity`` in rad/s or m/s, ``effort`` in N*m
or N, stamped with simulation time.  Topic :func:`joint_state_topic`; QoS
:func:`joint_state_qos` for the publisher, :func:`joint_state_viewer_qos`
for a viewer.

A received JointState is matched to a body's joints trusting nothing.
A message from the network may come from a buggy publisher, another robot
or a different version of the model.  :func:`match_joint_state` looks at
every entry of the message and decides, for each, to apply it or to reject it
with one reason:

==================  ===========================================================
reason              the entry
==================  ===========================================================
``unknown_name``    names no numbered joint of this body (or is empty)
``duplicate_name``  names a joint that appears more than once in the message:
                    which one is right cannot be known, so all are rejected
``no_position``     has a name but the position array is too short
``no_name``         has a position but the name array is too short
``not_finite``      position is NaN or infinite
``out_of_range``    position is outside the joint's range by more than the
                    tolerance
==================  ===========================================================

An entry naming a joint the body computes from another (a URDF mimic
joint, ``Body.following``: a gripper's second finger) is *ignored*, neither
applied nor rejected: ``joint_state_publisher`` sends those too, and the
viewer moves them with the joint they follow.

Policy for ranges: *reject*, do not clamp.  A value a little past a limit
(within ``tolerance``: 0.05 rad or 0.01 m) is what a simulated or real joint
does when it presses on its stop, so it is applied unchanged.  A value far
outside is a broken publisher or the wrong model; clamping it would show a
plausible but false posture, so the joint keeps its last good value and
the rejection is counted.  Entries are matched by name, in any order;
body joints the message does not mention keep their values (``missing``).

The function is pure: it returns a :class:`MatchReport` and changes
nothing, so any thread may call it.  Applying the report is the owner's job.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

from tutorial.core.body import JointInfo


def joint_state_topic(body_name: str) -> str:
    """``/<body name>/joint_state``: named after the body, so any model works."""
    return f"/{body_name}/joint_state"


def joint_state_qos():
    """The joint state's QoS: reliable, keep last 1, transient local.

    * keep last 1: a viewer needs only the newest state; an older one is
      already out of date, so no queue builds up behind a slow subscriber;
    * reliable: a state that is sent should arrive, the last one before
      the simulation stops above all;
    * transient local: the publisher keeps its newest state for subscribers
      that join later, so a viewer started while the simulation is paused
      (or publishing slowly) still gets it.  A volatile subscriber matches
      it too, so every ordinary subscriber works unchanged.
    """
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


def joint_state_viewer_qos():
    """What a viewer asks of a joint-state publisher: reliable, keep last 1, volatile.

    Volatile asks the least, so every publisher matches: ours (transient
    local) and ordinary volatile ones, as most robots and
    ``joint_state_publisher`` use.  (DDS does not match a transient-local
    subscriber with a volatile publisher.)
    """
    from rclpy.qos import DurabilityPolicy

    qos = joint_state_qos()
    qos.durability = DurabilityPolicy.VOLATILE
    return qos


REASONS = ("unknown_name", "duplicate_name", "no_position", "no_name", "not_finite", "out_of_range")
HINGE_TOLERANCE = 0.05  # rad
SLIDE_TOLERANCE = 0.01  # m


@dataclass
class MatchReport:
    """What to do with one message.

    Attributes:
        applied: joint name -> position to apply (rad or m), in message order.
        rejected: (entry index, name or None, reason) for each rejected entry.
        missing: names of body joints the message gave no usable value for.
        ignored: names of the entries that named a following joint (see ``following``).
    """

    applied: dict[str, float] = field(default_factory=dict)
    rejected: list[tuple[int, str | None, str]] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    ignored: list[str] = field(default_factory=list)

    def counts(self) -> Counter:
        """Rejections by reason."""
        return Counter(reason for _, _, reason in self.rejected)

    @property
    def matched(self) -> int:
        return len(self.applied)


def _tolerance(joint: JointInfo) -> float:
    return SLIDE_TOLERANCE if joint.kind == "slide" else HINGE_TOLERANCE


def match_joint_state(
    joints: Sequence[JointInfo],
    names: Sequence[str],
    positions: Sequence[float],
    following: Collection[str] = (),
) -> MatchReport:
    """Decide which entries of a JointState to apply to which joints.

    Args:
        joints: the body's numbered joints (``Body.joint_infos``).
        names: ``JointState.name`` as received (any length, any order).
        positions: ``JointState.position`` as received (any length, any values).
        following: names of the body's joints that follow another
            (``Body.following``): their entries are ignored, not rejected.

    Returns:
        A :class:`MatchReport`: every entry is applied, ignored (it names a
        following joint), or rejected with exactly one reason (see the
        module text).

    Never raises for any strings in ``names`` and any numbers in ``positions``
    (all a received JointState can hold; a name that is not hashable, which no
    message can carry, raises ``TypeError``).
    """
    by_name = {j.name: j for j in joints}
    occurrences = Counter(n for n in names if n in by_name)
    report = MatchReport()
    for i in range(max(len(names), len(positions))):
        name = names[i] if i < len(names) else None
        if name is None:
            report.rejected.append((i, None, "no_name"))
            continue
        joint = by_name.get(name)
        if joint is None and name in following:
            report.ignored.append(name)
            continue
        if joint is None:
            report.rejected.append((i, name, "unknown_name"))
            continue
        if occurrences[name] > 1:
            report.rejected.append((i, name, "duplicate_name"))
            continue
        if i >= len(positions):
            report.rejected.append((i, name, "no_position"))
            continue
        try:
            q = float(positions[i])
        except (TypeError, ValueError):
            q = math.nan
        if not math.isfinite(q):
            report.rejected.append((i, name, "not_finite"))
            continue
        tol = _tolerance(joint)
        if joint.limited and not (joint.lower - tol <= q <= joint.upper + tol):
            report.rejected.append((i, name, "out_of_range"))
            continue
        report.applied[name] = q
    report.missing = [j.name for j in joints if j.name not in report.applied]
    return report


def match_like_the_original(
    joint_names: Sequence[str], names: Sequence[str], positions: Sequence[float]
) -> dict[int, float]:
    """The original tutorial's loop, for comparison: joint *i* takes entry *i* if the names agree.

    It is bounded (never reads past an array) and checks names, but it
    needs the message in the model's joint order and applies NaN or any
    out-of-range value as is.  Returns joint index -> position.
    """
    n = min(len(joint_names), len(names), len(positions))
    return {i: positions[i] for i in range(n) if joint_names[i] == names[i]}
