"""Periodic output from a fixed simulation step: when is the next joint state, IMU mean or picture due?

Every periodic publisher (joint states, the IMU, the camera, the recorder
of trajectories) decides when it is due with the same exact counter, so it
lives in the core, below every step: a step module that defined it would
change every other step when a learner edits its notebook.
"""

from __future__ import annotations


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
