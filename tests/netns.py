"""The network tier's hosts: a fixture that makes two hosts, runs our programs on them, and removes them.

``net`` gives a :class:`tutorial.tools.network.hosts.Network` with the hosts
``robot`` (198.18.25.1) and ``operator`` (198.18.25.2), each a network
namespace joined to the other through a switch namespace.  Programs started
with :func:`on` run inside a host with ``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET``
(the only place the test suite uses it: nothing but the two hosts is on that
subnet) and the session's ``ROS_DOMAIN_ID``.  After the test, passed or not,
every program still running on the hosts is stopped and the namespaces and
the hosts' ``/dev/shm`` directories are removed; namespaces that a killed
earlier run left (named ``rttnet-<its pid>-...``) are removed before.

Where namespaces cannot be made (not root, no ``ip``, ``nft`` or ``tc``) the
tests skip, saying which.  ``make test`` installs Debian's nftables first
(``scripts/ensure-nftables.sh``).
"""

from __future__ import annotations

import functools
import json

import pytest

from tutorial.tools.network.hosts import Host, Network, why_unavailable

from conftest import Proc, module_command


@functools.lru_cache(maxsize=1)
def network_problem() -> str | None:
    return why_unavailable()


@pytest.fixture
def net():
    """A robot and an operator host, removed after the test (also when it fails)."""
    problem = network_problem()
    if problem:
        pytest.skip(f"the network tier needs its own hosts, and they cannot be made here: {problem}")
    network = Network(("robot", "operator")).open()
    try:
        yield network
    finally:
        network.close()


def on(procs, host: Host, module: str, *args: str, **env: str) -> Proc:
    """Start ``python -m module args`` on ``host`` (with ``env`` added), as a ``procs`` process."""
    return procs(host.command(module_command(module, *args)), env=host.env(**env))


def is_event(event: str):
    """A line predicate: a JSON record of this event."""
    tag = f'"event": "{event}"'

    def predicate(line: str) -> bool:
        return line.startswith("{") and tag in line and json.loads(line).get("event") == event

    return predicate
