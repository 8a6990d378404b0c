"""How ROS 2 nodes on two hosts find each other: multicast, static peers, or a discovery server.

ROS 2 Jazzy (Fast DDS underneath) finds other participants by *discovery*:

* **multicast** (the default with ``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET``):
  every participant announces itself to the group 239.255.0.1; every host
  on the subnet that listens hears it.  Many WiFi networks, VPNs and
  mobile links drop multicast, and then nothing is discovered.
* **static peers** (``ROS_STATIC_PEERS``, addresses separated by ``;``):
  participants also announce themselves by unicast to these addresses.
  Each side needs the other's address (or one side the other's, and the
  other then answers).
* **a discovery server** (``ROS_DISCOVERY_SERVER=<address>:<port>``): every
  participant is a client of one server, which tells each of them about the
  others; only unicast.  Fast DDS's server program is
  ``fast-discovery-server``, shipped in the ``ros-fastrtps`` wheel.

Data always goes by unicast between the participants once they know each
other; discovery only decides whether they ever do.  :func:`static_peers_env`,
:func:`discovery_server_env` and :func:`discovery_server_command` give the
environment and command lines; any thread may call them.
"""

from __future__ import annotations

import os
import sys
import sysconfig
from collections.abc import Sequence
from pathlib import Path

DISCOVERY_SERVER_PORT = 11811  # Fast DDS's default server port


def static_peers_env(peers: Sequence[str]) -> dict[str, str]:
    """``{"ROS_STATIC_PEERS": "a;b"}`` for a program that should announce itself to ``peers`` (IPv4 addresses)."""
    return {"ROS_STATIC_PEERS": ";".join(peers)}


def discovery_server_env(address: str, port: int = DISCOVERY_SERVER_PORT) -> dict[str, str]:
    """``{"ROS_DISCOVERY_SERVER": "address:port"}``: make a program a client of that server."""
    return {"ROS_DISCOVERY_SERVER": f"{address}:{port}"}


def fast_dds_library_path() -> str:
    """The ``LD_LIBRARY_PATH`` ``fast-discovery-server`` needs in this Python environment.

    The wheels put Fast DDS's libraries in ``<prefix>/lib`` and their own
    dependencies in ``site-packages/ros_rmw_fastrtps_cpp.libs``; the program
    finds neither by itself.
    """
    site = Path(sysconfig.get_paths()["purelib"])
    parts = [str(Path(sys.prefix) / "lib"), str(site / "ros_rmw_fastrtps_cpp.libs")]
    if os.environ.get("LD_LIBRARY_PATH"):
        parts.append(os.environ["LD_LIBRARY_PATH"])
    return ":".join(parts)


def discovery_server_command(address: str, port: int = DISCOVERY_SERVER_PORT, server_id: int = 0) -> list[str]:
    """The command line of a Fast DDS discovery server listening on ``address:port`` (UDP).

    Run it with ``LD_LIBRARY_PATH`` set to :func:`fast_dds_library_path`.
    ``server_id`` is the server's place in clients' ``ROS_DISCOVERY_SERVER``
    list (0: the first).

    Raises:
        FileNotFoundError: ``fast-discovery-server`` is not in this environment's ``bin``.
    """
    program = Path(sys.prefix) / "bin" / "fast-discovery-server"
    if not program.exists():
        raise FileNotFoundError(f"{program} is missing: install the ros-jazzy-rmw-fastrtps-cpp wheel")
    return [str(program), "-i", str(server_id), "-l", address, "-p", str(port)]
