"""When a view draws a frame: once a burst of changes is complete or has settled, at most FRAME_RATE a second.

:class:`FramePacer` is the App's frame clock (owner thread only).  The App
tells it what changed (:meth:`FramePacer.note`), asks when the next frame
is due (:meth:`FramePacer.next_frame_due`) and tells it when a frame was
drawn (:meth:`FramePacer.drawn`).  It knows nothing of meshcat or ROS: what
changes is counted by the App (bodies' kinematic-state changes, overlay
arrows' versions).
"""

from __future__ import annotations

import math
import os


def frame_rate(text: str | None) -> float:
    """The views' frame rate, Hz, from the text of ``RTT_FRAME_RATE`` (None or blank: 60).

    A class's server sets it lower (``course/jupyterhub_config.py``): every
    frame of a live view in a notebook costs the server CPU, in the kernel,
    in the learner's Jupyter server and in the hub's proxy.

    Raises:
        ValueError: not a number of frames per second from 1 to 240.
    """
    if text is None or not text.strip():
        return 60.0
    try:
        rate = float(text)
    except ValueError:
        rate = math.nan
    if not 1.0 <= rate <= 240.0:  # a NaN fails too
        raise ValueError(f"RTT_FRAME_RATE must be frames per second from 1 to 240, got {text!r}")
    return rate


FRAME_RATE = frame_rate(os.environ.get("RTT_FRAME_RATE"))  # Hz, the most often the scene is redrawn
SETTLE = 0.004  # s: a frame waits this long after a change for more of the same burst (see next_frame_due)
SETTLE_MAX = 0.008  # s: ... and at most this long after the first change it shows


class FramePacer:
    """The frame clock of one view (owner thread only).

    Times are ``time.monotonic()`` values, s.  Burst members are
    ``((kind, name), change count)`` pairs, e.g. ``(("body", "Tank"), 12)``.
    """

    def __init__(self):
        self.last_frame = 0.0  # time.monotonic() of the last frame, on the frame clock
        self._changes_seen = 0  # the change count when note() last looked
        self._first_change = None  # time of the first change not yet drawn, or None
        self._last_change = None  # ... and of the newest
        self._drawn_changes: dict[tuple[str, str], int] = {}  # each burst member's count at the last frame

    def note(self, now: float, changes: int) -> None:
        """The view's change count at ``now``: a new count starts or extends the burst not yet drawn."""
        if changes != self._changes_seen:
            self._changes_seen = changes
            if self._first_change is None:
                self._first_change = now
            self._last_change = now

    def next_frame_due(self, simulating: bool, members) -> float:
        """The ``time.monotonic()`` at which the next frame is due; ``inf``: nothing new to show.

        While a project simulates (``simulating``), every frame has something
        new: frames come ``1/FRAME_RATE`` s apart.  Otherwise a frame is due
        when the view has changed.  The states of one simulation step arrive
        as a burst of messages, one per robot, and are drawn together: at once
        when every member that has ever changed has changed again since the
        last frame (:meth:`burst_complete`, which says what it cannot know);
        else ``SETTLE`` s after the newest change, for the rest of the burst,
        and at most ``SETTLE_MAX`` s after the first change, so a steady stream
        of changes is still drawn.  Never before the frame clock allows
        (``1/FRAME_RATE`` s per frame on average, see :meth:`drawn`).  A frame
        drawn at a fixed 60 Hz, whatever came, showed a state that arrived
        just after a frame a whole frame late (``benchmarks/RESULTS.md``,
        *What closed the gaps*).
        """
        cap = self.last_frame + 1.0 / FRAME_RATE
        if simulating:
            return cap
        if self._first_change is None:
            return math.inf
        if self.burst_complete(members):
            return cap
        return max(cap, min(self._last_change + SETTLE, self._first_change + SETTLE_MAX))

    def burst_complete(self, members) -> bool:
        """True when every member that has ever changed has changed since the last frame.

        The members are the bodies (their kinematic-state changes) and the
        overlay arrows (their versions) that have changed at least once.
        What it cannot know:

        - a member whose updates stopped (its publisher ended) keeps it False:
          frames then wait ``SETTLE`` s after the newest change;
        - members updated at different rates (a 20 Hz IMU's arrows beside
          50 Hz joint states) complete it only when their updates coincide;
        - states faster than ``FRAME_RATE``: a burst completed early waits for
          the frame clock, and the frame may show part of the next burst too;
        - the first state of a new robot alone completes it, once.
        """
        moved_since = [count > self._drawn_changes.get(key, 0) for key, count in members if count]
        return bool(moved_since) and all(moved_since)

    def drawn(self, now: float, members) -> None:
        """A frame is drawn at ``now`` showing ``members``' counts: the burst is over, the clock advances.

        The frame clock advances one period per frame while a frame comes less
        than a period after it was allowed (a frame a little late does not
        push the next one back: 60 frames/s, not 59), else it restarts from
        now.  So frames come at most FRAME_RATE a second on average, and one
        may follow a late one sooner.
        """
        cap = self.last_frame + 1.0 / FRAME_RATE
        self.last_frame = cap if cap <= now < cap + 1.0 / FRAME_RATE else now
        self._first_change = self._last_change = None
        self._drawn_changes = dict(members)
