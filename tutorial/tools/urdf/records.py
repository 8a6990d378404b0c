"""A URDF as records (links, joints, shapes, inertials) and their XML, written with ``lxml``.

:func:`tutorial.tools.urdf.export.export_body` fills the records from a MuJoCo body;
:meth:`UrdfExport.xml` and :meth:`UrdfExport.write` write them.  Any thread may
use them: nothing here is shared.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tutorial.tools.urdf.frames import rpy_from_matrix
from tutorial.tools.urdf.meshes import write_stl

ROOT_FREE, ROOT_FIXED, ROOT_WORLD = "free", "fixed", "world"
ELLIPSOID_MESH = "ellipsoid.stl"
MOVING = ("revolute", "continuous", "prismatic")


@dataclass
class Geometry:
    """One URDF ``<geometry>``: ``kind`` is ``box`` (``size``: full x, y, z, m), ``cylinder``
    (``size``: radius, length), ``sphere`` (``size``: radius) or ``mesh`` (``filename``, ``scale``)."""

    kind: str
    size: tuple[float, ...] = ()
    filename: str = ""
    scale: tuple[float, float, float] | None = None


@dataclass
class Shape:
    """A ``<visual>`` or ``<collision>``: its name, pose in the link (4x4, m), geometry, and
    colour (rgba, visuals only)."""

    name: str
    origin: np.ndarray
    geometry: Geometry
    rgba: tuple[float, float, float, float] | None = None


@dataclass
class Inertial:
    """``<inertial>``: the centre of mass and principal axes (4x4), mass (kg), principal inertia (3,) kg m^2."""

    origin: np.ndarray
    mass: float
    inertia: tuple[float, float, float]


@dataclass
class Link:
    """A URDF link: a MuJoCo body (or a joint frame between two joints of one body)."""

    name: str
    inertial: Inertial | None = None
    visuals: list[Shape] = field(default_factory=list)
    collisions: list[Shape] = field(default_factory=list)


@dataclass
class Joint:
    """A URDF joint: ``type`` fixed, revolute, continuous, prismatic or floating; ``origin``
    (4x4) places the child in the parent at 0; limits in rad or m, ``effort`` N*m or N,
    ``damping`` and ``friction`` from MuJoCo's ``damping`` and ``frictionloss``."""

    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: tuple[float, float, float] | None = None
    lower: float | None = None
    upper: float | None = None
    effort: float = 0.0
    velocity: float = 0.0
    damping: float = 0.0
    friction: float = 0.0


@dataclass
class UrdfExport:
    """A body as a URDF, before it is written.

    Attributes:
        name: the robot's name.
        links: every link, the root first.
        joints: every joint, in model order.
        root_link: the name of the URDF's root link.
        root_kind: ``free`` (the root body's free joint: its pose is the odometry),
            ``fixed`` (the root body is welded to the world) or ``world`` (a link
            for the world frame, see the module text).
        body_links: MuJoCo body id (in the world model) -> its link's name.
        moving_joints: the URDF's revolute, continuous and prismatic joints, in
            model order: the body's numbered joints (``Body.joint_names``).
        root_body: the MuJoCo id of the root link's body; None when the root
            link stands for the world frame (``root_kind`` ``world``).
        meshes: STL file name -> ``(vertices (n, 3) m, faces (k, 3))`` to write beside the URDF.
        notes: what was approximated or left out, one line each.
    """

    name: str
    links: list[Link]
    joints: list[Joint]
    root_link: str
    root_kind: str
    body_links: dict[int, str]
    moving_joints: list[str]
    root_body: int | None = None
    meshes: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def xml(self, mesh_prefix: str = "", source: str = "") -> str:
        """The URDF as text, mesh files named ``mesh_prefix + name`` (e.g. ``tank_meshes/``).

        ``source`` is named in the opening comment (e.g. the model file).
        Numbers are written as Python's shortest exact text (``repr``), so
        reading the file back gives the same floats.
        """
        from lxml import etree

        robot = etree.Element("robot", name=self.name)
        robot.append(etree.Comment(self.comment(source)))
        for link in self.links:
            element = etree.SubElement(robot, "link", name=link.name)
            if link.inertial is not None:
                inertial = etree.SubElement(element, "inertial")
                _origin(inertial, link.inertial.origin)
                etree.SubElement(inertial, "mass", value=_num(link.inertial.mass))
                ixx, iyy, izz = link.inertial.inertia
                attrib = {"ixx": ixx, "ixy": 0.0, "ixz": 0.0, "iyy": iyy, "iyz": 0.0, "izz": izz}
                etree.SubElement(inertial, "inertia", {k: _num(v) for k, v in attrib.items()})
            for tag, shapes in (("visual", link.visuals), ("collision", link.collisions)):
                for shape in shapes:
                    child = etree.SubElement(element, tag, name=shape.name)
                    _origin(child, shape.origin)
                    _geometry(etree.SubElement(child, "geometry"), shape.geometry, mesh_prefix)
                    if shape.rgba is not None:
                        material = etree.SubElement(child, "material", name=shape.name)
                        etree.SubElement(material, "color", rgba=" ".join(_num(c) for c in shape.rgba))
        for joint in self.joints:
            element = etree.SubElement(robot, "joint", name=joint.name, type=joint.type)
            etree.SubElement(element, "parent", link=joint.parent)
            etree.SubElement(element, "child", link=joint.child)
            _origin(element, joint.origin)
            if joint.type in MOVING:
                etree.SubElement(element, "axis", xyz=" ".join(_num(a) for a in joint.axis))
                limit = {"effort": _num(joint.effort), "velocity": _num(joint.velocity)}
                if joint.lower is not None:
                    limit.update(lower=_num(joint.lower), upper=_num(joint.upper))
                etree.SubElement(element, "limit", limit)
                if joint.damping or joint.friction:
                    etree.SubElement(element, "dynamics", damping=_num(joint.damping), friction=_num(joint.friction))
        text = etree.tostring(robot, xml_declaration=True, pretty_print=True, encoding="utf-8")
        return text.decode("utf-8")

    def comment(self, source: str = "") -> str:
        """The file's opening comment: where it came from, its root, what was left out."""
        lines = [
            f" Written by rtt-urdf (ros-tank-tutorial) from {source or 'a MuJoCo model'}: robot {self.name}. ",
            f" Root link {self.root_link} ({_ROOT_TEXT[self.root_kind]}). ",
            f" Joints moved by /{self.name}/joint_state: {', '.join(self.moving_joints) or 'none'}. ",
        ]
        if self.notes:
            lines.append(" Approximated or left out: ")
            lines += [f"   {n} " for n in self.notes]
        return "\n" + "\n".join(lines).replace("--", "- -") + "\n"

    def description(self, mesh_folder=None, source: str = "") -> str:
        """The URDF as a robot description to publish: mesh files named by ``file://`` URIs.

        A description travels as text, without its files: a reader on this
        machine finds the meshes by absolute URI (RViz2 and Foxglove read
        ``file://``).  The meshes are written into ``mesh_folder`` (a new
        temporary folder when None and the body has meshes).
        """
        if not self.meshes:
            return self.xml(source=source)
        import tempfile

        folder = Path(mesh_folder) if mesh_folder is not None else Path(tempfile.mkdtemp(prefix="rtt-urdf-meshes-"))
        folder.mkdir(parents=True, exist_ok=True)
        for name, (vertices, faces) in self.meshes.items():
            write_stl(folder / name, vertices, faces)
        return self.xml(folder.resolve().as_uri() + "/", source)

    def write(self, path, mesh_uri: str = "relative", source: str = "") -> list[Path]:
        """Write the URDF to ``path`` and its meshes to ``<stem>_meshes/`` beside it; the files written.

        Args:
            path: the ``.urdf`` file.
            mesh_uri: how the URDF names the mesh files: ``relative`` (to the
                URDF's folder, which ``yourdfpy`` and MuJoCo read) or ``file``
                (``file:///absolute/path``, which RViz2 and Foxglove read).
            source: named in the file's opening comment.

        Raises:
            ValueError: an unknown ``mesh_uri``.
            OSError: a file cannot be written.
        """
        if mesh_uri not in ("relative", "file"):
            raise ValueError(f"mesh_uri {mesh_uri!r}: use 'relative' or 'file'")
        path = Path(path)
        folder = path.with_name(path.stem + "_meshes")
        written = []
        if self.meshes:
            folder.mkdir(parents=True, exist_ok=True)
            for name, (vertices, faces) in self.meshes.items():
                written.append(write_stl(folder / name, vertices, faces))
        prefix = f"{folder.name}/" if mesh_uri == "relative" else folder.resolve().as_uri() + "/"
        path.write_text(self.xml(prefix, source), encoding="utf-8")
        return [path, *written]


_ROOT_TEXT = {
    ROOT_FREE: "the body's free joint: its pose in the world is the odometry",
    ROOT_FIXED: "welded to the world",
    ROOT_WORLD: "the world frame the model is placed in",
}


def _num(value: float) -> str:
    """A number as its shortest exact text (``0.1``, ``-6.283185307179586``); -0.0 as 0.0."""
    value = float(value)
    return repr(value + 0.0)


def _origin(parent, matrix: np.ndarray) -> None:
    from lxml import etree

    xyz = " ".join(_num(v) for v in matrix[:3, 3])
    rpy = " ".join(_num(v) for v in rpy_from_matrix(matrix))
    etree.SubElement(parent, "origin", xyz=xyz, rpy=rpy)


def _geometry(parent, geometry: Geometry, mesh_prefix: str) -> None:
    from lxml import etree

    if geometry.kind == "box":
        etree.SubElement(parent, "box", size=" ".join(_num(v) for v in geometry.size))
    elif geometry.kind == "cylinder":
        etree.SubElement(parent, "cylinder", radius=_num(geometry.size[0]), length=_num(geometry.size[1]))
    elif geometry.kind == "sphere":
        etree.SubElement(parent, "sphere", radius=_num(geometry.size[0]))
    else:
        attrib = {"filename": mesh_prefix + geometry.filename}
        if geometry.scale is not None:
            attrib["scale"] = " ".join(_num(v) for v in geometry.scale)
        etree.SubElement(parent, "mesh", attrib)
