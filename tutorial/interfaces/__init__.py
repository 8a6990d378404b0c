"""The ROS interfaces the project speaks: one module per message.

Each module holds its topic's name, its QoS and why, the units, and the
checks on received data, so every step, tool and test that uses the topic
agrees on it, and editing one step's notebook changes no other step.

=======================  ============================================================================
module                   message
=======================  ============================================================================
``joy``                  ``/joy``, ``sensor_msgs/Joy``: axes and buttons, their checks
``joint_state``          ``/<body>/joint_state``, ``sensor_msgs/JointState``; matching by name
``imu``                  ``/<body>/imu``, ``sensor_msgs/Imu``; finding a body's IMU; its checks
``image``                ``/<body>/camera/image``, ``sensor_msgs/Image``; reading one safely
``compressed_image``     ``/<body>/camera/image/compressed``, ``sensor_msgs/CompressedImage``: JPEG, PNG
``robot_description``    ``/<body>/robot_description``, ``std_msgs/String``: the URDF; its checks
``odometry``             ``/<body>/odom``, ``nav_msgs/Odometry``: the root link's pose and velocity
``tf``                   ``/tf``, ``/tf_static``, ``tf2_msgs/msg/TFMessage``: encoded from its definition
                         (no wheel ships it: the text is kept in ``share/``)
``timing``               simulation-time stamps on the wire
``definitions``          message definitions as rosbag2 stores them; message classes by type name
=======================  ============================================================================

When each periodic message is due is :mod:`tutorial.core.period`.
"""
