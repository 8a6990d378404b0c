# The class on containers: each learner's server is a container of the learner image
# (course/containers/Containerfile), started by JupyterHub's DockerSpawner through Docker's API, which
# podman serves too (`podman system service`).
#
#   make hub-containers     # http://127.0.0.1:8000, as `make hub`; podman, as root
#
# What it shares with course/jupyterhub_config.py (read first, then changed here): who logs in, where the hub
# listens, the idle culler.  What differs:
# - each learner's server is a container on a network of its own (RTT_HUB_CONTAINER_NETWORK, made by
#   `make hub-containers` with --internal: nothing routes from it beyond this machine), whose address the
#   hub's API also listens on (RTT_HUB_CONTAINER_GATEWAY), for the servers to reach the hub;
# - the learner's home is a named volume, rtt-home-<name>: the image's notebooks and project files the first
#   time, the learner's own work after (a container is removed when its server stops; the volume stays);
# - each container in a user namespace of its own (below): on this machine, a learner's files belong to a uid
#   of that learner's alone;
# - the limits are DockerSpawner's (mem_limit, cpu_limit, a pids limit), from the same figures as course/limits.py;
# - no book of ROS domains: each container has a network namespace of its own, where discovery on localhost
#   finds that learner's nodes only, so every learner uses the same domain (RTT_HUB_CONTAINER_DOMAIN, default 0).
# - nbgrader's exchange: released assignments and feedback read only, and an inbound folder of each learner's
#   own (course/container_exchange.py).
# Not stopped: a learner's container reaching a port another learner's container serves on that network (the
# learners' Jupyter servers ask for the hub's login; anything else a learner starts there does not).

import contextlib
import grp
import os
import pwd
from pathlib import Path

c = get_config()  # noqa: F821 - JupyterHub provides it
load_subconfig(str(Path(__file__).with_name("jupyterhub_config.py")))  # noqa: F821

GATEWAY = os.environ.get("RTT_HUB_CONTAINER_GATEWAY") or "127.0.0.1"  # never "": every address
c.JupyterHub.hub_ip = GATEWAY  # the hub's API, for the learners' servers: on the containers' network only
c.JupyterHub.hub_connect_ip = GATEWAY

from container_exchange import JOVYAN, give_learner_their_exchange  # noqa: E402 - course/ is on the path: the base's
from dockerspawner import DockerSpawner  # noqa: E402
from idle_stops import remembering_last_use  # noqa: E402 - course/ is on the path: the base put it there
from traitlets.config.loader import PyFileConfigLoader  # noqa: E402

c.JupyterHub.spawner_class = remembering_last_use(DockerSpawner)
c.DockerSpawner.image = os.environ.get("RTT_HUB_IMAGE", "localhost/ros-tank-tutorial:learner")
c.DockerSpawner.network_name = os.environ.get("RTT_HUB_CONTAINER_NETWORK", "rtt-learners")
c.DockerSpawner.use_internal_ip = True  # the proxy reaches each container at its address on that network
c.DockerSpawner.remove = True
c.DockerSpawner.notebook_dir = "/home/jovyan"
# U: podman gives the volume to the container's user as its namespace maps it (below), at every start
c.DockerSpawner.volumes = {"rtt-home-{username}": {"bind": "/home/jovyan", "mode": "rw,U"}}
# Each learner's container in a user namespace of its own: its uids 0 to 65535 are this machine's
# USERNS_FIRST + 65536 x (the hub's id for the learner) on.  So the image's jovyan (uid 1000) is, on this
# machine, a uid no account has and no other learner's container shares: what a learner's container writes
# (their home volume, their folder of the exchange) is theirs alone, not uid 1000's.  Podman takes the
# mapping through Docker's API as its --userns=auto:uidmapping=...; the default first uid, 2^24, is past
# the ranges /etc/subuid usually hands out.
# Podman only: Docker refuses both this user namespace mode and the volume's U.  The hub's id for a learner is
# a row of its database: a new database may give a learner another's range, which :U and the pre-spawn hook
# give back to them (their files are theirs again; no other learner's volume or folder is ever mounted).
USERNS_FIRST = int(os.environ.get("RTT_HUB_USERNS_FIRST", str(1 << 24)))
USERNS_SIZE = 65536
if USERNS_FIRST < 1 << 24:
    raise SystemExit(f"RTT_HUB_USERNS_FIRST={USERNS_FIRST}: below 2^24, the learners' uids may be accounts'")


def learner_uid(spawner, uid: int = 0) -> int:
    """This machine's uid for ``uid`` in ``spawner``'s learner's container.

    Raises:
        RuntimeError: that learner's range is past the last uid, or an account, a group or a subordinate
            range (/etc/subuid, /etc/subgid) of this machine has some of it: their files would not be theirs alone.
    """
    first = USERNS_FIRST + USERNS_SIZE * spawner.user.id
    last = first + USERNS_SIZE - 1
    if last >= (1 << 32) - 1:
        raise RuntimeError(f"no uids left for {spawner.user.name} (the hub's learner {spawner.user.id})")
    for listed in ("/etc/subuid", "/etc/subgid"):
        for line in Path(listed).read_text().splitlines() if Path(listed).is_file() else ():
            fields = line.split(":")
            if len(fields) == 3 and fields[1].isdigit() and fields[2].isdigit():
                start = int(fields[1])
                if start <= last and first < start + int(fields[2]):
                    raise RuntimeError(f"{listed} gives {fields[0]} uids of {spawner.user.name}'s range {first}-{last}")
    for owner in (first, first + JOVYAN):  # the uids the learner's files have on this machine
        for known in (pwd.getpwuid, grp.getgrgid):
            with contextlib.suppress(KeyError):
                raise RuntimeError(f"uid {owner}, of {spawner.user.name}'s container, is {known(owner)[0]!r} here")
    return first + uid


def in_a_user_namespace_of_their_own(spawner) -> dict:
    mapping = f"0:{learner_uid(spawner)}:{USERNS_SIZE}"
    return {"host_config": {"UsernsMode": f"auto:uidmapping={mapping},gidmapping={mapping}"}}


c.DockerSpawner.extra_create_kwargs = in_a_user_namespace_of_their_own
c.DockerSpawner.extra_host_config = {"pids_limit": int(os.environ.get("RTT_HUB_PIDS_LIMIT", "500"))}
c.Spawner.cmd = ["jupyterhub-singleuser"]  # the image's own environment, not this machine's
c.Spawner.args = []
c.Spawner.ip = "0.0.0.0"  # inside the container: its own network namespace, on the containers' network
# nbgrader's exchange, where the base's configuration for the learners (its folder, before the environment
# below drops it) says it is, with an inbound folder per learner (course/container_exchange.py).
LEARNER_CONFIG = Path(c.Spawner.environment["JUPYTER_CONFIG_PATH"])
EXCHANGE = Path(PyFileConfigLoader("nbgrader_config.py", path=str(LEARNER_CONFIG)).load_config().Exchange.root)


def prepare_learner(spawner):
    """No domain to give, no files to copy (the image and the volume hold them): the learner's exchange, and
    a learner the culler stopped is told, as on the base (course/idle_stops.py, whose IdleStops the base's
    post_stop_hook belongs to)."""
    give_learner_their_exchange(spawner, EXCHANGE, LEARNER_CONFIG, owner=learner_uid(spawner, JOVYAN))
    c.Spawner.post_stop_hook.__self__.before_spawn(spawner)


c.Spawner.pre_spawn_hook = prepare_learner
# The base's environment for the learners, but for what names this machine (its PATH, its Jupyter
# configuration folder): the image has its own.  The domain: the same for every learner.
c.Spawner.environment = {
    **{k: v for k, v in c.Spawner.environment.items() if k not in ("PATH", "JUPYTER_CONFIG_PATH")},
    "ROS_DOMAIN_ID": os.environ.get("RTT_HUB_CONTAINER_DOMAIN", "0"),
}
