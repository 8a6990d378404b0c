"""A robot description (URDF) as MuJoCo model text, for a viewer that has no model file of its own.

MuJoCo reads URDF itself.  :func:`mujoco_text` prepares a received
description for it, for *drawing* (a viewer never simulates it):

* ``<collision>`` elements are dropped: MuJoCo would make a second geom of
  each, drawn over the visual one;
* a ``<mujoco><compiler .../></mujoco>`` element asks MuJoCo to keep the
  visuals (its URDF default discards them), to keep fixed links as bodies of
  their own (its default merges them into their parents), to read mesh paths
  as they are, and to give a massless link a tiny mass (a joint frame of
  :mod:`tutorial.urdf.export` has none, and MuJoCo refuses a massless moving
  body);
* each mesh is found as ROS finds it (``package://`` under
  ``AMENT_PREFIX_PATH`` and ``ROS_PACKAGE_PATH``, ``file://``) and, in a
  format MuJoCo does not read (Collada), converted to STL files, one per
  colour (:mod:`tutorial.urdf.mesh_files`); a mesh that cannot be found or
  read leaves its visual out, with one line saying which and why, and the
  rest of the robot is drawn;
* Gazebo, ``ros2_control`` and transmission elements are dropped: they
  describe a simulator's plugins and a robot's hardware, not its shape.

The joints keep their names and types (revolute and prismatic with their
limits, continuous unlimited), so a JointState of the robot moves the model
by name.  Any thread may call it.
"""

from __future__ import annotations

COMPILER = {
    "discardvisual": "false",
    "fusestatic": "false",
    "strippath": "false",
    "angle": "radian",
    "boundmass": "1e-6",
    "boundinertia": "1e-9",
}


def mujoco_text(urdf: str, environ=None, cache=None) -> tuple[str, list[str]]:
    """``(text MuJoCo loads, one line per visual left out)`` for a checked URDF (see the module text).

    ``environ`` (``os.environ`` when None) gives ``AMENT_PREFIX_PATH`` and
    ``ROS_PACKAGE_PATH``; ``cache`` the folder of converted meshes.

    Raises:
        ValueError: the text is not XML.
    """
    import copy

    from lxml import etree

    from tutorial.urdf.mesh_files import MeshError, drawable_meshes, resolve_mesh

    try:
        root = etree.fromstring(urdf.encode("utf-8"), parser=etree.XMLParser(resolve_entities=False))
    except etree.XMLSyntaxError as exc:
        raise ValueError(f"not XML: {exc}") from None
    for tag in ("collision", "gazebo", "transmission", "ros2_control"):
        for element in list(root.iter(tag)):
            element.getparent().remove(element)
    left_out = []
    for n, mesh in enumerate(list(root.iter("mesh"))):
        visual = next((a for a in mesh.iterancestors() if a.tag == "visual"), None)
        if visual is None or visual.getparent() is None:
            continue
        link = visual.getparent().get("name", "?")
        try:
            parts = drawable_meshes(resolve_mesh(mesh.get("filename", ""), environ), cache)
        except (MeshError, OSError) as exc:
            visual.getparent().remove(visual)
            left_out.append(f"link {link}: visual left out: {exc}")
            continue
        for i, (path, rgba) in enumerate(parts):
            part = visual if i == len(parts) - 1 else copy.deepcopy(visual)
            if part is not visual:
                visual.addprevious(part)
            part_mesh = next(part.iter("mesh"))
            part_mesh.set("filename", str(path))
            if rgba is not None:  # the file's own colour for this part, over the visual's
                for old in part.findall("material"):
                    part.remove(old)
                material = etree.SubElement(part, "material", name=f"rtt_mesh{n}_part{i}")
                etree.SubElement(material, "color", rgba=" ".join(f"{c:g}" for c in rgba))
    for old in root.findall("mujoco"):
        root.remove(old)
    extension = etree.SubElement(root, "mujoco")
    etree.SubElement(extension, "compiler", attrib=COMPILER)
    return etree.tostring(root, encoding="unicode"), left_out


def load_description(urdf: str, source: str):
    """A received robot description, checked all the way to MuJoCo's text: ``(text, visuals left out, tree)``.

    What a viewer does with ``std_msgs/String.data`` from a description
    topic: :func:`tutorial.interfaces.robot_description.check_robot_description`,
    then the joint tree (:class:`tutorial.urdf.kinematics.UrdfKinematics`)
    and :func:`mujoco_text`.  ``visuals left out`` holds one line per mesh
    that could not be drawn; ``tree`` says how many links and moving joints
    it has.  Any thread.

    Raises:
        tutorial.interfaces.robot_description.DescriptionError: any of those
            refused it; the message names ``source`` (the topic) and why.
    """
    from tutorial.interfaces.robot_description import DescriptionError, check_robot_description
    from tutorial.urdf.kinematics import UrdfKinematics

    check_robot_description(urdf, source)
    try:
        tree = UrdfKinematics(urdf)
        text, left_out = mujoco_text(urdf)
    except ValueError as exc:
        raise DescriptionError(f"{source}: {exc}") from None
    return text, left_out, tree
