"""URDF: a MuJoCo body as the stock ROS 2 tools describe a robot, and its transforms.

RViz2, Foxglove and ``robot_state_publisher`` know a robot from its URDF and
show it from TF.  One job per module:

===============  ===============================================================
``export``       a :class:`tutorial.core.body.Body` as a URDF (``rtt-urdf``),
                 written with ``yourdfpy``; what it maps and what it cannot
``kinematics``   a URDF's joints as transforms, as ``robot_state_publisher``
                 computes them: fixed ones once, moving ones from a JointState
``records``      a URDF as records (links, joints, shapes) and their XML
``frames``       transforms as 4x4 matrices: MuJoCo's poses, URDF's roll-pitch-yaw
``meshes``       a compiled MuJoCo mesh's triangles, spheres, binary STL files
``mesh_files``   a description's ``package://`` meshes, found and made drawable
``mujoco_load``  a URDF (a robot description received over ROS) as a MuJoCo model
===============  ===============================================================

``rtt-bag record --tf`` computes ``/tf`` and ``/tf_static`` with these while it
records: :mod:`tutorial.tools.bag.record_tf`.

No ROS import at module level here: the URDF and its kinematics are plain files and numbers.
"""
