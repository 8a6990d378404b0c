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
``mujoco`` is first imported, so it must be set here, before that.  Where
EGL's libraries are not installed (a minimal server or container), it turns
MuJoCo's OpenGL off instead: ``import mujoco`` would fail with EGL chosen and
no libEGL, and only the camera renders.  The camera then says what to install
(:data:`NO_OPENGL`).
"""

import ctypes as _ctypes
import os as _os
import sys as _sys

from tutorial.ros import env as _ros_env

_ros_env.use_localhost_by_default()
_ros_env.use_project_profiles_by_default()
_ros_env.warn_if_not_assigned_domain()  # on a class's hub: ROS_DOMAIN_ID is the learner's own
# What the camera says when MuJoCo's OpenGL was turned off for want of EGL's libraries.
NO_OPENGL = (
    "no OpenGL library for offscreen rendering (libEGL.so.1, libOpenGL.so.0): "
    "on Debian or Ubuntu, apt-get install libegl1 libopengl0 libgl1-mesa-dri"
)


def _egl_installed() -> bool:
    try:
        for name in ("libEGL.so.1", "libOpenGL.so.0"):  # what MuJoCo's EGL backend opens
            _ctypes.CDLL(name)
    except OSError:
        return False
    return True


if _sys.platform.startswith("linux") and "MUJOCO_GL" not in _os.environ:  # elsewhere egl makes `import mujoco` fail
    _os.environ["MUJOCO_GL"] = "egl" if _egl_installed() else "disable"

__version__ = "0.1.0"
