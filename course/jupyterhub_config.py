# A JupyterHub for a class: each learner's server runs the project's environment, opens its notebooks, and
# gets a ROS 2 domain of its own (course/domains.py), so each learner's robots are their own.
#
#   make hub        # http://127.0.0.1:8000, learners learner1..learner3, trial password "tanktutorial"
#
# What a course changes, each in one place below: who logs in (the authenticator), where a learner's
# server runs (the spawner), and where the hub listens.  Settings from the environment, for a trial or a test:
#   RTT_HUB_URL         where the hub listens (default http://127.0.0.1:8000; keep 127.0.0.1 for a trial)
#   RTT_HUB_STATE       the hub's own files: database, cookie secret, the book of ROS domains, learners'
#                       homes in a trial (default course/.hub)
#   RTT_HUB_LEARNERS    the trial's learner accounts, comma-separated (default learner1,learner2,learner3)
#   RTT_HUB_PASSWORD    the trial's shared password (at least 8 characters; default tanktutorial)
#   RTT_HUB_TEACHER, RTT_HUB_TEACHER_PASSWORD  the teacher's account, an admin of the hub (its admin page: the
#                       learners' servers), and its own password (at least 32 characters); default none
#   RTT_HUB_SPAWNER     "simple" (default: every learner's server runs as this user, homes under the state
#                       folder; a trial only) or "users" (each learner a Unix user of this machine; the hub
#                       runs as root; RTT_HUB_PYTHON then names an environment every user can run)
#   RTT_HUB_PYTHON      the Python of the learners' environment (default this project's .venv)
#   RTT_HUB_IDLE_TIMEOUT  seconds without use after which a learner's server is stopped (default 3600);
#                       RTT_HUB_ACTIVITY_INTERVAL how often the servers report their use (default 300 s)
#   RTT_HUB_MEM_LIMIT, RTT_HUB_CPU_LIMIT, RTT_HUB_PIDS_LIMIT  each learner's server's memory (default 2G),
#                       a cap in cores (default none: an equal share each) and processes (default 500):
#                       course/limits.py
#   RTT_HUB_DOMAINS     the ROS domains to give out, comma-separated (default: every one a server has, 1-101
#                       and 215-232; tests pick their own)
#   RTT_HUB_FRAME_RATE  the learners' live views' frames per second, at most (default 20: a server's CPU is
#                       shared; a learner's own machine draws 60)
#   RTT_HUB_REALTIME_SLICE_MS  how far ahead of real time a learner's simulation runs before it sleeps (default
#                       10 ms; 0.2 as on a learner's own machine, where CPU is not shared)
#   RTT_HUB_PER_LEARNER_NETWORK  "1" when the spawner gives each learner a network namespace (containers,
#                       pods): domains may then repeat
#   RTT_HUB_WORKED_SOLUTIONS  "shown" to keep the notebooks' folded worked solutions in the learners' copies (a
#                       workshop that grades nothing); by default they are held back, as in the assignments
#   RTT_NBGRADER_EXCHANGE  nbgrader's exchange, where learners fetch assignments and submit them (default
#                       the state folder's exchange/; a course's server: /srv/nbgrader/exchange); the teacher's
#                       course/nbgrader_config.py reads the same variable

import json
import os
import pwd
import stat
import sys
from pathlib import Path

from tornado import web

COURSE = Path(__file__).resolve().parent
ROOT = COURSE.parent
sys.path.insert(0, str(COURSE))

from domains import BOOK_NAME, DomainBook, DomainError, hub_state, running_hub  # noqa: E402
from idle_stops import IdleStops, remembering_last_use  # noqa: E402
from learner_home import close_home, make_learner_home  # noqa: E402 - course/ is on the path only from here
from limits import LimitedLocalProcessSpawner, LimitedSimpleLocalProcessSpawner  # noqa: E402

c = get_config()  # noqa: F821 - JupyterHub provides it

STATE = hub_state()
STATE.mkdir(parents=True, exist_ok=True)
if (already := running_hub(STATE)) is not None:
    sys.exit(
        f"a hub already runs with the state folder {STATE} (process {already}): a second one would stop its proxy "
        "and take its database. Stop that one first (Ctrl+C in its terminal), or give this one another folder "
        "(RTT_HUB_STATE) and address (RTT_HUB_URL)."
    )
PYTHON = Path(os.environ.get("RTT_HUB_PYTHON", ROOT / ".venv" / "bin" / "python"))
ENV_BIN = PYTHON.parent  # jupyterhub-singleuser and the rtt-* programs of the learners' environment
LEARNERS = [n.strip() for n in os.environ.get("RTT_HUB_LEARNERS", "learner1,learner2,learner3").split(",") if n.strip()]
SHOW_SOLUTIONS = os.environ.get("RTT_HUB_WORKED_SOLUTIONS") == "shown"

# ---- where the hub listens: this machine only, unless a course puts it behind its own HTTPS front
c.JupyterHub.bind_url = os.environ.get("RTT_HUB_URL", "http://127.0.0.1:8000")
PORT = int(c.JupyterHub.bind_url.rstrip("/").rsplit(":", 1)[1])
c.JupyterHub.hub_ip = "127.0.0.1"
c.JupyterHub.hub_port = PORT + 2  # the hub's own API; the proxy's is the next port
c.ConfigurableHTTPProxy.api_url = f"http://127.0.0.1:{PORT + 1}"
c.ConfigurableHTTPProxy.command = [str(COURSE / "node_modules" / ".bin" / "configurable-http-proxy")]
c.JupyterHub.db_url = f"sqlite:///{STATE / 'jupyterhub.sqlite'}"
c.JupyterHub.cookie_secret_file = str(STATE / "jupyterhub_cookie_secret")
c.JupyterHub.pid_file = str(STATE / "jupyterhub.pid")
c.ConfigurableHTTPProxy.pid_file = str(STATE / "proxy.pid")

# ---- who logs in.  A trial: one shared password for the listed learners.  A course plugs in its own:
#   OAuth (GitHub, Google, a university's):  pip install oauthenticator
#       c.JupyterHub.authenticator_class = "github"; c.GitHubOAuthenticator.client_id = ...
#   LTI, from a learning management system (Moodle, Canvas):  pip install jupyterhub-ltiauthenticator
#       c.JupyterHub.authenticator_class = "ltiauthenticator.lti13.authenticator.LTI13Authenticator"
c.JupyterHub.authenticator_class = "shared-password"
c.SharedPasswordAuthenticator.user_password = os.environ.get("RTT_HUB_PASSWORD", "tanktutorial")
c.Authenticator.allowed_users = set(LEARNERS)
# The teacher's account, an admin of the hub: its admin page lists the learners' servers, and starts, stops and
# opens them.  With the shared password, an admin logs in with a password of their own, of 32 characters or more.
TEACHER = os.environ.get("RTT_HUB_TEACHER", "").strip()
if TEACHER:
    if len(os.environ.get("RTT_HUB_TEACHER_PASSWORD", "")) < 32:
        sys.exit("RTT_HUB_TEACHER needs RTT_HUB_TEACHER_PASSWORD, at least 32 characters (the admin's own)")
    c.Authenticator.admin_users = {TEACHER}
    c.SharedPasswordAuthenticator.admin_password = os.environ["RTT_HUB_TEACHER_PASSWORD"]

# ---- where a learner's server runs.  A trial: a process of this user per learner.  A course uses one of:
#   every learner a Unix user of this machine (The Littlest JupyterHub):  RTT_HUB_SPAWNER=users below
#   a container each:  pip install dockerspawner;  c.JupyterHub.spawner_class = "docker"
#   Kubernetes (Zero to JupyterHub):  pip install jupyterhub-kubespawner;  c.JupyterHub.spawner_class = "kubespawner"
#   systemd units with resource limits:  pip install jupyterhub-systemdspawner;  c.JupyterHub.spawner_class = "systemd"
# In a container or pod each learner has a network namespace of their own: set RTT_HUB_PER_LEARNER_NETWORK=1.
# The local spawners here keep each learner's server in cgroups of its own (course/limits.py): memory, processes
# and CPU, so one learner cannot take the class's server down.  Containers and pods get theirs from
# DockerSpawner's or KubeSpawner's mem_limit and cpu_limit.  Whichever spawner, remembering_last_use(...) lets a
# learner the idle culler stopped be told so (course/idle_stops.py).
UNIX_USERS = os.environ.get("RTT_HUB_SPAWNER", "simple") == "users"
if UNIX_USERS:
    # each learner's server runs as their Unix user
    c.JupyterHub.spawner_class = remembering_last_use(LimitedLocalProcessSpawner)
    c.LocalProcessSpawner.notebook_dir = "~"
else:
    # a trial: no isolation between learners' files
    c.JupyterHub.spawner_class = remembering_last_use(LimitedSimpleLocalProcessSpawner)
    c.SimpleLocalProcessSpawner.home_dir_template = str(STATE / "homes" / "{username}")
    if os.geteuid() == 0:  # a trial started as root (a container): Jupyter refuses root without this
        c.Spawner.args = ["--allow-root"]
c.Spawner.cmd = [str(ENV_BIN / "jupyterhub-singleuser")]
c.Spawner.ip = "127.0.0.1"
c.Spawner.default_url = "/lab/tree/notebooks/00_setup_check.ipynb"
c.Spawner.http_timeout = 60  # s: a 2-core server starting several learners at once is slow
c.Spawner.start_timeout = 120
# Each learner's limits (course/limits.py): what Step 6's camera notebook needs with room to spare (its kernel
# peaks near 0.5 GiB), a fourth of the processes a fork bomb would want, and an equal share of the CPU.
c.Spawner.mem_limit = os.environ.get("RTT_HUB_MEM_LIMIT", "2G")
if os.environ.get("RTT_HUB_CPU_LIMIT"):  # cores; by default an equal share each, and all when nobody else needs it
    c.Spawner.cpu_limit = float(os.environ["RTT_HUB_CPU_LIMIT"])
c.LimitedLocalProcessSpawner.pids_limit = int(os.environ.get("RTT_HUB_PIDS_LIMIT", "500"))
c.Spawner.environment = {
    "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",  # a learner's nodes never look beyond this machine
    "PATH": f"{ENV_BIN}:/usr/local/bin:/usr/bin:/bin",  # rtt-* in the learner's terminals
    # Live views draw at most this many frames a second (tutorial/app/frame_clock.py; 60 on a learner's own
    # machine): each frame costs the server, and the book's Benchmarks page says how many learners it holds.
    "RTT_FRAME_RATE": os.environ.get("RTT_HUB_FRAME_RATE", "20"),
    # A simulation keeps real time in slices of 10 ms, not 0.2 ms (tutorial/core/simulator.py): each wake-up
    # costs about 0.1 ms of CPU, so a learner's tank at 1 kHz costs 0.05 cores less.  The lessons' topics
    # (50 Hz) and views (20 frames/s) are far slower than 10 ms; a 1 kHz publisher's messages come in tens.
    "RTT_REALTIME_SLICE_MS": os.environ.get("RTT_HUB_REALTIME_SLICE_MS", "10"),
    # One thread each for NumPy's BLAS and OpenMP (not one per core of a large server): threads count
    # against a learner's processes (course/limits.py), and the lessons' arrays are small.
    "OPENBLAS_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
}

# nbgrader for the learners: the course and its exchange (fetch and submit, from the Assignments tab of
# JupyterLab or `nbgrader fetch_assignment` in a terminal), and no teacher's tools (formgrader, creating
# assignments) in their JupyterLab.  Their servers read it from a Jupyter configuration folder of the hub's.
EXCHANGE = Path(os.environ.get("RTT_NBGRADER_EXCHANGE", STATE / "exchange"))
EXCHANGE.mkdir(parents=True, exist_ok=True)
EXCHANGE.chmod(0o1777)  # every learner writes their submissions into it; only its owner renames what is in it
# The course's folder in it is made now, the hub's (the teacher's), before any learner can: one a learner made
# first would be theirs, and grading refuses a course folder that is not the teacher's (course/submissions.py).
COURSE_EXCHANGE = EXCHANGE / "ros-tank-tutorial"
try:
    COURSE_EXCHANGE.mkdir(mode=0o700)  # closed while it is made: nobody puts a folder in it meanwhile
    COURSE_EXCHANGE.chmod(0o755)  # as nbgrader's release makes it, whatever the umask
except FileExistsError:
    pass
_made = COURSE_EXCHANGE.lstat()
if not stat.S_ISDIR(_made.st_mode) or _made.st_uid != os.geteuid() or _made.st_mode & 0o022:
    raise SystemExit(
        f"{COURSE_EXCHANGE} is not the hub's (a link, or someone else's, or writable by others): a learner may have "
        "made it before the course was released. Move it away (its inbound holds any submissions), then start "
        "the hub again."
    )
LEARNER_CONFIG = STATE / "learner_jupyter"
(LEARNER_CONFIG / "labconfig").mkdir(parents=True, exist_ok=True)
(LEARNER_CONFIG / "nbgrader_config.py").write_text(
    "import os\n"
    "c = get_config()  # noqa: F821\n"
    'c.CourseDirectory.course_id = "ros-tank-tutorial"\n'
    f"c.Exchange.root = {str(EXCHANGE)!r}\n"
    "c.Exchange.path_includes_course = True\n"
    "# A submission is the hub's learner's, not the Unix user's: nbgrader names it after the Unix user, and\n"
    "# on the trial's spawner every learner is the same one (their submissions would overwrite each other).\n"
    'if os.environ.get("JUPYTERHUB_USER"):\n'
    '    c.CourseDirectory.student_id = os.environ["JUPYTERHUB_USER"]\n'
)
# Also left out: nbgrader's toolbar Validate button, which on a lesson notebook (not an assignment) reports
# "Success!" whatever the answers (the check cells are the test; the Assignments tab keeps its own Validate),
# and JupyterLab's question about Jupyter's news feed.
LEFT_OUT = ["create-assignment", "course-list", "formgrader", "validate-assignment"]
(LEARNER_CONFIG / "labconfig" / "page_config.json").write_text(
    json.dumps(
        {
            "disabledExtensions": {
                **{f"@jupyter/nbgrader:{name}": True for name in LEFT_OUT},
                "@jupyterlab/apputils-extension:announcements": True,
            }
        }
    )
    + "\n"
)
# A learner's terminal is not a login shell, so it keeps the server's environment (PATH with the rtt-* programs,
# the ROS domain): JupyterLab otherwise starts a login shell under a hub, and /etc/profile resets PATH.
SHELL = "/bin/bash" if Path("/bin/bash").exists() else "/bin/sh"
(LEARNER_CONFIG / "jupyter_server_config.json").write_text(
    json.dumps(
        {
            "ServerApp": {
                "jpserver_extensions": {
                    "nbgrader.server_extensions.formgrader": False,
                    "nbgrader.server_extensions.course_list": False,
                    "own_ports": True,
                },
                "terminado_settings": {"shell_command": [SHELL]},
            },
            # /proxy/HOST:PORT/ reaches no host: /proxy/PORT/ alone, checked by course/own_ports.py
            "ServerProxy": {"host_allowlist": []},
        }
    )
    + "\n"
)
# A learner's Jupyter proxies (/user/NAME/proxy/PORT/) only the ports their own processes serve: not another
# learner's meshcat page or server on this machine (course/own_ports.py).
(LEARNER_CONFIG / "jupyter_server_config.py").write_text(
    f"import sys\nsys.path.insert(0, {str(COURSE)!r})  # own_ports, a server extension (jupyter_server_config.json)\n"
)
for path in (LEARNER_CONFIG, LEARNER_CONFIG / "labconfig"):
    path.chmod(0o755)
c.Spawner.environment["JUPYTER_CONFIG_PATH"] = str(LEARNER_CONFIG)


def closed_to_others(path: Path) -> Path | None:
    """The first folder on the way to ``path`` that other users cannot enter, or ``path`` if they cannot read it
    (list it, for a folder); None if they can."""
    closed = next((f for f in reversed(path.parents) if not f.stat().st_mode & stat.S_IXOTH), None)
    needed = stat.S_IROTH | (stat.S_IXOTH if path.is_dir() else 0)
    return closed or (None if path.stat().st_mode & needed == needed else path)


# Learners who are Unix users must reach these, or their servers would start without them, silently: no
# nbgrader, and a proxy to every port of the machine.  The hub refuses to start instead.
for path in LEARNER_CONFIG.rglob("*"):  # written under the hub's umask: readable by every learner
    path.chmod(0o755 if path.is_dir() else 0o644)
for what, path in (("their Jupyter configuration", LEARNER_CONFIG), ("nbgrader's exchange", EXCHANGE),
                   ("course/own_ports.py", COURSE), ("course/own_ports.py", COURSE / "own_ports.py")):  # fmt: skip
    if UNIX_USERS and (closed := closed_to_others(path)):
        raise SystemExit(
            f"learners as Unix users cannot reach {what} ({path}): other users cannot enter or read {closed}. "
            "Put the hub's state (RTT_HUB_STATE) or the exchange (RTT_NBGRADER_EXCHANGE) where every user can, "
            f"or chmod o+rx {closed}."
        )

DOMAINS = DomainBook(
    STATE / BOOK_NAME,
    domains=[int(d) for d in os.environ["RTT_HUB_DOMAINS"].split(",")] if os.environ.get("RTT_HUB_DOMAINS") else None,
    per_learner_network=os.environ.get("RTT_HUB_PER_LEARNER_NETWORK") == "1",
)


class SpawnRefused(web.HTTPError):
    """A learner's server refused, with the reason: on their page (``jupyterhub_message``), as the hub API's
    503 (the server cannot be had now, the hub itself is fine), and in the hub's log."""

    def __init__(self, message: str):
        super().__init__(503, "%s", message, reason="Service Unavailable")
        self.jupyterhub_message = message


def give_learner_their_domain_and_notebooks(spawner):
    """Before a learner's server starts: their ROS domain, in its environment, and their copy of the notebooks.

    A learner the book cannot give a domain (a name it cannot hold, none left) gets the reason on the hub's
    page and no server; no other learner's server is touched.
    """
    name = spawner.user.name
    try:
        domain = DOMAINS.domain_for(name)
    except DomainError as exc:
        spawner.log.error("%s", exc)
        raise SpawnRefused(str(exc)) from None
    spawner.environment["ROS_DOMAIN_ID"] = str(domain)
    spawner.environment["RTT_ASSIGNED_ROS_DOMAIN_ID"] = str(domain)  # the notebooks warn if it is changed
    spawner.log.info("learner %s: ROS domain %d", name, domain)
    unix_user = UNIX_USERS
    home = Path(pwd.getpwnam(name).pw_dir) if unix_user else Path(spawner.home_dir)
    make_learner_home(
        home, SHOW_SOLUTIONS, ENV_BIN / "jupyter", give=lambda path: _give_to_learner(path, name, unix_user)
    )
    if unix_user and close_home(home):  # another learner could read their answers and feedback
        spawner.log.info("learner %s: home %s made theirs alone (700)", name, home)
    IDLE_STOPS.before_spawn(spawner)


def _give_to_learner(path: Path, name: str, unix_user: bool) -> None:
    """Made by the hub (root) for a learner who is a Unix user: ``path`` and all in it are theirs from now on.

    Links are given as links (``lchown``), never followed: a link the learner planted in their home cannot
    make the hub give them a file of the system's."""
    if unix_user and os.geteuid() == 0:
        entry = pwd.getpwnam(name)
        for each in [path, *path.rglob("*")]:
            os.lchown(each, entry.pw_uid, entry.pw_gid)


c.Spawner.pre_spawn_hook = give_learner_their_domain_and_notebooks

# ---- idle culling: a learner's server nobody has used for IDLE_TIMEOUT seconds is stopped (with everything it
# started: course/limits.py), by JupyterHub's own culler, a service of this hub.  Their notebooks stay in their
# home and their ROS domain in the book: logging in again brings both back.  A server is used while a page of it
# is open and talks to it (a notebook, a terminal, a live view) or a cell runs; a simulation left running in a
# kernel nobody looks at is not use.  The servers tell the hub of their activity every ACTIVITY_INTERVAL s.
IDLE_TIMEOUT = int(os.environ.get("RTT_HUB_IDLE_TIMEOUT", "3600"))
ACTIVITY_INTERVAL = int(os.environ.get("RTT_HUB_ACTIVITY_INTERVAL", "300"))
c.JupyterHub.last_activity_interval = ACTIVITY_INTERVAL
IDLE_STOPS = IdleStops(STATE / "idle-stops.json", IDLE_TIMEOUT)  # told in the learner's next first init_ros()
c.Spawner.post_stop_hook = IDLE_STOPS.after_stop
c.Spawner.environment["JUPYTERHUB_ACTIVITY_INTERVAL"] = str(ACTIVITY_INTERVAL)
c.JupyterHub.load_roles = [
    {
        "name": "idle-culler",
        "scopes": ["list:users", "read:users:activity", "read:servers", "delete:servers"],
        "services": ["idle-culler"],
    }
]
c.JupyterHub.services = [
    {
        "name": "idle-culler",
        "command": [
            sys.executable,
            "-m",
            "jupyterhub_idle_culler",
            f"--timeout={IDLE_TIMEOUT}",
            f"--cull-every={max(1, min(300, IDLE_TIMEOUT // 4))}",
        ],
    }
]
