"""ROS 2 process set-up: localhost-only discovery and the project's Fast DDS profile by default, and init.

The spin thread is :mod:`tutorial.ros.spin`; what every ``rtt-*`` program does
with its command line and its stop signals is :mod:`tutorial.ros.program`.

ROS 2 Jazzy finds other nodes by multicast discovery.  Its reach is set by
``ROS_AUTOMATIC_DISCOVERY_RANGE`` (``LOCALHOST``, ``SUBNET``, ``OFF``,
``SYSTEM_DEFAULT``) and the group of nodes that see each other by
``ROS_DOMAIN_ID`` (0-101).  This tutorial defaults to ``LOCALHOST``: its nodes
only see nodes on the same machine.  That is the switch to flip for a real
robot: ``export ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET`` before starting.

The variables are read by the middleware when ``rclpy.init`` creates a context,
so :func:`use_localhost_by_default` must run before that; importing
:mod:`tutorial` does it.  It also names the project's Fast DDS profile
(:func:`use_project_profiles_by_default`): reliable writers repair a lost
message within milliseconds, which a monitor on a lossy link needs.

A ROS 2 installation sourced in the same shell (``source /opt/ros/jazzy/setup.bash``)
puts a second build of rclpy and its libraries on the paths: ``PYTHONPATH``
comes before this environment's ``site-packages``, so ``import rclpy`` would
load the installation's rclpy (built for the system's Python) with this
environment's libraries, or the other way round.  Importing this module
checks for it (:func:`sourced_ros_installation`) and stops the program with
a clear message when rclpy would come from elsewhere; it only warns when a
ROS installation is sourced but this environment's rclpy still comes first.
``RTT_ALLOW_SOURCED_ROS=1`` skips the check.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping, MutableMapping, Sequence
from pathlib import Path

DISCOVERY_RANGE_VARIABLE = "ROS_AUTOMATIC_DISCOVERY_RANGE"
DEFAULT_DISCOVERY_RANGE = "LOCALHOST"
ALLOW_SOURCED_ROS_VARIABLE = "RTT_ALLOW_SOURCED_ROS"
ROS_PATH_VARIABLES = ("AMENT_PREFIX_PATH", "PYTHONPATH", "LD_LIBRARY_PATH")


def sourced_ros_installation(
    environ: Mapping[str, str] | None = None, rclpy_origin: str | None = "find", prefix: str = sys.prefix
) -> tuple[str, str] | None:
    """Whether a ROS 2 installation is sourced into this environment: ``(level, message)`` or None.

    Args:
        environ: the environment to look at (``os.environ`` by default).
        rclpy_origin: where ``import rclpy`` would load it from (found
            without importing it by default; None: not found).
        prefix: this environment's prefix (``sys.prefix``).

    Returns:
        None when nothing is sourced; ``("error", message)`` when rclpy would
        be imported from a ``PYTHONPATH`` entry outside ``prefix`` (two rclpy
        builds: it fails, or mixes libraries); ``("warning", message)`` when a ROS installation is
        on the paths (``AMENT_PREFIX_PATH``, ``PYTHONPATH``,
        ``LD_LIBRARY_PATH`` entries outside ``prefix`` that belong to one) but
        this environment's rclpy is still the one imported.

    Any thread may call it; it changes nothing.
    """
    env = os.environ if environ is None else environ
    if rclpy_origin == "find":
        import importlib.util

        spec = importlib.util.find_spec("rclpy")
        rclpy_origin = spec.origin if spec is not None else None
    home = os.path.realpath(prefix)

    def outside(path: str) -> bool:
        real = os.path.realpath(path)
        return real != home and not real.startswith(home + os.sep)

    installs = [p for p in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p and outside(p)]
    roots = [os.path.realpath(p) for p in installs] + ["/opt/ros"]
    found = [
        f"{name} has {path}"
        for name in ROS_PATH_VARIABLES
        for path in env.get(name, "").split(os.pathsep)
        if path and outside(path) and any(os.path.realpath(path).startswith(r) for r in roots)
    ]
    # PYTHONPATH comes before site-packages: an rclpy under one of its entries shadows ours.  (An entry
    # that holds this environment, e.g. the project's folder with .venv inside it, shadows nothing.)
    shadowing = [
        p
        for p in env.get("PYTHONPATH", "").split(os.pathsep)
        if p and outside(p) and rclpy_origin is not None and outside(rclpy_origin)
        if os.path.realpath(rclpy_origin).startswith(os.path.realpath(p) + os.sep)
    ]
    if shadowing:
        level = "error"
        what = f"rclpy would be imported from {os.path.dirname(rclpy_origin)}, not from this environment ({prefix})"
    elif found:
        level = "warning"
        what = "this environment's rclpy comes first, but the installation's libraries and messages are on the paths"
    else:
        return None
    return level, (
        f"a ROS 2 installation is sourced in this shell ({'; '.join(found) or 'PYTHONPATH'}): {what}. "
        "Two builds of rclpy on one path fail in confusing ways. Run the rtt-* programs and notebooks in a "
        "shell that has not sourced /opt/ros/<distro>/setup.bash (open a new terminal, or `env -u PYTHONPATH "
        "-u AMENT_PREFIX_PATH -u LD_LIBRARY_PATH ...`), and ros2, RViz2 and robot_state_publisher in another "
        f"(see the book's 'With ROS 2 installed'). {ALLOW_SOURCED_ROS_VARIABLE}=1 skips this check."
    )


def _check_sourced_ros() -> None:
    """At import: stop with the message of an ``error``, print a ``warning`` (see :func:`sourced_ros_installation`)."""
    if os.environ.get(ALLOW_SOURCED_ROS_VARIABLE) == "1":
        return
    found = sourced_ros_installation()
    if found is None:
        return
    level, message = found
    print(f"rtt: {'ERROR' if level == 'error' else 'WARNING'}: {message}", file=sys.stderr, flush=True)
    if level == "error":
        raise SystemExit(2)


_check_sourced_ros()


def use_localhost_by_default(environ: MutableMapping[str, str] | None = None) -> str:
    """Make localhost-only discovery the default unless the user chose otherwise.

    Args:
        environ: the environment to change; ``os.environ`` when None.

    Returns:
        The discovery range now in force (the user's, if one was set).

    Any thread may call this, but it only matters before ``rclpy.init``.
    """
    env = os.environ if environ is None else environ
    return env.setdefault(DISCOVERY_RANGE_VARIABLE, DEFAULT_DISCOVERY_RANGE)


ASSIGNED_DOMAIN_VARIABLE = "RTT_ASSIGNED_ROS_DOMAIN_ID"  # set by a class's hub (course/jupyterhub_config.py)


def assigned_domain_warning(environ: Mapping[str, str] | None = None) -> str | None:
    """A warning when ``ROS_DOMAIN_ID`` is not the domain a class's hub gave this learner, else None.

    On a shared server each learner's nodes live in a domain of their own
    (``RTT_ASSIGNED_ROS_DOMAIN_ID``, set by the hub).  A learner who changes
    ``ROS_DOMAIN_ID`` by hand loses their own nodes started elsewhere and may
    join another learner's robots.  Any thread may call it.
    """
    env = os.environ if environ is None else environ
    assigned = env.get(ASSIGNED_DOMAIN_VARIABLE)
    current = env.get("ROS_DOMAIN_ID", "0") or "0"
    if not assigned or current == assigned:
        return None
    return (
        f"ROS_DOMAIN_ID is {current}, but this server gave you ROS domain {assigned}: your notebooks, terminals "
        f"and rtt-* programs meet only in {assigned}, and {current} may be another learner's robots. "
        f"Run `export ROS_DOMAIN_ID={assigned}` (or unset it in this notebook: "
        f"os.environ['ROS_DOMAIN_ID'] = '{assigned}') before starting nodes."
    )


def warn_if_not_assigned_domain() -> None:
    """Print :func:`assigned_domain_warning`'s warning, if any (at import, and before rclpy starts in a
    notebook: :func:`tutorial.notebook.session.init_ros`; main thread)."""
    message = assigned_domain_warning()
    if message:
        print(f"rtt: WARNING: {message}", file=sys.stderr, flush=True)


PROFILES_VARIABLE = "FASTRTPS_DEFAULT_PROFILES_FILE"  # the name Fast DDS 2.x (Jazzy's 2.14) reads
PROJECT_PROFILES = Path(__file__).with_name("fastdds_profiles.xml")


def use_project_profiles_by_default(environ: MutableMapping[str, str] | None = None) -> str:
    """Make this project's Fast DDS profile the default unless the user named a file of theirs.

    The profile (``tutorial/ros/fastdds_profiles.xml``, where the reasons and
    the measured figures are) makes reliable writers repair a lost message
    within milliseconds instead of Fast DDS's 3 s heartbeat: on a lossy link
    a 50 Hz monitor then shows nearly every state, not only those the link
    kept.  QoS policies still come from the code.  Another middleware
    (``RMW_IMPLEMENTATION``) ignores the variable.  To run without it, name
    a file of your own (``<profiles xmlns="..."/>`` holds nothing).

    Args:
        environ: the environment to change; ``os.environ`` when None.  An
            empty ``FASTRTPS_DEFAULT_PROFILES_FILE`` counts as not set.

    Returns:
        The profiles file now in force (the user's, if one was set).

    Main thread, before any ROS 2 thread starts (it writes the environment,
    which C code reads unlocked); it only matters before the process's first
    node: Fast DDS reads the file once, when it creates a participant.
    """
    env = os.environ if environ is None else environ
    if not env.get(PROFILES_VARIABLE):
        env[PROFILES_VARIABLE] = str(PROJECT_PROFILES)
    return env[PROFILES_VARIABLE]


def init(args: Sequence[str] | None = None):
    """Initialise rclpy for this process with localhost discovery by default.

    Args:
        args: the command line, ``--ros-args ...`` included (``sys.argv`` style).

    Returns:
        The command line with the ROS arguments removed, for argparse.

    Call from the main thread, once per process (or once per ``try_shutdown``).
    """
    use_localhost_by_default()
    import rclpy
    from rclpy.utilities import remove_ros_args

    rclpy.init(args=list(args) if args is not None else None)
    return remove_ros_args(list(args) if args is not None else None)
