"""Each learner's server in cgroups of their own: one learner's memory, processes or busy loops cannot take
the class's server down.

JupyterHub's local spawners start a learner's server as a process of this machine and set no limit
(``Spawner.mem_limit`` and ``cpu_limit`` are only passed on to the server in ``MEM_LIMIT`` and ``CPU_LIMIT``).
SystemdSpawner would enforce them, but needs systemd; DockerSpawner and KubeSpawner enforce them with
containers (``course/Containerfile``'s image).  This module's spawners are for a server without either:
before the learner's server runs its first instruction, the spawner puts it in cgroup v1 groups named
``rtt-learner-<name>`` under the cpu, memory and pids controllers, and everything it starts (kernels,
simulations, joysticks, terminals) stays there:

- **memory** (``Spawner.mem_limit``, default 2 GiB): over it, the kernel's own OOM killer stops the biggest
  process of that learner (their kernel, which Jupyter restarts) and nobody else's.  ``init_ros()`` then
  tells the learner why (:func:`tutorial.notebook.session.init_ros`, from ``memory.oom_control``);
- **processes** (:attr:`LimitedLocalProcessSpawner.pids_limit`, default 500): a fork past it fails with
  ``BlockingIOError`` in the learner's own code;
- **CPU** (``Spawner.cpu_limit``, default 1 core): a quota per 100 ms period; busy loops get at most that.

When the server stops (the learner, the teacher, the idle culler), whatever of the learner's is still in the
groups is killed and the groups are removed.  Without root or cgroup v1 (a trial), the hub logs that the
limits are not applied and starts the server anyway.  The hub's thread calls all of it.
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


class LimitedLocalProcessSpawner(LocalProcessSpawner):
    """Each learner a Unix user of this machine, in cgroups of their own; configured as
    ``c.LimitedLocalProcessSpawner`` (``pids_limit``) and ``c.Spawner`` (``mem_limit``, ``cpu_limit``)."""

    pids_limit = Integer(500, config=True, help="Processes (and threads) a learner's server may hold at once.")

    @default("mem_limit")
    def _default_mem_limit(self):
        return 2 * 1024**3

    @default("cpu_limit")
    def _default_cpu_limit(self):
        return 1.0

    def cgroup_settings(self) -> dict[str, dict[str, int]]:
        """Per controller, the files to write and their values (bytes, microseconds, a count)."""
        memory = {"memory.limit_in_bytes": int(self.mem_limit)}
        if (CGROUPS / "memory" / "memory.memsw.limit_in_bytes").exists():  # swap counted too, where it is
            memory["memory.memsw.limit_in_bytes"] = int(self.mem_limit)
        return {
            "cpu": {"cpu.cfs_period_us": PERIOD_US, "cpu.cfs_quota_us": int(self.cpu_limit * PERIOD_US)},
            "memory": memory,
            "pids": {"pids.max": int(self.pids_limit)},
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
                for name, value in settings.items():
                    (group / name).write_text(str(value))
        except OSError as exc:
            self.log.warning("learner %s: no limits on their server (%s)", self.user.name, exc)
            for group in made:
                with contextlib.suppress(OSError):
                    group.rmdir()  # empty: nothing joined it yet
            return []
        self.log.info(
            "learner %s: at most %.1f GiB, %d processes, %.2f cores",
            self.user.name,
            self.mem_limit / 1024**3,
            self.pids_limit,
            self.cpu_limit,
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
        await super().stop(now=now)
        await self.remove_cgroups()

    async def remove_cgroups(self, timeout: float = 10.0) -> None:
        """Kill what is left in the learner's groups (kernels run in sessions of their own), then remove them."""
        loop = asyncio.get_running_loop()
        for group in self.cgroups():
            deadline = loop.time() + timeout
            while group.exists() and loop.time() < deadline:
                pids = [int(p) for p in (group / "cgroup.procs").read_text().split()]
                if not pids:
                    break
                for pid in pids:
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(pid, signal.SIGKILL)
                await asyncio.sleep(0.05)  # the killed processes leave the group as the kernel reaps them
            try:
                group.rmdir()
            except FileNotFoundError:
                pass
            except OSError as exc:
                self.log.warning("learner %s: %s not removed (%s)", self.user.name, group, exc)


class LimitedSimpleLocalProcessSpawner(LimitedLocalProcessSpawner, SimpleLocalProcessSpawner):
    """A trial's learners (this machine's one user), with limits."""
