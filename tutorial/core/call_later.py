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

How soon the owner runs posted work is a matter of speed, not of
correctness: :class:`tutorial.core.hand_over.HandOverLoop` adds a way for the
posting thread to step aside for it, and the App uses that.
"""

from __future__ import annotations

import threading
import time
import traceback
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Any


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
        # The lock guards the pending calls and the counters: posting threads
        # and the owner both touch them, and posting never waits for a call to run.
        self._lock = threading.Lock()
        self._pending: OrderedDict[Hashable, tuple[Callable, tuple, dict]] = OrderedDict()
        self._wakeup = threading.Event()
        self._wake_requested = False  # set by wake() on the owner thread (a signal handler), see wake()
        self._timers: list[list] = []  # [next_due, period, func]
        self.posted = 0
        self.coalesced = 0
        self.executed = 0
        self.max_pending = 0  # the longest the queue has been: stays at the number of keys, never grows
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

    # ---- owner thread only: each method below raises WrongThreadError on any other thread ---------
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

        Raises:
            WrongThreadError: called from a thread that is not the owner.
        """
        self._check_owner()
        with self._lock:
            batch, self._pending = self._pending, OrderedDict()
            self._taken()
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
            self._wait(timeout)
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

    def _wait(self, timeout: float) -> None:
        """Block the owner until a post wakes it or ``timeout`` s pass (a subclass may note that it waits)."""
        self._wakeup.wait(timeout)

    def _taken(self) -> None:
        """The owner took every pending call (called with the lock held; a subclass may tell the posters)."""

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
