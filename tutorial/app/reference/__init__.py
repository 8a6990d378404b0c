"""Frozen references: the earlier steps' worked solutions that later steps stand on.

Step 2's project drives the tank with Step 1's controller, Step 5's shows the
joint state with Step 3's monitor, Step 6's publishes the joint state as Step 2
does.  Those later steps (their notebooks, their checks and their project files)
use the copies here, never the lesson modules of :mod:`tutorial.controllers`:
editing one step's notebook and running ``make export`` changes that step and
no other (``tests/test_step_independence.py`` holds it).

Each module is a copy of a lesson module as it stood when it was frozen, made by
``scripts/freeze_reference.py`` (its first line names the notebook it came
from).  To have the later steps stand on a changed lesson, freeze it again, on
purpose.  Nothing here is a lesson: edit the notebook, never these copies.

==========================  ========  ===========================================
module                      step      what the later steps use it for
==========================  ========  ===========================================
``tank_controller``         1         the tank driven from ``/joy`` (Steps 2 to 9)
``joint_state_publisher``   2         ``/Tank/joint_state`` (Steps 4 to 6)
``joint_state_subscriber``  3         the joint-state monitor (Step 5's viewer)
``imu_state_publisher``     4         ``/Tank/imu`` (notebook 05's simulation)
``camera_image_publisher``  6         ``/Tank/camera/image`` (notebook 08's two hosts)
``robot_model_publisher``   9         ``/Tank/robot_description`` and ``/Tank/odom``
                                      for the stock ROS 2 tools (rtt-run --describe,
                                      notebooks 10 and 11)
==========================  ========  ===========================================
"""
