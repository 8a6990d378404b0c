"""A learner whose server the idle culler stopped is told so, in their next server's first ``init_ros()``.

The culler (``jupyterhub-idle-culler``, a service of the hub: ``course/jupyterhub_config.py``) stops a server
nobody has used for the class's timeout, with every simulation, joystick and view it ran.  Without a word, a
learner who comes back finds their runs gone and their cells' results empty, and cannot tell why.

- After any stop (:meth:`IdleStops.after_stop`, the spawner's ``post_stop_hook``), a server whose last use
  was at least the timeout old when it was asked to stop is written down in the hub's state folder: the time
  of the stop and how long it was idle.  The culler stops exactly those; a server a teacher stops idle is
  told as one too.  The hub sets a server's last use to "now" before that hook runs, so the spawner class
  keeps it as it was (:func:`remembering_last_use`).
- Before that learner's next server starts (:meth:`IdleStops.before_spawn`, called by the ``pre_spawn_hook``),
  the note goes into its environment (``RTT_IDLE_STOP``: ``ISO-TIME IDLE_S TIMEOUT_S``) and out of the file.
  The learner's kernel says it once (:func:`tutorial.notebook.session.idle_stop_note`).

Nothing is written in the learner's home by the hub (root there could be led by a planted link).  The hub's
thread calls all of it.
"""

from __future__ import annotations

import json
import os
from datetime import UTC, datetime
from pathlib import Path

VARIABLE = "RTT_IDLE_STOP"


def remembering_last_use(spawner_class: type) -> type:
    """``spawner_class``, keeping its server's last use as it was when the hub asked it to stop
    (``last_use_before_stop``: naive UTC, as the hub keeps times; None when unknown)."""

    class Spawner(spawner_class):
        last_use_before_stop = None

        async def stop(self, now=False):
            self.last_use_before_stop = self.orm_spawner.last_activity if self.orm_spawner else None
            return await super().stop(now=now)

    Spawner.__name__ = Spawner.__qualname__ = spawner_class.__name__
    return Spawner


class IdleStops:
    """The learners whose servers were stopped idle and are not yet told, in ``path`` (JSON)."""

    def __init__(self, path: Path, timeout_s: int):
        self.path = path
        self.timeout_s = timeout_s

    def after_stop(self, spawner) -> None:
        """Write the stop down if the server had been idle for the timeout (``post_stop_hook``)."""
        last = getattr(spawner, "last_use_before_stop", None)  # None: stopped by itself, or never started
        if last is None:
            return
        now = datetime.now(UTC)
        idle_s = (now.replace(tzinfo=None) - last).total_seconds()
        if idle_s < self.timeout_s:
            return
        stops = self._read()
        stops[spawner.user.name] = {"stopped": now.strftime("%Y-%m-%dT%H:%M:%SZ"), "idle_s": int(idle_s)}
        self._write(stops)
        spawner.log.info("learner %s: server stopped after %d s without use", spawner.user.name, idle_s)

    def before_spawn(self, spawner) -> None:
        """Put a stop not yet told into the server's environment (from the ``pre_spawn_hook``)."""
        stops = self._read()
        stop = stops.pop(spawner.user.name, None)
        if stop is None:
            return
        spawner.environment[VARIABLE] = f"{stop['stopped']} {stop['idle_s']} {self.timeout_s}"
        self._write(stops)

    def _read(self) -> dict:
        try:
            return json.loads(self.path.read_text())
        except (OSError, ValueError):
            return {}

    def _write(self, stops: dict) -> None:
        partial = self.path.with_suffix(".partial")
        partial.write_text(json.dumps(stops))
        os.replace(partial, self.path)  # whole or not at all: a hub stopped mid-write loses no other note
