"""Each learner's own ROS 2 domain on a shared server: which one, kept across restarts, never shared.

On one host, every ROS 2 node of every learner finds every other one in the
same ``ROS_DOMAIN_ID``: with the defaults, a class is one ROS graph.  The
hub gives each learner's server a domain of their own (its environment, so
their notebooks, terminals and ``rtt-*`` programs all inherit it).  A domain
is a convention, not a wall: a learner can set another's number on purpose.
Where that matters, give each learner a network namespace of their own
(containers, pods): then domains may repeat (:attr:`DomainBook.per_learner_network`).

Which domains exist: Fast DDS puts domain ``d`` on UDP ports from
``7400 + 250 * d``, and the ports must stay below Linux's ephemeral range
(32768): domains 0 to 101, and 215 to 232 above it.  Domain 0 is everyone's
default (a program started without the hub's environment lands there), so
no learner gets it: 119 learners per server.  A class larger than that
spreads over several servers, each with its own hub and book of domains.

The book is a JSON file, ``{learner: domain}``, written whole and atomically
(a new file renamed over the old).  One hub process uses it, on its event
loop's thread, so it needs no lock.
"""

from __future__ import annotations

import json
import os
import re
import tempfile
from pathlib import Path

BOOK_NAME = "ros_domains.json"  # the hub's book of domains, in its state folder


def hub_state() -> Path:
    """The hub's state folder: ``RTT_HUB_STATE``, or ``course/.hub`` (database, book of domains, a trial's homes)."""
    return Path(os.environ.get("RTT_HUB_STATE", Path(__file__).resolve().parent / ".hub")).resolve()


def running_hub(state: Path) -> int | None:
    """The process ID of a JupyterHub that runs with the state folder ``state`` (its ``jupyterhub.pid``), or None.

    A second hub on the same state folder would stop the first one's proxy (JupyterHub stops the process a
    proxy's pid file names) and take its database: ``course/jupyterhub_config.py`` refuses to start then."""
    try:
        pid = int((state / "jupyterhub.pid").read_text().strip())
        command = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except (OSError, ValueError):  # no pid file, not a number, or no such process
        return None
    hub = any(os.path.basename(part) == b"jupyterhub" for part in command)  # not jupyterhub-singleuser, say
    return pid if pid != os.getpid() and hub else None


# Fast DDS's port arithmetic on Linux (see the module's text); 0 is the default everyone shares.
LEARNER_DOMAINS = tuple(range(1, 102)) + tuple(range(215, 233))
NAME = re.compile(r"^[a-z0-9][a-z0-9._@-]{0,63}$")  # JupyterHub's usual (normalized, lower-case) names


class DomainError(RuntimeError):
    """A learner cannot be given a domain: a name the book cannot hold, or none left."""


class DomainBook:
    """The learners' domains, kept in ``path``.

    Args:
        path: the JSON file (made when the first learner comes).
        domains: the domains to give out, in order (None: :data:`LEARNER_DOMAINS`).
        per_learner_network: each learner's server runs in a network namespace
            of its own (containers, pods): every learner may then get the same
            domain, the first of ``domains``, and nothing is written.

    Used by one thread (the hub's event loop).
    """

    def __init__(self, path, domains=LEARNER_DOMAINS, per_learner_network: bool = False):
        self.path = Path(path)
        self.domains = tuple(LEARNER_DOMAINS if domains is None else domains)
        self.per_learner_network = per_learner_network

    def read(self) -> dict[str, int]:
        """``{learner: domain}`` as kept (empty before the first learner).

        Raises:
            DomainError: the file is not a book of domains (it is never overwritten then).
        """
        try:
            book = json.loads(self.path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return {}
        except (OSError, ValueError) as exc:
            raise DomainError(f"cannot read the book of ROS domains {self.path}: {exc}") from None
        if not isinstance(book, dict) or not all(isinstance(d, int) for d in book.values()):
            raise DomainError(f"{self.path} is not a book of ROS domains ({{learner: domain}})")
        return book

    def domain_for(self, learner: str) -> int:
        """The learner's domain: the one they had, or the first free one, kept from now on.

        Raises:
            DomainError: ``learner`` is not a name the book holds, or every domain
                is taken (the message names the limit and what to do).
        """
        if not NAME.match(learner):
            raise DomainError(
                f"learner name {learner!r} cannot be given a ROS domain: names are 1 to 64 lower-case "
                "letters, digits and . _ @ - (ask the teacher to rename the account)"
            )
        if self.per_learner_network:
            return self.domains[0]
        book = self.read()
        if learner in book:
            return book[learner]
        taken = set(book.values())
        free = [d for d in self.domains if d not in taken]
        if not free:
            raise DomainError(
                f"no ROS domain left for {learner}: this server gives each learner one of its "
                f"{len(self.domains)} domains and all are taken. Spread the class over several servers "
                "(each with its own hub), or give each learner a network namespace (containers) and set "
                "per_learner_network."
            )
        book[learner] = free[0]
        self._write(book)
        return free[0]

    def _write(self, book: dict[str, int]) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=self.path.parent, prefix=self.path.name, suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(book, f, indent=1, sort_keys=True)
        os.chmod(tmp, 0o644)  # mkstemp makes it the hub's alone: the teacher's make grade reads it too
        os.replace(tmp, self.path)  # readers see the old book or the new, never half of one
