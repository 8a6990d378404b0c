"""URDF: a MuJoCo body as the stock ROS 2 tools describe a robot, and its transforms.

RViz2, Foxglove and ``robot_state_publisher`` know a robot from its URDF and
show it from TF.  One job per module:

=================================  ===============================================================
:mod:`tutorial.urdf.export`        a :class:`tutorial.core.body.Body` as a URDF (``rtt-urdf``),
                                   written with ``yourdfpy``; what it maps and what it cannot
:mod:`tutorial.urdf.kinematics`    a URDF's joints as transforms, as ``robot_state_publisher``
                                   computes them: fixed ones once, moving ones from a JointState
:mod:`tutorial.urdf.records`       a URDF as records (links, joints, shapes) and their XML
:mod:`tutorial.urdf.frames`        transforms as 4x4 matrices: MuJoCo's poses, URDF's roll-pitch-yaw
:mod:`tutorial.urdf.meshes`        a compiled MuJoCo mesh's triangles, spheres, binary STL files
:mod:`tutorial.urdf.mesh_files`    a description's ``package://`` meshes, found and made drawable
:mod:`tutorial.urdf.mujoco_load`   a URDF (a robot description received over ROS) as a MuJoCo model
=================================  ===============================================================

``rtt-bag record --tf`` computes ``/tf`` and ``/tf_static`` with these while it
records: :mod:`tutorial.bag.record_tf`.

No ROS import at module level here: the URDF and its kinematics are plain files and numbers.
"""
