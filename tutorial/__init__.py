"""ros-tank-tutorial: the library behind the notebooks and the ``rtt-*`` programs.

Importing the package makes localhost-only ROS 2 discovery the default for this
process (see :mod:`tutorial.ros_env`), so a learner's first run never talks to
other machines.  Set ``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET`` before starting
a program to reach a real robot on your network.
"""

from tutorial import ros_env as _ros_env

_ros_env.use_localhost_by_default()

__version__ = "0.1.0"
