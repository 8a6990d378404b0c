"""ros-tank-tutorial: the library behind the notebooks and the ``rtt-*`` programs.

Importing the package makes localhost-only ROS 2 discovery the default for this
process (see :mod:`tutorial.ros.env`), so a learner's first run never talks to
other machines.  Set ``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET`` before starting
a program to reach a real robot on your network.

It also makes the project's Fast DDS profile the default unless you named
one (``tutorial/ros/fastdds_profiles.xml``: reliable writers repair a lost
message within milliseconds; see :func:`tutorial.ros.env.use_project_profiles_by_default`).

On a class's JupyterHub (``course/``), it warns when ``ROS_DOMAIN_ID`` is not
the domain the hub gave the learner (:func:`tutorial.ros.env.assigned_domain_warning`).

It also makes EGL MuJoCo's OpenGL backend on Linux unless ``MUJOCO_GL`` is
set: Step 6's camera renders offscreen with it, with no display (Mesa's EGL
renders on the CPU where there is no GPU).  MuJoCo picks its backend when
``mujoco`` is first imported, so it must be set here, before that.
"""

import os as _os
import sys as _sys

from tutorial.ros import env as _ros_env

_ros_env.use_localhost_by_default()
_ros_env.use_project_profiles_by_default()
_ros_env.warn_if_not_assigned_domain()  # on a class's hub: ROS_DOMAIN_ID is the learner's own
if _sys.platform.startswith("linux"):  # elsewhere MUJOCO_GL=egl makes `import mujoco` fail
    _os.environ.setdefault("MUJOCO_GL", "egl")

__version__ = "0.1.0"
