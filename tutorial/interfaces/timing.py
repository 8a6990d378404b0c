"""Simulated time on the wire: message stamps, and periodic output from a fixed step.

Every message the simulation publishes is stamped with *simulation* time
(:func:`stamp_parts`), and every periodic publisher (joint states, the IMU,
the camera, the recorder of trajectories) decides when it is due with the
same exact counter (:class:`PeriodAccumulator`).  They live here, in a
module of their own, because they are shared: a step module that defined
them would change every other step when a learner edits its notebook.
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


class PeriodAccumulator:
    """Decides, step by step, when a periodic output is due.

    Args:
        time_step: the simulation step, s.
        rate: outputs per simulated second, Hz; a rate of one per step or
            more (or 0) means every step.
        first_due: whether the first step is due (default).  A publisher
            that sends the state the simulation starts in from ``start()``
            passes False: its first periodic output is then one period later.

    ``tick()`` is called once per step and returns True when an output is
    due.  It counts integer nanoseconds, so it is exact for any step and
    rate that are whole numbers of nanoseconds: 0.001 s added twenty times
    is not exactly 0.02 s in floating point, but 1_000_000 ns is.  Used by
    one thread only.
    """

    def __init__(self, time_step: float, rate: float, first_due: bool = True):
        self.step_ns = max(1, round(time_step * 1e9))
        rate_ns = self.step_ns if rate <= 0 else round(1e9 / rate)
        self.period_ns = max(self.step_ns, rate_ns)
        # due at once, or (first_due False) one period from now
        self.elapsed_ns = self.period_ns if first_due else 0

    def tick(self) -> bool:
        """One step has passed: True when an output is due now."""
        due = self.elapsed_ns >= self.period_ns
        if due:
            self.elapsed_ns -= self.period_ns  # carry the remainder over
        self.elapsed_ns += self.step_ns
        return due
