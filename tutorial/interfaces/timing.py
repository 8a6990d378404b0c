"""Simulated time on the wire: message stamps.

Every message the simulation publishes is stamped with *simulation* time
(:func:`stamp_parts`).  When a periodic output is due is decided by
:class:`tutorial.core.period.PeriodAccumulator`.  Both live in modules of
their own because they are shared: a step module that defined them would
change every other step when a learner edits its notebook.
"""

from __future__ import annotations


def stamp_parts(t: float) -> tuple[int, int]:
    """Simulation time ``t`` (s, >= 0) as a ROS time ``(sec, nanosec)``.

    Rounded to the nanosecond first, so 0.9999999999 s is (1, 0), never
    (0, 1_000_000_000).  Any thread may call it.
    """
    return divmod(round(t * 1e9), 1_000_000_000)


def stamp_seconds(stamp) -> float:
    """A ``builtin_interfaces/Time`` (``header.stamp``) as s.  Any thread may call it."""
    return stamp.sec + stamp.nanosec * 1e-9
