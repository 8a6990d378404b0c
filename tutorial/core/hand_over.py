"""A faster hand-over: the posting thread steps aside until the owner has taken its work.

Speed only: :class:`tutorial.core.call_later.MainLoop` is correct without it.
Python runs one thread at a time (the interpreter lock, the GIL), and that
decides how soon posted work runs.  Posting wakes the owner, but it can run
only once the posting thread lets go of the lock, which a busy thread does
when it next blocks.  After a subscription callback, rclpy's executor runs
its own Python for a while (it builds its wait set again) before it blocks,
and the woken owner waits all that time.  So a posting thread with nothing
urgent to do may step aside: :meth:`HandOverLoop.yield_to_owner` blocks it
(which lets go of the lock) until the owner has taken what was posted, at
most ``HAND_OVER_WAIT``.  :class:`tutorial.ros.spin.SpinThread` does this
after each callback when it is given such a loop; the App gives it one.
What it gains is measured on the book's *Benchmarks* page (the 1 kHz
latency targets).
"""

from __future__ import annotations

import threading

from tutorial.core.call_later import MainLoop

HAND_OVER_WAIT = 0.001  # s: the longest yield_to_owner() waits for the owner to take posted work


class HandOverLoop(MainLoop):
    """A :class:`MainLoop` whose posting threads may wait, briefly, for the owner to take their work.

    Same threads as :class:`MainLoop`; :meth:`yield_to_owner` is for any
    thread but the owner.
    """

    def __init__(self, owner: threading.Thread | None = None):
        super().__init__(owner)
        # Signalled (under the loop's lock) each time the owner takes the pending calls.
        self._taken_signal = threading.Condition(self._lock)
        self._taken_upto = 0  # the value of `posted` when the owner last took the pending calls
        self._owner_waiting = False  # the owner is blocked in run_once(), waiting for work
        self.yields = 0  # yield_to_owner() calls that waited until the owner took the work
        self.yield_timeouts = 0  # ... and that gave up after HAND_OVER_WAIT

    def yield_to_owner(self, timeout: float = HAND_OVER_WAIT) -> bool:
        """Step aside until the owner has taken every call posted so far (any thread but the owner).

        Blocking here lets go of the interpreter lock, so an owner that was
        woken by the post runs it at once instead of waiting for this
        thread's next blocking call.  It waits only when the owner is blocked
        in :meth:`run_once` and posted calls are still pending: an owner busy
        drawing, or not running the loop at all, costs nothing.

        Args:
            timeout: the longest wait, s.

        Returns:
            True when the owner took the work in time; False when there was
            nothing to wait for, or after ``timeout`` (counted in :attr:`yield_timeouts`).
        """
        if threading.get_ident() == self._owner:
            return False  # the owner cannot wait for itself
        with self._lock:
            target = self.posted
            if not self._owner_waiting or self._taken_upto >= target:
                return False
            taken = self._taken_signal.wait_for(lambda: self._taken_upto >= target, timeout)
            if taken:
                self.yields += 1
            else:
                self.yield_timeouts += 1
            return taken

    @property
    def owner_waiting(self) -> bool:
        """Whether the owner is blocked in :meth:`run_once` now (any thread; a hint, stale at once)."""
        return self._owner_waiting

    def _wait(self, timeout: float) -> None:
        self._owner_waiting = True  # a hint for yield_to_owner(); a stale read only costs a wait
        try:
            super()._wait(timeout)
        finally:  # a Ctrl-C raised in the wait must not leave posting threads waiting for nobody
            self._owner_waiting = False

    def _taken(self) -> None:
        self._taken_upto = self.posted
        self._taken_signal.notify_all()  # a thread in yield_to_owner() may go on
