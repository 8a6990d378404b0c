"""Hand work to the owner (main) thread: the analog of Choreonoid's ``callLater``.

A subscription callback runs on the ROS spin thread, but the viewer's model
and its meshcat connection belong to the main thread (meshcat's zmq socket is
not thread-safe, and a model half-updated by two threads draws nonsense).  So
the callback does not touch them: it *posts* the work to the main thread's
:class:`MainLoop` and returns at once.  The main thread runs posted work
between frames, one call at a time, so that work needs no lock.

Posting is coalescing, like Choreonoid's ``LazyCaller``: while a call to a
function is pending, posting the same function again replaces its arguments
instead of queueing a second call.  The newest state wins and a burst of
messages can never build a backlog; :attr:`MainLoop.coalesced` counts the
calls that were superseded.

Python runs one thread at a time (the interpreter lock, the GIL), and that
decides how soon posted work runs.  Posting wakes the main thread, but it can
only run once the posting thread lets go of the lock, which a busy thread
does when it next blocks.  After a subscription callback, rclpy's executor
runs its own Python for 0.1 to 0.2 ms (it builds its wait set again) before it
blocks; the woken main thread waits all that time.  So a posting thread that
has nothing urgent to do may *step aside*: :meth:`MainLoop.yield_to_owner`
blocks it (which lets go of the lock) until the owner has taken what was
posted, at most ``HAND_OVER_WAIT``.  :class:`tutorial.ros.spin.SpinThread`
does this after each callback when it is given the loop.  In the benchmark
at 1 kHz, callback -> applied on the main thread then takes 0.07 to 0.13 ms
(p50) instead of 0.16 to 0.19 ms (``book/benchmarks.md``).
"""

from __future__ import annotations

import threading
import time
import traceback
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Any

HAND_OVER_WAIT = 0.001  # s: the longest yield_to_owner() waits for the owner to take posted work


class WrongThreadError(RuntimeError):
    """A method that only the owner thread may call was called from another thread."""


class MainLoop:
    """A coalescing queue of calls that run on one owner thread.

    The thread that creates the loop owns it (or pass ``owner``).  Any thread
    may :meth:`call_later`; only the owner may :meth:`process_pending`,
    :meth:`run_once` or :meth:`run`.

    Errors raised by posted calls do not stop the loop: they are printed and
    kept in :attr:`errors` (at most 100).
    """

    def __init__(self, owner: threading.Thread | None = None):
        self._owner = (owner or threading.current_thread()).ident
        self._lock = threading.Lock()
        # Signalled (under _lock) each time the owner takes the pending calls: see yield_to_owner().
        self._taken = threading.Condition(self._lock)
        self._taken_upto = 0  # the value of `posted` when the owner last took the pending calls
        self._owner_waiting = False  # the owner is blocked in run_once(), waiting for work
        self._pending: OrderedDict[Hashable, tuple[Callable, tuple, dict]] = OrderedDict()
        self._wakeup = threading.Event()
        self._wake_requested = False  # set by wake() on the owner thread (a signal handler), see wake()
        self._timers: list[list] = []  # [next_due, period, func]
        self.posted = 0
        self.coalesced = 0
        self.executed = 0
        self.max_pending = 0  # the longest the queue has been: stays at the number of keys, never grows
        self.yields = 0  # yield_to_owner() calls that waited until the owner took the work
        self.yield_timeouts = 0  # ... and that gave up after HAND_OVER_WAIT
        self.errors: list[str] = []

    # ---- any thread ------------------------------------------------------
    def call_later(self, func: Callable, *args: Any, key: Hashable | None = None, **kwargs: Any) -> None:
        """Run ``func(*args, **kwargs)`` later on the owner thread.

        Args:
            func: what to run.
            key: calls with the same key coalesce (newest arguments win, the
                call keeps its place in the queue); defaults to ``func``
                itself, so posting a bound method again replaces its
                pending arguments.

        Any thread may call this; it never blocks for long and never runs ``func``.
        """
        k = func if key is None else key
        with self._lock:
            self.posted += 1
            if k in self._pending:
                self.coalesced += 1
            self._pending[k] = (func, args, kwargs)
            self.max_pending = max(self.max_pending, len(self._pending))
        self._wakeup.set()

    def yield_to_owner(self, timeout: float = HAND_OVER_WAIT) -> bool:
        """Step aside until the owner has taken every call posted so far (any thread but the owner).

        Blocking here lets go of the interpreter lock, so a main thread that
        was woken by the post runs it at once instead of waiting for this
        thread's next blocking call (see the module's docstring).  It waits
        only when the owner is blocked in :meth:`run_once` and posted calls
        are still pending: an owner busy drawing, or not running the loop at
        all, costs nothing.

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
            taken = self._taken.wait_for(lambda: self._taken_upto >= target, timeout)
            if taken:
                self.yields += 1
            else:
                self.yield_timeouts += 1
            return taken

    @property
    def owner_waiting(self) -> bool:
        """Whether the owner is blocked in :meth:`run_once` now (any thread; a hint, stale at once)."""
        return self._owner_waiting

    def pending(self) -> int:
        """How many calls wait to run (any thread)."""
        with self._lock:
            return len(self._pending)

    def wake(self) -> None:
        """Make a waiting :meth:`run_once` return early (any thread, and signal handlers).

        A signal handler runs on the main thread, between two bytecodes of
        whatever that thread was doing, and that can be inside
        ``self._wakeup.wait()`` at a moment it holds the event's internal lock.
        ``Event.set()`` takes that lock, so calling it there waits for the
        thread it is running on: a deadlock (a viewer once hung on Ctrl-C this
        way).  So on the owner thread, where nothing can be waiting anyway,
        wake only sets a flag, a plain store that takes no lock;
        :meth:`run_once` checks it before it waits.  If the signal lands after
        that check, the wait simply ends at its timeout.
        """
        if threading.get_ident() == self._owner:
            self._wake_requested = True
        else:
            self._wakeup.set()

    # ---- owner thread only -------------------------------------------------
    def _check_owner(self) -> None:
        if threading.get_ident() != self._owner:
            raise WrongThreadError(
                "MainLoop: only its owner thread may run posted calls; other threads must use call_later()"
            )

    def call_every(self, period: float, func: Callable[[], Any]) -> None:
        """Run ``func()`` on the owner thread every ``period`` s (owner thread)."""
        self._check_owner()
        self._timers.append([time.monotonic() + period, period, func])

    def process_pending(self) -> int:
        """Run every call posted so far; returns how many ran (owner thread).

        The queue is swapped out under the lock and the calls run outside it,
        so posting threads never wait for a call to finish.
        """
        self._check_owner()
        with self._lock:
            batch, self._pending = self._pending, OrderedDict()
            self._taken_upto = self.posted
            self._taken.notify_all()  # a thread in yield_to_owner() may go on
        for func, args, kwargs in batch.values():
            self._run(func, args, kwargs)
        self.executed += len(batch)
        now = time.monotonic()
        for timer in self._timers:
            if now >= timer[0]:
                timer[0] = max(timer[0] + timer[1], now)
                self._run(timer[2], (), {})
        return len(batch)

    def run_once(self, timeout: float) -> int:
        """Wait up to ``timeout`` s for posted calls, then run them (owner thread)."""
        self._check_owner()
        if timeout > 0 and not self._wake_requested:
            due = min((t[0] for t in self._timers), default=None)
            if due is not None:
                timeout = max(0.0, min(timeout, due - time.monotonic()))
            self._owner_waiting = True  # a hint for yield_to_owner(); a stale read only costs a wait
            try:
                self._wakeup.wait(timeout)
            finally:  # a Ctrl-C raised in the wait must not leave posting threads waiting for nobody
                self._owner_waiting = False
        self._wake_requested = False
        self._wakeup.clear()
        return self.process_pending()

    def run_until(self, done: Callable[[], bool], timeout: float, poll: float = 0.01) -> bool:
        """Run posted calls until ``done()`` is true or ``timeout`` s pass (owner thread).

        Returns:
            ``done()`` at the end.
        """
        deadline = time.monotonic() + timeout
        while not done():
            left = deadline - time.monotonic()
            if left <= 0:
                break
            self.run_once(min(poll, left))
        return done()

    def _run(self, func: Callable, args: tuple, kwargs: dict) -> None:
        try:
            func(*args, **kwargs)
        except Exception:  # noqa: BLE001 - a posted call must not stop the loop
            text = traceback.format_exc()
            if len(self.errors) < 100:
                self.errors.append(text)
            print(f"[call_later] error in {getattr(func, '__qualname__', func)}:\n{text}", flush=True)


class LazyCaller:
    """A function that, called from any thread, runs later on a loop's owner thread.

    Calls made while one is pending coalesce into one run with the newest
    arguments (Choreonoid's ``LazyCaller``).

    Args:
        loop: the owner thread's :class:`MainLoop`.
        func: the function to run there.
    """

    def __init__(self, loop: MainLoop, func: Callable):
        self.loop = loop
        self.func = func

    def __call__(self, *args: Any, **kwargs: Any) -> None:
        self.loop.call_later(self.func, *args, key=self, **kwargs)
