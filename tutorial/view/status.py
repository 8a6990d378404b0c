"""Status of a joint-state viewer, for people monitoring a robot.

Once a second the viewer reports how many messages arrived, how old the
newest displayed state is, how many joints matched and what was rejected.
Four times a second it checks for silence: when no state has arrived for
longer than :data:`STALE_AFTER` it says so (``stale``, at most
``STALE_AFTER + STALE_CHECK_PERIOD`` s after the last state) once, and
once more when data resumes (``recovered``): a frozen view that looks
alive is the most dangerous thing a monitor can show.

Threads: :meth:`ViewerStatus.received` is called by the spin thread; the
rest by the main thread.  The counters the spin thread writes are guarded by
a lock.
"""

from __future__ import annotations

import threading
import time
from collections import Counter
from collections.abc import Callable, Sequence

STALE_AFTER = 1.0  # s without a state before the view is called stale
STALE_CHECK_PERIOD = 0.25  # s between checks for silence
NAMES_SHOWN = 3  # rejected joint names the status line gives per reason, the newest
NAME_CHARS = 40  # of each: a name comes from the network, any length


def _shown_name(name: str) -> str:
    """A received joint name as a status line shows it: printable, at most :data:`NAME_CHARS` characters."""
    text = name if isinstance(name, str) and name and name.isprintable() else repr(name)
    return text if len(text) <= NAME_CHARS else text[: NAME_CHARS - 3] + "..."


class ViewerStatus:
    """Counters and the stale/recovered state machine of one viewer.

    Args:
        joint_count: how many numbered joints the viewed body has.
        clock: monotonic time source in s (tests and notebooks pass a simulated one).
    """

    def __init__(self, joint_count: int, clock: Callable[[], float] = time.monotonic):
        self.joint_count = joint_count
        self.clock = clock
        self._lock = threading.Lock()
        self._received = 0  # spin thread writes, main thread reads: guarded by _lock
        self._last_arrival: float | None = None  # ditto
        self.applied = 0  # main thread only from here on
        self.applied_arrival: float | None = None
        self.matched = 0
        self.rejections: Counter = Counter()
        self.rejected_names: dict[str, list[str]] = {}  # reason -> the names rejected for it, newest first
        self.last_positions: dict[str, float] = {}
        self.stale = False
        self.stamps_back = 0  # times a state's stamp was older than the one before (a restarted publisher)
        self.last_stamp: float | None = None  # s, the newest live state's
        self._received_at_last_report = 0
        self._last_report = clock()

    def received(self) -> float:
        """Count one arrival (spin thread); returns its arrival time."""
        now = self.clock()
        with self._lock:
            self._received += 1
            self._last_arrival = now
        return now

    def stamp(self, stamp: float) -> float | None:
        """Note a live state's stamp, s (main thread); the stamp before it if this one is older, else None.

        An older stamp is a publisher that restarted (a new run from t = 0):
        counted in ``stamps_back`` and in the status line; the new run is
        what the view shows from then on.
        """
        before, self.last_stamp = self.last_stamp, stamp
        if before is not None and stamp < before:
            self.stamps_back += 1
            return before
        return None

    def applied_message(
        self, arrival: float, matched: int, rejected: Sequence[tuple[int, str | None, str]], positions: dict[str, float]
    ) -> None:
        """Record one message applied to the model (main thread).

        ``rejected``: ``MatchReport.rejected``, (entry index, name or None,
        reason) per rejected entry; the status line names the newest
        :data:`NAMES_SHOWN` names rejected for each reason.
        """
        self.applied += 1
        self.applied_arrival = arrival
        self.matched = matched
        for _, name, reason in rejected:
            self.rejections[reason] += 1
            if name is not None:
                names = self.rejected_names.setdefault(reason, [])
                shown = _shown_name(name)
                if shown in names:
                    names.remove(shown)
                names.insert(0, shown)
                del names[NAMES_SHOWN:]
        self.last_positions.update(positions)

    def late_state_shown(self, arrival: float | None, matched: int, positions: dict[str, float]) -> None:
        """A late joiner's state (kept by a transient-local publisher from before the viewer started) is shown.

        The status line then gives its age and the joints it matched, as
        for a live state; the count of live states applied, the rate and
        the stale watch are left to live states (main thread).
        """
        self.applied_arrival = arrival
        self.matched = matched
        self.last_positions.update(positions)

    def check_stale(self) -> list[dict]:
        """A ``stale`` or ``recovered`` record when the view changed between live and stale, else none (main thread)."""
        with self._lock:
            last_arrival = self._last_arrival
        if last_arrival is None:
            return []  # nothing ever came: the status line says "no state yet"
        silent_for = self.clock() - last_arrival
        is_stale = silent_for > STALE_AFTER
        records = []
        if is_stale and not self.stale:
            records.append({"event": "stale", "silent_s": round(silent_for, 3)})
        elif not is_stale and self.stale:
            records.append({"event": "recovered"})
        self.stale = is_stale
        return records

    def report(self) -> list[dict]:
        """Records for this second: any ``stale``/``recovered`` change, then a ``status`` record (main thread)."""
        records = self.check_stale()
        now = self.clock()
        with self._lock:
            received, last_arrival = self._received, self._last_arrival
        period = now - self._last_report
        rate = (received - self._received_at_last_report) / period if period > 0 else 0.0
        self._last_report, self._received_at_last_report = now, received
        records.append(
            {
                "event": "status",
                "rate_hz": round(rate, 1),
                "received": received,
                "applied": self.applied,
                "age_ms": None if self.applied_arrival is None else round((now - self.applied_arrival) * 1000.0, 1),
                "matched": self.matched,
                "joints": self.joint_count,
                "rejected": dict(sorted(self.rejections.items())),
                "rejected_names": {k: list(v) for k, v in sorted(self.rejected_names.items())},
                "stale": last_arrival is None or self.stale,
                "stamps_back": self.stamps_back,
            }
        )
        return records

    def received_count(self) -> int:
        with self._lock:
            return self._received


def format_status(record: dict, node: str = "") -> str:
    """A status record as one line of text."""
    tag = f"[{node}] " if node else ""
    event = record["event"]
    if event == "stale":
        return f"{tag}WARNING: no joint state for {record['silent_s']:.1f} s: the view is stale"
    if event == "first_state":
        return f"{tag}first joint state on {record['topic']}: {record['matched']}/{record['joints']} joints matched"
    if event == "publishers":
        count = record["count"]
        return f"{tag}{record['topic']}: matched with {count} publisher{'' if count == 1 else 's'}"
    if event == "recovered":
        return f"{tag}joint state is arriving again: the view is live"
    age = "no state yet" if record["age_ms"] is None else f"newest state {record['age_ms']:.0f} ms old"
    names = record.get("rejected_names", {})
    rejected = (
        ", ".join(
            f"{k} {v}" + (f" ({', '.join(names[k])})" if names.get(k) else "") for k, v in record["rejected"].items()
        )
        or "none"
    )
    stale = " [STALE]" if record["stale"] and record["received"] else ""
    back = record.get("stamps_back", 0)
    went_back = f", stamps went back {back}x (a publisher restarted)" if back else ""
    return (
        f"{tag}{record['rate_hz']:.1f} msg/s, {age}, {record['matched']}/{record['joints']} joints matched, "
        f"rejected: {rejected}{went_back}{stale}"
    )
