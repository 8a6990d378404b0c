"""Test hosts: Linux network namespaces joined by a switch, with faults on their links.

A :class:`Network` makes one namespace per host and one for a switch (a
Linux bridge), and joins each host to the switch with a veth pair::

    robot (198.18.25.1) --rtt0== veth ==--+
                                          switch (bridge, no address)
    operator (198.18.25.2) --rtt0== veth =+

Nothing can leave: a namespace starts with no interface but its own
loopback, and the only links made are these veth pairs, whose ends are all
inside the network's own namespaces; there is no route out and no default
route.  The addresses are from 198.18.0.0/15, which RFC 2544 sets aside for
benchmarking network devices (not routed on the internet, not a private LAN
range that a real network here could use), so they cannot be mistaken for a
real machine.

**Each host is a host.**  On one machine two processes also share
``/dev/shm``, and Fast DDS's shared-memory transport would carry their
traffic past the link (and past its faults).  So each host gets a
``/dev/shm`` of its own: every program run with :meth:`Host.command` bind-
mounts the host's directory over ``/dev/shm`` in its own mount namespace
(``ip netns exec`` makes one for it).  Programs on the same host share that
directory, as on a real machine; programs on two hosts cannot see each
other's segments.  (Fast DDS 2.14 also tells hosts apart by their IP
addresses, which differ here, and so does not offer shared memory across
them; the network tier's partition test shows that nothing gets through.)

**Faults** are nftables rules and a ``tc`` queue on one host's link, both
directions: :meth:`Host.set_loss` (``numgen random mod 100 < N drop``),
:meth:`Host.partition` and :meth:`Host.heal` (drop everything),
:meth:`Host.block_multicast`, :meth:`Host.limit_rate` (a token bucket,
``tc qdisc ... tbf``, on the host's side for what it sends and on the
switch's side for what it receives).  They act on the host's ``rtt0`` only:
programs on the same host still talk over its loopback.

Names start with :data:`PREFIX` and carry the creating process's id, so a
run killed before it cleaned up is recognised and cleaned by the next one
(:func:`remove_stale`).  Everything here needs root; :func:`why_unavailable`
says what is missing where it cannot work.  One thread at a time per
:class:`Network` (the test or the notebook that made it).

Why one module of over 400 lines: one job, the test hosts' life (make,
fault, remove, and remove what a killed run left), in two classes that
share the namespaces' names and the commands that make and undo them.
"""

from __future__ import annotations

import contextlib
import ipaddress
import itertools
import os
import shutil
import signal
import subprocess
import time
from collections.abc import Mapping, Sequence

PREFIX = "rttnet-"  # every namespace, and every host's /dev/shm directory, begins with it
SUBNET = ipaddress.ip_network("198.18.25.0/24")  # RFC 2544 benchmarking range: no real machine has it
LINK = "rtt0"  # each host's interface to the switch
SHM_ROOT = "/dev/shm"  # where each host's own /dev/shm directory is made (RAM, like /dev/shm itself)
TABLE = "rttnet"  # the nftables table (family inet) in each host's namespace
COMMAND_TIMEOUT = 20.0  # s for one ip/nft/tc command
STOP_GRACE = 5.0  # s between SIGINT and SIGKILL for a program still running when the network closes

HOSTS_VARIABLE = "RTT_NETWORK_HOSTS"  # "off": behave as where no hosts can be made

_counter = itertools.count()


class NetworkError(RuntimeError):
    """A command that builds, changes or removes the network failed; the text has its output."""


def run(argv: Sequence[str], stdin: str | None = None) -> str:
    """Run one ``ip``/``nft``/``tc`` command; its standard output.

    Raises:
        NetworkError: it exited non-zero or did not finish in :data:`COMMAND_TIMEOUT` s.
    """
    try:
        done = subprocess.run(
            list(argv), input=stdin, capture_output=True, text=True, timeout=COMMAND_TIMEOUT, check=False
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise NetworkError(f"{' '.join(argv)}: {exc}") from None
    if done.returncode != 0:
        raise NetworkError(f"{' '.join(argv)} exited {done.returncode}: {done.stderr.strip() or done.stdout.strip()}")
    return done.stdout


def why_unavailable() -> str | None:
    """Why hosts cannot be made here, or None when they can.

    Checks that this process is root, that ``ip``, ``nft`` and ``tc`` exist,
    and that a namespace can really be made (a container may forbid it).
    ``RTT_NETWORK_HOSTS=off`` says no on purpose: what a computer without
    root shows (notebook 08 and the network tier skip, saying so).
    Any thread may call it; it makes and removes one namespace.
    """
    if os.environ.get(HOSTS_VARIABLE, "").lower() == "off":
        return f"{HOSTS_VARIABLE}=off"
    if os.geteuid() != 0:
        return "making network namespaces needs root (this process is not)"
    for tool, package in (("ip", "iproute2"), ("nft", "nftables"), ("tc", "iproute2")):
        if shutil.which(tool) is None:
            return f"`{tool}` is missing (Debian package {package})"
    probe = f"{PREFIX}{os.getpid()}-probe"
    try:
        run(["ip", "netns", "add", probe])
    except NetworkError as exc:
        return f"cannot make a network namespace here: {exc}"
    with contextlib.suppress(NetworkError):
        run(["ip", "netns", "del", probe])
    return None


def namespaces() -> list[str]:
    """The names of the network namespaces that exist (``ip netns list``)."""
    return [line.split()[0] for line in run(["ip", "netns", "list"]).splitlines() if line.strip()]


def _owner(name: str) -> int | None:
    """The id of the process that made ``rttnet-<pid>-...``, or None when the name is not ours."""
    if not name.startswith(PREFIX):
        return None
    pid = name[len(PREFIX) :].split("-", 1)[0]
    return int(pid) if pid.isdigit() else None


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists and has not ended (a zombie, ended but not yet reaped, has)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            state = f.read().rpartition(")")[2].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


def _pids(namespace: str) -> list[int]:
    try:
        return [int(p) for p in run(["ip", "netns", "pids", namespace]).split()]
    except NetworkError:
        return []


def _stop_programs(namespaces: Sequence[str], grace: float = STOP_GRACE) -> list[int]:
    """Stop every process in ``namespaces``: Ctrl-C (SIGINT), then SIGKILL after ``grace`` s; their ids.

    SIGINT first: our programs, and ``fast-discovery-server``, end cleanly on
    it (a ROS 2 node then removes its shared-memory files).
    """
    pids = [pid for namespace in namespaces for pid in _pids(namespace)]
    for pid in pids:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGINT)
    deadline = time.monotonic() + grace
    while time.monotonic() < deadline and any(_alive(p) for p in pids):
        time.sleep(0.05)  # polling processes that may not be our children: no event to wait on
    for pid in pids:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    return pids


def _remove(namespaces: Sequence[str]) -> None:
    _stop_programs(namespaces)
    for namespace in namespaces:
        with contextlib.suppress(NetworkError):
            run(["ip", "netns", "del", namespace])
        shutil.rmtree(os.path.join(SHM_ROOT, namespace), ignore_errors=True)


def remove_stale() -> list[str]:
    """Remove the namespaces (and host directories) left by a run whose process is gone; their names.

    Only names that begin with :data:`PREFIX` and carry the id of a process
    that no longer exists are touched: a run still going, here or in another
    test session, keeps its hosts.
    """
    removed = []
    for name in namespaces():
        pid = _owner(name)
        if pid is not None and not _alive(pid):
            removed.append(name)
    _remove(removed)
    with contextlib.suppress(OSError):
        for entry in os.listdir(SHM_ROOT):
            pid = _owner(entry)
            if pid is not None and not _alive(pid) and os.path.isdir(os.path.join(SHM_ROOT, entry)):
                shutil.rmtree(os.path.join(SHM_ROOT, entry), ignore_errors=True)
                removed.append(entry)
    return removed


class Host:
    """One host of a :class:`Network`: a namespace, an address on :data:`SUBNET`, a ``/dev/shm`` of its own.

    Attributes:
        name: the host's name in the network (``robot``).
        namespace: its network namespace (``rttnet-<pid>-<n>-robot``).
        address: its IPv4 address, a string (``198.18.25.1``).
        shm_dir: the directory its programs see as ``/dev/shm``.
    """

    def __init__(self, network: Network, name: str, address: str, port: str):
        self.network = network
        self.name = name
        self.namespace = f"{network.name}-{name}"
        self.address = address
        self.switch_port = port  # the switch's end of this host's veth pair
        self.shm_dir = os.path.join(SHM_ROOT, self.namespace)
        self.loss = 0  # percent
        self.partitioned = False
        self.multicast_blocked = False
        self.rate_mbit: float | None = None

    def __repr__(self) -> str:
        return f"Host({self.name!r}, {self.address})"

    # ---- programs -------------------------------------------------------------
    def command(self, argv: Sequence[str]) -> list[str]:
        """``argv`` run on this host: in its namespace, with its own ``/dev/shm``.

        The program's pid is the one ``subprocess`` returns (``ip netns exec``
        and ``sh`` exec into it), so signals reach it directly.
        """
        return [
            "ip",
            "netns",
            "exec",
            self.namespace,
            "sh",
            "-c",
            'mount --bind "$0" /dev/shm && exec "$@"',
            self.shm_dir,
            *argv,
        ]

    def env(self, base: Mapping[str, str] | None = None, **extra: str) -> dict[str, str]:
        """The environment for a ROS 2 program on this host.

        ``base`` (``os.environ`` when None) with
        ``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET``: inside these namespaces the
        subnet is the network's own, and nothing else is reachable.  The
        ``ROS_DOMAIN_ID`` of ``base`` is kept; ``extra`` is added last.
        """
        env = dict(os.environ if base is None else base)
        env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "SUBNET"
        env.update(extra)
        return env

    def run(self, argv: Sequence[str], timeout: float = 30.0) -> subprocess.CompletedProcess:
        """Run ``argv`` on this host to the end; the completed process (text output)."""
        return subprocess.run(
            self.command(argv), env=self.env(), capture_output=True, text=True, timeout=timeout, check=False
        )

    def stop_programs(self) -> list[int]:
        """Stop every program still running on this host (SIGINT, then SIGKILL); their ids."""
        return _stop_programs([self.namespace])

    # ---- faults ---------------------------------------------------------------
    def set_loss(self, percent: int) -> None:
        """Drop ``percent`` % of the packets this host sends and receives on its link, at random.

        Raises:
            ValueError: ``percent`` is not in 0..100.
        """
        if not 0 <= int(percent) <= 100:
            raise ValueError(f"loss must be 0..100 %, got {percent}")
        self.loss = int(percent)
        self._apply_rules()

    def partition(self) -> None:
        """Cut this host off: every packet on its link is dropped, both ways (until :meth:`heal`)."""
        self.partitioned = True
        self._apply_rules()

    def heal(self) -> None:
        """End a partition (loss and multicast blocking stay as they were set)."""
        self.partitioned = False
        self._apply_rules()

    def block_multicast(self, blocked: bool = True) -> None:
        """Drop multicast (224.0.0.0/4) on this host's link: DDS's default discovery cannot cross."""
        self.multicast_blocked = blocked
        self._apply_rules()

    def limit_rate(self, mbit: float | None, latency_ms: float = 50.0) -> None:
        """Limit this host's link to ``mbit`` Mbit/s each way (a token bucket); None removes the limit.

        ``tc qdisc ... tbf`` on the host's end (what it sends) and on the
        switch's end (what it receives).  A packet waits at most
        ``latency_ms`` in the bucket's queue; later ones are dropped, as a
        congested WiFi or mobile link does.  The bucket holds 16 kB (about
        ten full packets), so short bursts pass at once.
        """
        self.rate_mbit = mbit
        for namespace, dev in ((self.namespace, LINK), (self.network.switch, self.switch_port)):
            if mbit is None:
                with contextlib.suppress(NetworkError):
                    run(["ip", "netns", "exec", namespace, "tc", "qdisc", "del", "dev", dev, "root"])
            else:
                run(
                    ["ip", "netns", "exec", namespace, "tc", "qdisc", "replace", "dev", dev, "root"]
                    + ["tbf", "rate", f"{mbit}mbit", "burst", "16kb", "latency", f"{latency_ms}ms"]
                )

    def clear_faults(self) -> None:
        """No loss, no partition, multicast passes, no rate limit."""
        self.loss, self.partitioned, self.multicast_blocked = 0, False, False
        self._apply_rules()
        if self.rate_mbit is not None:
            self.limit_rate(None)

    def rules(self) -> str:
        """The fault rules now in force, as ``nft`` prints them (for a notebook or a test)."""
        return run(["ip", "netns", "exec", self.namespace, "nft", "list", "chain", "inet", TABLE, "faults"])

    def _apply_rules(self) -> None:
        """Replace the ``faults`` chain's rules in one ``nft`` transaction (atomic: no packet sees half)."""
        rules = []
        if self.partitioned:
            rules.append("drop")
        if self.multicast_blocked:
            rules.append("ip daddr 224.0.0.0/4 drop")
        if self.loss:
            rules.append(f"numgen random mod 100 < {self.loss} drop")
        script = f"flush chain inet {TABLE} faults\n" + "".join(f"add rule inet {TABLE} faults {r}\n" for r in rules)
        run(["ip", "netns", "exec", self.namespace, "nft", "-f", "-"], stdin=script)

    def _setup_rules(self) -> None:
        """The table: packets in and out of ``rtt0`` (never loopback) go through the ``faults`` chain."""
        script = f"""table inet {TABLE} {{
    chain faults {{
    }}
    chain incoming {{
        type filter hook input priority 0; policy accept;
        iifname "{LINK}" jump faults
    }}
    chain outgoing {{
        type filter hook output priority 0; policy accept;
        oifname "{LINK}" jump faults
    }}
}}
"""
        run(["ip", "netns", "exec", self.namespace, "nft", "-f", "-"], stdin=script)


class Network:
    """Hosts joined by a switch, each a network namespace; removed by :meth:`close` (or ``with``).

    Args:
        hosts: the hosts' names, e.g. ``("robot", "operator")``; each gets the
            next address of :data:`SUBNET` (``.1``, ``.2``, ...).

    ``open()`` first removes what a killed earlier run left (:func:`remove_stale`),
    then builds; when building fails half-way, what was made is removed
    before the error is raised.  ``close()`` stops every program still
    running on the hosts, then removes the namespaces and the hosts'
    ``/dev/shm`` directories; it never raises.

    Raises (``open``):
        NetworkError: a command failed (see :func:`why_unavailable` first).
    """

    def __init__(self, hosts: Sequence[str] = ("robot", "operator")):
        if not hosts or len(set(hosts)) != len(hosts):
            raise ValueError(f"give distinct host names, got {list(hosts)}")
        if len(hosts) > 200:
            raise ValueError("at most 200 hosts")
        self.name = f"{PREFIX}{os.getpid()}-{next(_counter)}"
        self.switch = f"{self.name}-switch"
        addresses = itertools.islice(SUBNET.hosts(), len(hosts))
        self.hosts = {
            name: Host(self, name, str(address), f"port{i}") for i, (name, address) in enumerate(zip(hosts, addresses))
        }
        self.opened = False

    def __getitem__(self, name: str) -> Host:
        return self.hosts[name]

    def __enter__(self) -> Network:
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()

    def namespaces(self) -> list[str]:
        """This network's namespaces: the switch's, then each host's."""
        return [self.switch] + [h.namespace for h in self.hosts.values()]

    def open(self) -> Network:
        """Build the switch and the hosts; returns self."""
        remove_stale()
        self.opened = True
        try:
            run(["ip", "netns", "add", self.switch])
            sw = ["ip", "-n", self.switch]
            # No IGMP snooping: the bridge floods multicast to every port, as a small switch does.
            run(sw + ["link", "add", "br0", "type", "bridge", "mcast_snooping", "0"])
            run(sw + ["link", "set", "br0", "up"])
            for host in self.hosts.values():
                run(["ip", "netns", "add", host.namespace])
                os.makedirs(host.shm_dir, mode=0o1777, exist_ok=True)
                os.chmod(host.shm_dir, 0o1777)  # as /dev/shm: anyone may create, only owners delete
                # Both ends are made inside the namespaces: no interface ever exists outside them.
                run(
                    ["ip", "link", "add", LINK, "netns", host.namespace, "type", "veth"]
                    + ["peer", "name", host.switch_port, "netns", self.switch]
                )
                run(sw + ["link", "set", host.switch_port, "master", "br0", "up"])
                ns = ["ip", "-n", host.namespace]
                run(ns + ["addr", "add", f"{host.address}/{SUBNET.prefixlen}", "dev", LINK])
                run(ns + ["link", "set", "lo", "up"])
                run(ns + ["link", "set", LINK, "up"])
                host._setup_rules()
        except BaseException:
            self.close()
            raise
        return self

    def close(self) -> None:
        """Stop the hosts' programs, remove the namespaces and directories (never raises; idempotent)."""
        if not self.opened:
            return
        with contextlib.suppress(Exception):
            _remove(self.namespaces())
        self.opened = False

    def routes(self, host: str) -> list[str]:
        """The routes of a host (``ip route``, IPv4), one string each: only :data:`SUBNET` is expected."""
        return [line.strip() for line in run(["ip", "-n", self[host].namespace, "route"]).splitlines() if line.strip()]

    def interfaces(self, namespace: str) -> list[str]:
        """The interfaces of one of this network's namespaces, by name."""
        out = run(["ip", "-n", namespace, "-o", "link"])
        return [line.split(":")[1].strip().split("@")[0] for line in out.splitlines() if line.strip()]
