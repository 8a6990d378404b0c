"""A robot description (URDF) as MuJoCo model text, for a viewer that has no model file of its own.

MuJoCo reads URDF itself.  :func:`mujoco_text` prepares a received
description for it, for *drawing* (a viewer never simulates it, so a
description's physics never stops it):

* ``<collision>`` elements are dropped: MuJoCo would make a second geom of
  each, drawn over the visual one (and load meshes a viewer never shows);
* a ``<mujoco><compiler .../></mujoco>`` element asks MuJoCo to keep the
  visuals (its URDF default discards them), to keep fixed links as bodies of
  their own (its default merges them into their parents), to read mesh paths
  as they are, to take a link's mass from its ``<inertial>`` only (a visual
  never adds mass), and to give a massless link a tiny mass (a joint frame
  of :mod:`tutorial.tools.urdf.export` has none, and MuJoCo refuses a massless
  moving body);
* an inertia MuJoCo refuses (principal moments with ``A + B < C``, or not
  positive, common in real robots' files) is replaced by a valid one, the
  mean of its principal moments about every axis, and the link is named in
  :attr:`MujocoText.changed`;
* each mesh is found as ROS finds it (``package://`` under
  ``AMENT_PREFIX_PATH`` and ``ROS_PACKAGE_PATH``, ``file://``) and, in a
  format MuJoCo does not read (Collada), converted to STL files, one per
  colour; one over MuJoCo's 200,000 triangles is simplified
  (:mod:`tutorial.tools.urdf.mesh_files`);
* a mesh's inertia is its surface's (MuJoCo's ``inertia="shell"``), which
  only places the mesh in its geom: a thin or open visual mesh has no volume
  for MuJoCo's default to measure ("mesh volume is too small");
* a mesh that cannot be found or read, or that MuJoCo still refuses, leaves
  its visual out, with one line saying which and why, and the rest of the
  robot is drawn;
* Gazebo, ``ros2_control`` and transmission elements are dropped: they
  describe a simulator's plugins and a robot's hardware, not its shape.

The result is URDF that :func:`tutorial.core.world.drawing_spec` compiles,
as the world does (compiled here once, so what cannot be drawn is found
here, not in the world).
The joints keep their names and types (revolute and prismatic with their
limits, continuous unlimited), so a JointState of the robot moves the model
by name.  Any thread may call it.
"""

from __future__ import annotations

import re
from typing import NamedTuple

COMPILER = {
    "discardvisual": "false",
    "fusestatic": "false",
    "strippath": "false",
    "angle": "radian",
    "boundmass": "1e-6",
    "boundinertia": "1e-9",
    "inertiafromgeom": "false",  # a visual never adds mass: a link is what its <inertial> says, or the bounds
    # an inertia within rounding of A + B = C, which the check below lets through: MuJoCo evens it out
    "balanceinertia": "true",
}
_MATCHING = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


class MujocoText(NamedTuple):
    """What :func:`mujoco_text` made of a description."""

    text: str  # the prepared URDF, for tutorial.core.world.drawing_spec
    left_out: list[str]  # one line per visual not drawn: "link L: visual left out: why"
    changed: list[str]  # one line per kind of change made to draw it (inertias replaced, meshes simplified)


def mujoco_text(urdf: str, environ=None, cache=None) -> MujocoText:
    """The description as URDF MuJoCo compiles for drawing, with what was left out or changed (see the module text).

    ``environ`` (``os.environ`` when None) gives ``AMENT_PREFIX_PATH`` and
    ``ROS_PACKAGE_PATH``; ``cache`` the folder of converted meshes.

    Raises:
        ValueError: the text is not XML, or MuJoCo cannot read or compile it
            for a reason other than a mesh (MuJoCo's message, one line).
    """
    import copy

    from lxml import etree

    from tutorial.tools.urdf.mesh_files import MAX_FACES, MeshError, drawable_meshes, resolve_mesh

    try:
        root = etree.fromstring(urdf.encode("utf-8"), parser=etree.XMLParser(resolve_entities=False))
    except etree.XMLSyntaxError as exc:
        raise ValueError(f"not XML: {exc}") from None
    for tag in ("collision", "gazebo", "transmission", "ros2_control"):
        for element in list(root.iter(tag)):
            element.getparent().remove(element)
    changed = []
    replaced = _replace_refused_inertias(root)
    if replaced:
        changed.append(
            f"the inertia of {_count(replaced, 'link', 'links')} replaced, which MuJoCo refuses ({_names(replaced)})"
        )
    left_out, simplified, visuals = [], [], {}
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
        for i, part in enumerate(parts):
            if part.simplified_from is not None:
                said = f"{mesh.get('filename', '').rsplit('/', 1)[-1]} had {part.simplified_from:,}"
                simplified += [] if said in simplified else [said]  # a file drawn twice is said once
            drawn = visual if i == len(parts) - 1 else copy.deepcopy(visual)
            if drawn is not visual:
                visual.addprevious(drawn)
            visuals.setdefault(str(part.path), (link, mesh.get("filename", ""), []))[2].append(drawn)
            next(drawn.iter("mesh")).set("filename", str(part.path))
            if part.rgba is not None:  # the file's own colour for this part, over the visual's
                for old in drawn.findall("material"):
                    drawn.remove(old)
                material = etree.SubElement(drawn, "material", name=f"rtt_mesh{n}_part{i}")
                etree.SubElement(material, "color", rgba=" ".join(f"{c:g}" for c in part.rgba))
    if simplified:
        changed.append(
            f"{_count(simplified, 'mesh', 'meshes')} over MuJoCo's {MAX_FACES:,} triangles simplified to that many "
            f"({_names(simplified)})"
        )
    for old in root.findall("mujoco"):
        root.remove(old)
    extension = etree.SubElement(root, "mujoco")
    etree.SubElement(extension, "compiler", attrib=COMPILER)
    _leave_out_refused_meshes(root, visuals, left_out)
    return MujocoText(etree.tostring(root, encoding="unicode"), left_out, changed)


def _replace_refused_inertias(root) -> list[str]:
    """Give each link whose ``<inertia>`` MuJoCo would refuse a valid one; the links' names.

    MuJoCo's checks, as its compiler makes them (4.0, measured): MuJoCo
    reads a URDF inertia as a full matrix, whose eigenvalues (the principal
    moments) must be at least -1e-14; then the principal moments, each
    raised to ``boundinertia``, must satisfy ``A + B >= C``.  A value that
    is not a number is left for MuJoCo's parser to name.  (Within rounding
    of ``A + B = C`` the two may disagree: ``balanceinertia`` evens out what
    this lets through.)
    """
    import numpy as np

    bound, replaced = float(COMPILER["boundinertia"]), []
    for link in root.iter("link"):
        inertia = link.find("inertial/inertia")
        if inertia is None:
            continue
        try:
            xx, xy, xz, yy, yz, zz = (float(inertia.get(k, "0")) for k in _MATCHING)
        except ValueError:
            continue
        matrix = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        if not np.isfinite(matrix).all():
            continue
        moments = np.linalg.eigvalsh(matrix)  # ascending
        a, b, c = np.maximum(moments, bound)
        if moments[0] < -1e-14 or a + b < c:
            mean = max(float(np.abs(moments).mean()), bound)
            for k, value in zip(_MATCHING, (mean, 0.0, 0.0, mean, 0.0, mean), strict=True):
                inertia.set(k, repr(value))
            replaced.append(link.get("name", "?"))
    return replaced


def _leave_out_refused_meshes(root, visuals: dict, left_out: list[str]) -> None:
    """Compile the prepared URDF as the world will (each mesh's inertia its surface's); a mesh MuJoCo's
    compiler refuses leaves its visuals out of ``root`` (a line in ``left_out``, naming the description's
    file), and the rest is compiled again.

    ``visuals`` maps each drawn file to ``(link, the description's URI, [visual elements])``.
    """
    import warnings

    from lxml import etree

    from tutorial.core.world import drawing_spec

    with warnings.catch_warnings():  # MuJoCo's notes on a URDF (a repeated geom name, an ignored mimic)
        warnings.simplefilter("ignore")
        try:
            spec = drawing_spec(etree.tostring(root, encoding="unicode"))
        except ValueError as exc:
            raise ValueError(f"MuJoCo cannot read it: {_one_line(exc)}") from None
        while True:
            try:
                spec.compile()
                return
            except ValueError as exc:
                reason = _one_line(exc)
                mesh = next((m for m in spec.meshes if _names_mesh(reason, m)), None)
                if mesh is None or mesh.file not in visuals:  # not a mesh of a visual: nothing to leave out
                    raise ValueError(f"MuJoCo cannot compile it: {reason}") from None
                link, uri, elements = visuals[mesh.file]
                for geom in [g for g in spec.geoms if g.meshname == mesh.name]:
                    spec.delete(geom)
                spec.delete(mesh)
                for element in elements:
                    if element.getparent() is not None:
                        element.getparent().remove(element)
                left_out.append(f"link {link}: visual left out: {uri}: MuJoCo refuses it ({reason})")


def _names_mesh(reason: str, mesh) -> bool:
    """Whether MuJoCo's error names ``mesh``: by its name (a word of its own) or its file."""
    return bool(re.search(rf"(?<![\w.]){re.escape(mesh.name)}(?![\w.])", reason)) or mesh.file in reason


def _one_line(exc: Exception) -> str:
    return " ".join(str(exc).split()).removeprefix("Error: ")


def _count(items: list, noun: str, nouns: str) -> str:
    return f"{len(items)} {noun if len(items) == 1 else nouns}"


def _names(items: list[str], shown: int = 4) -> str:
    return ", ".join(items[:shown]) + (f" and {len(items) - shown} more" if len(items) > shown else "")


def load_description(urdf: str, source: str):
    """A received robot description, checked all the way to MuJoCo's text: ``(MujocoText, tree)``.

    What a viewer does with ``std_msgs/String.data`` from a description
    topic: :func:`tutorial.interfaces.robot_description.check_robot_description`,
    then the joint tree (:class:`tutorial.tools.urdf.kinematics.UrdfKinematics`)
    and :func:`mujoco_text` (the text, the visuals left out and what was
    changed to draw it); ``tree`` says how many links and moving joints it
    has.  Any thread.

    Raises:
        tutorial.interfaces.robot_description.DescriptionError: any of those
            refused it; the message names ``source`` (the topic) and why.
    """
    from tutorial.interfaces.robot_description import DescriptionError, check_robot_description
    from tutorial.tools.urdf.kinematics import UrdfKinematics

    check_robot_description(urdf, source)
    try:
        tree = UrdfKinematics(urdf)
        prepared = mujoco_text(urdf)
    except ValueError as exc:
        raise DescriptionError(f"{source}: {exc}") from None
    return prepared, tree
