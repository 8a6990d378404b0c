"""Each learner's server in cgroups of their own: one learner's memory, processes or busy loops cannot take
the class's server down.

JupyterHub's local spawners start a learner's server as a process of this machine and set no limit
(``Spawner.mem_limit`` and ``cpu_limit`` are only passed on to the server in ``MEM_LIMIT`` and ``CPU_LIMIT``).
SystemdSpawner would enforce them, but needs systemd; DockerSpawner and KubeSpawner enforce them with
containers (``course/containers/Containerfile``'s image).  This module's spawners are for a server without
either: before the learner's server runs its first instruction, the spawner puts it in cgroup v1 groups
named ``rtt-learner-<name>`` under the cpu, cpuacct, memory, pids and freezer controllers, and everything
it starts (kernels, simulations, joysticks, terminals) stays there:

- **memory** (``Spawner.mem_limit``, default 2 GiB): over it, the kernel's own OOM killer stops the biggest
  process of that learner (most often their kernel, which Jupyter restarts) and nobody else's.
  ``init_ros()`` then tells the learner why (:func:`tutorial.notebook.session.memory_limit_note`);
- **processes** (:attr:`LimitedLocalProcessSpawner.pids_limit`, default 500; threads count too): a fork
  past it fails with ``BlockingIOError`` in the learner's own code;
- **CPU**: an equal share per learner (``cpu.shares``): at full tilt a learner gets at most their share
  when others need theirs, and everything when nobody does.  ``Spawner.cpu_limit`` (cores; none by
  default) adds a hard cap, a quota per 100 ms period.

When the server stops (the learner, the teacher, the idle culler), whatever of the learner's is still in the
groups is killed and the groups are removed.  Without root or cgroup v1 (a trial; a machine with cgroup v2
only, as Debian 12 and Ubuntu 22.04 boot by default), the hub logs an error, NO LIMITS, and starts the
server anyway.  The hub's thread calls all of it.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import signal
from pathlib import Path

from jupyterhub.spawner import LocalProcessSpawner, SimpleLocalProcessSpawner
from traitlets import Integer, default

CGROUPS = Path("/sys/fs/cgroup")
PERIOD_US = 100_000  # the CPU quota's period: 100 ms
SHARES = 1024  # each learner's weight against the others (and against the hub, the machine's own root group)


class LimitedLocalProcessSpawner(LocalProcessSpawner):
    """Each learner a Unix user of this machine, in cgroups of their own; configured as
    ``c.LimitedLocalProcessSpawner`` (``pids_limit``) and ``c.Spawner`` (``mem_limit``, ``cpu_limit``)."""

    pids_limit = Integer(500, config=True, help="Processes (and threads) a learner's server may hold at once.")

    @default("mem_limit")
    def _default_mem_limit(self):
        return 2 * 1024**3

    def cgroup_settings(self) -> dict[str, dict[str, int]]:
        """Per controller, the files to write and their values (bytes, microseconds, a count)."""
        quota = int(self.cpu_limit * PERIOD_US) if self.cpu_limit else -1  # -1: no cap
        memory = {"memory.limit_in_bytes": int(self.mem_limit)}
        if (CGROUPS / "memory" / "memory.memsw.limit_in_bytes").exists():  # swap counted too, where it is
            memory["memory.memsw.limit_in_bytes"] = int(self.mem_limit)
        else:
            memory["memory.swappiness"] = 0  # no swap accounting: the group must not swap instead of stopping
        return {
            "cpu": {"cpu.shares": SHARES, "cpu.cfs_period_us": PERIOD_US, "cpu.cfs_quota_us": quota},
            "cpuacct": {},  # no limit: what the learner's processes used, for the teacher and the benchmarks
            "memory": memory,
            "pids": {"pids.max": int(self.pids_limit)},
            "freezer": {},  # held still while what is left is stopped (remove_cgroups): no pid is reused meanwhile
        }

    def cgroups(self) -> list[Path]:
        """This learner's groups, one per controller (``/sys/fs/cgroup/<controller>/rtt-learner-<name>``)."""
        return [CGROUPS / controller / f"rtt-learner-{self.user.name}" for controller in self.cgroup_settings()]

    def make_cgroups(self) -> list[Path]:
        """The groups made and set; [] (and a warning in the hub's log) where they cannot be (not root, no v1).

        A group left by a server that died with the hub keeps its processes until :meth:`stop` (the learner's
        old kernels count against the new server's limits until then)."""
        made = []
        try:
            for settings, group in zip(self.cgroup_settings().values(), self.cgroups()):
                group.mkdir(exist_ok=True)
                made.append(group)
                if "memory.memsw.limit_in_bytes" in settings:  # a left group's swap limit may be below the new one
                    (group / "memory.memsw.limit_in_bytes").write_text("-1")
                for name, value in settings.items():
                    (group / name).write_text(str(value))
        except OSError as exc:
            # Not root, no cgroup v1 (a cgroup v2 machine: Debian 12, Ubuntu 22.04 and later), a name too long
            self.log.error("learner %s: NO LIMITS on their server: %s (course/limits.py needs root and cgroup v1)",
                           self.user.name, exc)  # fmt: skip
            for group in made:
                with contextlib.suppress(OSError):
                    group.rmdir()  # empty: nothing joined it yet
            return []
        self.log.info(
            "learner %s: at most %.1f GiB, %d processes, %s",
            self.user.name,
            self.mem_limit / 1024**3,
            self.pids_limit,
            f"{self.cpu_limit:.2f} cores" if self.cpu_limit else "an equal share of the CPU",
        )
        return made

    def make_preexec_fn(self, name):
        join = [str(group / "cgroup.procs") for group in self.make_cgroups()]
        then = super().make_preexec_fn(name)

        def preexec():
            # In the new process, before it runs the server (and before it gives up root): every process it
            # starts from now on is in the groups too.
            for procs in join:
                with open(procs, "w") as f:
                    f.write(str(os.getpid()))
            then()

        return preexec

    async def stop(self, now=False):
        try:
            await super().stop(now=now)
        finally:
            await self.remove_cgroups()

    async def remove_cgroups(self, timeout: float = 10.0) -> None:
        """Kill what is left in the learner's groups (kernels run in sessions of their own), then remove them.

        The group is frozen first: a frozen process cannot exit, so no pid read here can be another
        process's by the time it is killed.  The kill lands once the group is thawed."""
        loop = asyncio.get_running_loop()
        groups = self.cgroups()
        freezer = next(g for g in groups if g.parent.name == "freezer")
        try:
            if freezer.exists():
                await self._set_frozen(freezer, True, loop.time() + timeout)
                for pid in _pids(freezer):
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(pid, signal.SIGKILL)
                await self._set_frozen(freezer, False, loop.time() + timeout)
        except OSError as exc:
            self.log.warning("learner %s: what was left of their server not stopped (%s)", self.user.name, exc)
        for group in groups:
            deadline = loop.time() + timeout
            while _pids(group) and loop.time() < deadline:
                await asyncio.sleep(0.05)  # the killed processes leave the group as the kernel reaps them
            try:
                group.rmdir()
            except FileNotFoundError:
                pass
            except OSError as exc:
                self.log.warning("learner %s: %s not removed (%s)", self.user.name, group, exc)

    @staticmethod
    async def _set_frozen(freezer: Path, frozen: bool, deadline: float) -> None:
        want = "FROZEN" if frozen else "THAWED"
        (freezer / "freezer.state").write_text(want)
        loop = asyncio.get_running_loop()
        while (freezer / "freezer.state").read_text().strip() != want and loop.time() < deadline:
            await asyncio.sleep(0.01)  # FREEZING until every task has stopped


def _pids(group: Path) -> list[int]:
    """The processes in ``group`` ([] once it is gone)."""
    try:
        return [int(p) for p in (group / "cgroup.procs").read_text().split()]
    except FileNotFoundError:
        return []


class LimitedSimpleLocalProcessSpawner(LimitedLocalProcessSpawner, SimpleLocalProcessSpawner):
    """A trial's learners (this machine's one user), with limits."""
