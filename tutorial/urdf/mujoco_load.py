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
* a mesh named by a ``file://`` URI (what a published description carries)
  is read from that path; a ``package://`` mesh cannot be found without a
  ROS installation, and its visual is dropped (counted in the result).

The joints keep their names and types (revolute and prismatic with their
limits, continuous unlimited), so a JointState of the robot moves the model
by name.  Any thread may call it.
"""

from __future__ import annotations

from urllib.parse import unquote, urlparse

COMPILER = {
    "discardvisual": "false",
    "fusestatic": "false",
    "strippath": "false",
    "angle": "radian",
    "boundmass": "1e-6",
    "boundinertia": "1e-9",
}


def mujoco_text(urdf: str) -> tuple[str, int]:
    """``(text MuJoCo loads, visuals dropped)`` for a checked URDF (see the module text).

    Raises:
        ValueError: the text is not XML.
    """
    from lxml import etree

    try:
        root = etree.fromstring(urdf.encode("utf-8"), parser=etree.XMLParser(resolve_entities=False))
    except etree.XMLSyntaxError as exc:
        raise ValueError(f"not XML: {exc}") from None
    for element in list(root.iter("collision")):
        element.getparent().remove(element)
    dropped = 0
    for mesh in list(root.iter("mesh")):
        name = mesh.get("filename", "")
        if name.startswith("file://"):
            mesh.set("filename", unquote(urlparse(name).path))
        elif "://" in name:
            visual = next((a for a in mesh.iterancestors() if a.tag == "visual"), None)
            if visual is not None and visual.getparent() is not None:
                visual.getparent().remove(visual)
                dropped += 1
    for old in root.findall("mujoco"):
        root.remove(old)
    extension = etree.SubElement(root, "mujoco")
    etree.SubElement(extension, "compiler", attrib=COMPILER)
    return etree.tostring(root, encoding="unicode"), dropped


def load_description(urdf: str, source: str):
    """A received robot description, checked all the way to MuJoCo's text: ``(text, visuals dropped, tree)``.

    What a viewer does with ``std_msgs/String.data`` from a description
    topic: :func:`tutorial.interfaces.robot_description.check_robot_description`,
    then the joint tree (:class:`tutorial.urdf.kinematics.UrdfKinematics`)
    and :func:`mujoco_text`.  ``tree`` says how many links and moving joints
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
        text, dropped = mujoco_text(urdf)
    except ValueError as exc:
        raise DescriptionError(f"{source}: {exc}") from None
    return text, dropped, tree
