"""Notebook 08's two hosts: the robot and the operator as network namespaces, and the programs on them.

:class:`TwoHosts` makes them (:class:`tutorial.tools.network.hosts.Network`) when this
computer allows it (root, ``ip``, ``nft``, ``tc``), starts the tutorial's
programs on either host as separate processes, reads what they print, and
removes everything in :meth:`TwoHosts.close` (also what a notebook's earlier
kernel left).  A kernel keeps one pair: making a new :class:`TwoHosts` (the
notebook's first cell, run again) closes the one before, and the hosts are
removed when the kernel exits (shut down or restarted before the last cell).
Without root, :attr:`TwoHosts.problem` says why, and every
method that would need the hosts returns None, so each cell can say so
instead of failing.  Main thread (the notebook's) only.
"""

from __future__ import annotations

import atexit

from tutorial.tools.network.host_program import HostProgram, python
from tutorial.tools.network.hosts import Host, Network, why_unavailable

_current: TwoHosts | None = None  # this kernel's pair of hosts (main thread only)


class TwoHosts:
    """``robot`` (198.18.25.1) and ``operator`` (198.18.25.2), or the reason they cannot be made.

    Making one closes the kernel's previous :class:`TwoHosts`, if any.
    """

    def __init__(self):
        global _current
        if _current is not None:
            _current.close()
        _current = self
        self.problem = why_unavailable()
        self.net: Network | None = None
        self.programs: list[HostProgram] = []
        self._open()

    def _open(self) -> None:
        if self.problem is None:
            self.net = Network(("robot", "operator")).open()
            atexit.register(self.close)  # the kernel exits before the notebook's last cell: nothing is left

    @property
    def ok(self) -> bool:
        return self.net is not None

    def __getitem__(self, name: str) -> Host:
        return self.net[name]

    def describe(self) -> str:
        if not self.ok:
            return f"no hosts here: {self.problem}"
        return "\n".join(
            f"{h.name:<9} {h.address:<13} namespace {h.name}, its own /dev/shm" for h in self.net.hosts.values()
        )

    def start(self, host: str, argv: list[str], **env: str) -> HostProgram:
        program = HostProgram(self[host], argv, env)
        self.programs.append(program)
        return program

    def simulation(
        self, host: str = "robot", project: str = "project/reference/step2.yaml", *args: str, **env: str
    ) -> HostProgram:
        return self.start(host, python("tutorial.tools.rtt_run", project, "--headless", "--json", *args), **env)

    def monitor(self, host: str = "operator", name: str = "rtt_viewer", **env: str) -> HostProgram:
        project = "project/reference/step3.yaml"
        argv = python("tutorial.tools.rtt_run", project, "--headless", "--json", "--ros-args", "-r", f"__node:={name}")
        return self.start(host, argv, **env)

    def image_viewer(self, host: str = "operator", transport: str = "raw") -> HostProgram:
        """``rtt-image`` on ``host``; its newest picture in the host's ``/dev/shm`` (here: ``self[host].shm_dir``)."""
        out = f"/dev/shm/camera_{transport}.png"  # a path on the host, whose /dev/shm is its own folder
        return self.start(
            host, python("tutorial.tools.rtt_image", "--transport", transport, "--no-window", "--output", out)
        )

    def stop_all(self) -> None:
        """Stop every program started so far; the faults are cleared."""
        for program in self.programs:
            program.stop()
        self.programs.clear()
        if self.ok:
            for host in self.net.hosts.values():
                host.clear_faults()

    def renew(self) -> None:
        """Stop every program and make both hosts afresh (as if both computers had restarted)."""
        self.close()
        self._open()

    def close(self) -> None:
        """Stop the programs and remove the hosts (safe to call twice, and without hosts)."""
        self.stop_all()
        if self.net is not None:
            self.net.close()
            self.net = None
            atexit.unregister(self.close)


def publishers(monitor: HostProgram) -> int:
    """The newest count of joint-state publishers the monitor reported (0 before any)."""
    seen = monitor.records("publishers")
    return seen[-1]["count"] if seen else 0


def states_applied(monitor: HostProgram) -> int:
    statuses = monitor.records("status")
    return statuses[-1]["applied"] if statuses else 0


def image_rates(viewer: HostProgram) -> list[float]:
    """The pictures per second ``rtt-image`` reported, once a second."""
    rates = []
    for line in viewer.lines():
        if " img/s, " in line:
            try:
                rates.append(float(line.split("] ", 1)[1].split(" img/s", 1)[0]))
            except (IndexError, ValueError):
                continue
    return rates
