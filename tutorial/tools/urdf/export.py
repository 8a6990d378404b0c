"""A body of a MuJoCo model as a URDF: what ``rtt-urdf`` writes and the simulation publishes.

:func:`export_body` reads a :class:`tutorial.core.body.Body` (the compiled
``MjModel``, never the MJCF text) into a small tree of :class:`Link` and
:class:`Joint` records, which :meth:`UrdfExport.xml` writes as URDF XML with
``lxml``.  Why not ``yourdfpy``'s writer: importing ``yourdfpy`` takes about
1 s (it imports ``trimesh``), which every simulation that publishes its
description would pay at start-up, and its writer drops ``<dynamics>``.
``yourdfpy`` is the *reader* instead: the tests load every written file
with it and compare its forward kinematics with MuJoCo's, so the file is
checked by a parser we did not write, and :mod:`tutorial.tools.urdf.kinematics`
reads received descriptions with it.  Names are the body's own: a link per MuJoCo
body, named as the body is (without the world's ``Tank/`` prefix; unnamed
ones by :func:`tutorial.core.world.name_unnamed_elements`'s rule), a joint per
MuJoCo joint, named as the joint is, so a ``JointState`` of the body moves
the URDF's joints by name (``robot_state_publisher``).

What it maps, exactly (a URDF link's pose equals MuJoCo's body pose for any
values of the numbered joints; ``tests/test_urdf.py`` checks it with
``yourdfpy``'s own forward kinematics on the tank and on third-party models):

==========================  ==============================================================
MuJoCo                      URDF
==========================  ==============================================================
the body's root             the *root link*: the one top-level body, when its joint is a
                            free joint (the tank's ``CHASSIS``: its pose is the body's
                            odometry, ``/<body>/odom``) or when it has no joint (welded to
                            the world); otherwise a link ``<robot>_world`` standing for
                            the world frame the model is placed in (its odometry is the
                            identity), with the top-level bodies hanging from it
hinge, numbered             ``revolute`` with ``lower``/``upper`` when limited, else
                            ``continuous``; the axis; MuJoCo's reference angle (``ref``,
                            ``qpos0``) is folded into the joint's origin, so the URDF joint
                            takes the same value JointState carries
slide, numbered             ``prismatic``, axis, ``lower``/``upper`` when limited (an
                            unlimited slide gets +-1e6 m: URDF has no unlimited prismatic
                            joint)
a joint off the body's      a joint turns or slides about an anchor (``pos``) that need not
origin, several joints      be the body's origin, and a MuJoCo body may have several joints:
on one body                 each becomes a URDF joint whose child is a link
                            ``<joint>_frame``, and a fixed joint ``<body>_offset`` carries
                            the rest to the body's own link, so every link is the body's frame
a body with no joint        a ``fixed`` joint ``<parent>_to_<body>``
joint group 3, ball joint   ``fixed`` at the reference position (``qpos0``): JointState does
                            not carry them (``Body.skipped_joints``), so
                            ``robot_state_publisher`` could not move them, and a moving joint
                            without a state leaves its links with no transform (RViz2:
                            "No transform from ..."); the Step 3 viewer shows them there too.
                            The tank's road wheels turn about their own axes: as drawn,
                            cylinders, they look the same at any angle
a free joint off the root   ``floating`` at its reference pose (no topic carries its pose;
                            ``robot_state_publisher`` moves no floating joint either)
mass, centre of mass,       ``<inertial>``: mass, origin at the centre of mass turned to the
inertia                     principal axes, the diagonal principal inertia
box, cylinder, sphere       ``<box>`` (full sizes), ``<cylinder>`` (radius, full length),
                            ``<sphere>``: exact
capsule                     a cylinder and two spheres: the same shape, exactly
ellipsoid                   a unit-sphere mesh (``ellipsoid.stl``, 482 vertices) scaled by
                            the radii: an approximation of the surface
plane                       a box 2 mm thick under the plane (20 m wide where MuJoCo's
                            size is 0, infinite)
mesh                        the compiled mesh (MuJoCo's vertices and faces, in the frame
                            the compiler moved it to) as a binary STL file beside the URDF
colours                     each visual's ``<material>``: the geom's rgba, or its MuJoCo
                            material's (as the meshcat viewer draws it)
visual / collision          a geom in groups 0-2 is a ``<visual>`` (groups 3 and up are
                            hidden, as in MuJoCo's viewer and ours); a geom that collides
                            (``contype`` or ``conaffinity`` not 0) is a ``<collision>``
==========================  ==============================================================

What it cannot map, and leaves out (each is listed in the file's opening
comment and in :attr:`UrdfExport.notes`): height fields and SDF geoms;
geoms the model fixes to the world when the root is free (a floor is not
part of a robot that drives on it); sites, cameras and lights; tendons,
actuators (transmissions) and equality constraints (the tank's wheels turning
together); armature; contact parameters; velocity limits (URDF's ``velocity`` is
written 0: MuJoCo has none) and an effort limit the model does not give
(``effort`` 0).  A floating joint's motion.  (Joint damping and friction
loss are written, as ``<dynamics>``.)  Any thread may call these functions:
they only read the model.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from tutorial.core.body import Body
from tutorial.tools.urdf.frames import is_identity, pose_matrix, rotation, translation
from tutorial.tools.urdf.meshes import compiled_mesh, unit_sphere
from tutorial.tools.urdf.records import (
    ELLIPSOID_MESH,
    MOVING,
    ROOT_FIXED,
    ROOT_FREE,
    ROOT_WORLD,
    Geometry,
    Inertial,
    Joint,
    Link,
    Shape,
    UrdfExport,
)

HIDDEN_GEOM_GROUP = 3  # as tutorial.view.scene: groups 3 and up are not drawn
PLANE_THICKNESS = 0.002  # m
INFINITE_PLANE = 10.0  # m, the half size given to a plane MuJoCo makes infinite
UNLIMITED_SLIDE = 1e6  # m

_T = mujoco.mjtGeom
_JNT = mujoco.mjtJoint


def export_body(body: Body, robot_name: str | None = None) -> UrdfExport:
    """The body as a URDF (see the module text for the mapping).

    Args:
        body: the body, in a world from :func:`tutorial.core.world.build_world`.
        robot_name: the URDF's robot name; the body's name by default.

    Returns:
        The :class:`UrdfExport`; :meth:`UrdfExport.xml` or :meth:`UrdfExport.write` writes it.

    Raises:
        ValueError: the body has no link (a model of static geoms only, a room).
    """
    if not body.root_ids:
        raise ValueError(
            f"body {body.name} has no link (its model only fixes geoms to the world): no robot to describe"
        )
    return _Builder(body, robot_name or body.name).build()


class _Builder:
    def __init__(self, body: Body, name: str):
        self.body, self.m, self.name = body, body.model, name
        self.links: dict[int, str] = {}
        self.link_objects: dict[str, Link] = {}
        self.joints: list[Joint] = []
        self.joint_names: set[str] = set()
        self.meshes: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self.notes: list[str] = []
        self.numbered = {info.joint_id: info for info in body.joint_infos}

    # names
    def local(self, obj, i: int) -> str:
        full = mujoco.mj_id2name(self.m, obj, i) or ""
        return full[len(self.body.prefix) :] if full.startswith(self.body.prefix) else full

    def unique_link(self, name: str) -> str:
        taken = set(self.link_objects) | {self.local(mujoco.mjtObj.mjOBJ_BODY, b) for b in self.body.body_ids}
        out, n = name, 0
        while out in taken:
            n += 1
            out = f"{name}_{n}"
        return out

    def unique_joint(self, name: str, own: bool = False) -> str:
        """``name`` for a joint: a MuJoCo joint's own name (``own``) as it is, any other made unique."""
        if own:
            self.joint_names.add(name)
            return name
        reserved = {self.local(mujoco.mjtObj.mjOBJ_JOINT, j) for j in self.body.joint_ids}
        out, n = name, 0
        while out in self.joint_names or out in reserved:
            n += 1
            out = f"{name}_{n}"
        self.joint_names.add(out)
        return out

    def add_link(self, name: str) -> Link:
        link = Link(name=name)
        self.link_objects[name] = link
        return link

    # the tree
    def build(self) -> UrdfExport:
        m, body = self.m, self.body
        roots = body.root_ids
        first_joint = int(m.body_jntadr[roots[0]]) if m.body_jntnum[roots[0]] else -1
        root_body = None
        if len(roots) == 1 and first_joint >= 0 and m.jnt_type[first_joint] == _JNT.mjJNT_FREE:
            kind, root_body = ROOT_FREE, roots[0]
        elif len(roots) == 1 and first_joint < 0:
            kind, root_body = ROOT_FIXED, roots[0]
        else:
            kind = ROOT_WORLD
        if root_body is not None:
            root_link = self.local(mujoco.mjtObj.mjOBJ_BODY, root_body)
            self.links[root_body] = root_link
            for j in range(int(m.body_jntadr[root_body]) + 1, int(m.body_jntadr[root_body] + m.body_jntnum[root_body])):
                self.notes.append(f"joint {self.local(mujoco.mjtObj.mjOBJ_JOINT, j)}: after the root's free joint")
        else:
            root_link = self.unique_link(f"{self.name}_world")
        self.add_link(root_link)
        if root_body is not None:
            self.fill_link(root_body, root_link)
        for b in sorted(body.body_ids):
            if b != root_body:
                self.add_body(b, root_link)
        self.world_geoms(kind, root_body, root_link)
        moving = [j.name for j in self.joints if j.type in MOVING]
        links = list(self.link_objects.values())
        return UrdfExport(
            self.name, links, self.joints, root_link, kind, dict(self.links), moving, root_body, self.meshes, self.notes
        )

    def add_body(self, b: int, root_link: str) -> None:
        m = self.m
        link = self.local(mujoco.mjtObj.mjOBJ_BODY, b)
        self.links[b] = link
        parent = int(m.body_parentid[b])
        parent_link = root_link if parent == 0 else self.links[parent]
        offset = pose_matrix(m.body_pos[b], m.body_quat[b])  # MuJoCo's frame = current link frame @ offset
        steps: list[Joint] = []  # the URDF joints of the MuJoCo joints (their parents and children come later)
        folded = []  # joints fixed at their reference position
        for j in range(int(m.body_jntadr[b]), int(m.body_jntadr[b] + m.body_jntnum[b])):
            jname = self.local(mujoco.mjtObj.mjOBJ_JOINT, j)
            jtype = int(m.jnt_type[j])
            anchor, axis = np.array(m.jnt_pos[j]), np.array(m.jnt_axis[j])
            ref = float(m.qpos0[m.jnt_qposadr[j]])
            info = self.numbered.get(j)
            if info is not None and jtype == _JNT.mjJNT_HINGE:
                origin = offset @ translation(anchor) @ rotation(axis, -ref)
                steps.append(self.moving(j, info, "revolute" if info.limited else "continuous", origin))
                offset = translation(-anchor)
            elif info is not None:  # a numbered slide
                origin = offset @ translation(-axis * ref)
                steps.append(self.moving(j, info, "prismatic", origin))
                offset = np.eye(4)
            elif jtype == _JNT.mjJNT_FREE:
                steps.append(Joint(jname, "floating", "", "", offset))
                offset = np.eye(4)
                self.notes.append(f"joint {jname}: a free joint below the root, floating at its reference pose")
            else:
                if jtype == _JNT.mjJNT_BALL:
                    adr = int(m.jnt_qposadr[j])
                    turn = pose_matrix((0.0, 0.0, 0.0), m.qpos0[adr : adr + 4])
                    offset = offset @ translation(anchor) @ turn @ translation(-anchor)
                # a hinge or slide at its reference position does not move the body
                folded.append(jname)
                why = self.body.skipped_joints.get(jname, "not numbered")
                self.notes.append(f"joint {jname}: fixed at its reference position ({why})")
        if not steps:
            name = self.unique_joint(folded[0], own=True) if folded else self.unique_joint(f"{parent_link}_to_{link}")
            self.add_link(link)
            self.joints.append(Joint(name, "fixed", parent_link, link, offset))
        else:
            current = parent_link
            for i, joint in enumerate(steps):
                last = i == len(steps) - 1
                child = link if last and is_identity(offset) else self.unique_link(f"{joint.name}_frame")
                self.add_link(child)
                joint.name = self.unique_joint(joint.name, own=True)
                joint.parent, joint.child = current, child
                self.joints.append(joint)
                current = child
            if current != link:
                self.add_link(link)
                self.joints.append(Joint(self.unique_joint(f"{link}_offset"), "fixed", current, link, offset))
        self.fill_link(b, link)

    def moving(self, j: int, info, kind: str, origin: np.ndarray) -> Joint:
        """A numbered joint's URDF joint: axis, limits, effort (its motor's), damping and friction loss."""
        m = self.m
        effort, a = 0.0, info.motor
        if a >= 0:
            if m.actuator_forcelimited[a]:
                effort = float(np.abs(m.actuator_forcerange[a]).max())
            elif m.actuator_ctrllimited[a]:
                effort = float(np.abs(m.actuator_ctrlrange[a]).max() * abs(info.gear))
        lower = upper = None
        if info.limited:
            lower, upper = float(info.lower), float(info.upper)
        elif kind == "prismatic":
            lower, upper = -UNLIMITED_SLIDE, UNLIMITED_SLIDE
        dof = int(m.jnt_dofadr[j])
        return Joint(
            info.name,
            kind,
            "",
            "",
            origin,
            tuple(float(v) for v in m.jnt_axis[j]),
            lower,
            upper,
            effort,
            damping=float(m.dof_damping[dof]),
            friction=float(m.dof_frictionloss[dof]),
        )

    # what hangs on a link
    def fill_link(self, b: int, link: str) -> None:
        m = self.m
        obj = self.link_objects[link]
        if m.body_mass[b] > 0:
            obj.inertial = Inertial(
                pose_matrix(m.body_ipos[b], m.body_iquat[b]),
                float(m.body_mass[b]),
                tuple(float(v) for v in m.body_inertia[b]),
            )
        for g in range(m.ngeom):
            if m.geom_bodyid[g] == b:
                self.add_geom(obj, g, np.eye(4))

    def world_geoms(self, kind: str, root_body, root_link: str) -> None:
        m = self.m
        on_world = [g for g in sorted(self.body.geom_ids) if m.geom_bodyid[g] == 0]
        if not on_world:
            return
        if kind == ROOT_FREE:
            names = ", ".join(self.local(mujoco.mjtObj.mjOBJ_GEOM, g) for g in on_world)
            self.notes.append(f"geoms fixed to the world, not part of a free robot: {names}")
            return
        world_to_root = np.eye(4)
        if kind == ROOT_FIXED:
            world_to_root = np.linalg.inv(pose_matrix(m.body_pos[root_body], m.body_quat[root_body]))
        for g in on_world:
            self.add_geom(self.link_objects[root_link], g, world_to_root)

    def add_geom(self, link: Link, g: int, frame: np.ndarray) -> None:
        m = self.m
        name = self.local(mujoco.mjtObj.mjOBJ_GEOM, g)
        pose = frame @ pose_matrix(m.geom_pos[g], m.geom_quat[g])
        size = tuple(float(v) for v in m.geom_size[g])
        kind = int(m.geom_type[g])
        shapes: list[tuple[str, Geometry, np.ndarray]] = []  # (name, geometry, origin)
        if kind == _T.mjGEOM_BOX:
            shapes.append((name, Geometry("box", tuple(2 * v for v in size)), pose))
        elif kind == _T.mjGEOM_CYLINDER:
            shapes.append((name, Geometry("cylinder", (size[0], 2 * size[1])), pose))
        elif kind == _T.mjGEOM_SPHERE:
            shapes.append((name, Geometry("sphere", (size[0],)), pose))
        elif kind == _T.mjGEOM_CAPSULE:
            shapes.append((name, Geometry("cylinder", (size[0], 2 * size[1])), pose))
            for i, sign in enumerate((-1.0, 1.0)):
                cap = pose @ translation((0.0, 0.0, sign * size[1]))
                shapes.append((f"{name}_cap{i}", Geometry("sphere", (size[0],)), cap))
        elif kind == _T.mjGEOM_ELLIPSOID:
            if ELLIPSOID_MESH not in self.meshes:
                self.meshes[ELLIPSOID_MESH] = unit_sphere()
                self.notes.append(f"ellipsoids: the unit-sphere mesh {ELLIPSOID_MESH}, scaled")
            shapes.append((name, Geometry("mesh", filename=ELLIPSOID_MESH, scale=size), pose))
        elif kind == _T.mjGEOM_PLANE:
            half = [v if v > 0 else INFINITE_PLANE for v in size[:2]]
            box = Geometry("box", (2 * half[0], 2 * half[1], PLANE_THICKNESS))
            shapes.append((name, box, pose @ translation((0.0, 0.0, -PLANE_THICKNESS / 2))))
            self.notes.append(f"geom {name}: a plane, as a box {PLANE_THICKNESS * 1000:g} mm thick")
        elif kind == _T.mjGEOM_MESH:
            mesh_id = int(m.geom_dataid[g])
            file_name = f"{self.local(mujoco.mjtObj.mjOBJ_MESH, mesh_id) or f'mesh{mesh_id}'}.stl"
            if file_name not in self.meshes:
                self.meshes[file_name] = compiled_mesh(m, mesh_id)
            shapes.append((name, Geometry("mesh", filename=file_name), pose))
        else:
            what = {int(_T.mjGEOM_HFIELD): "a height field", int(_T.mjGEOM_SDF): "an SDF"}.get(kind, f"type {kind}")
            self.notes.append(f"geom {name}: {what}, left out")
            return
        visual = m.geom_group[g] < HIDDEN_GEOM_GROUP
        collides = bool(m.geom_contype[g] or m.geom_conaffinity[g])
        rgba = m.mat_rgba[m.geom_matid[g]] if m.geom_matid[g] >= 0 else m.geom_rgba[g]
        # float32 in MjModel: written as its shortest text (0.36, not 0.36000001430511475)
        color = tuple(float(str(np.float32(c))) for c in rgba)
        for shape_name, geometry, origin in shapes:
            if visual:
                link.visuals.append(Shape(shape_name, origin, geometry, color))
            if collides:
                link.collisions.append(Shape(shape_name, origin, geometry))


def export_model_file(path, body_name: str | None = None) -> tuple[Body, UrdfExport]:
    """The model file ``path`` alone in a world, as body ``body_name``, and its URDF.

    Args:
        path: an MJCF (or URDF) file MuJoCo loads.
        body_name: the body's (and robot's) name; the model's own name by
            default (``<mujoco model="Tank">``), else the file's stem.

    Raises:
        ValueError: the file does not load, or the name is not a valid body name.
    """
    from tutorial.core.project import NAME_PATTERN
    from tutorial.core.world import ModelEntry, build_world

    path = Path(path)
    if body_name is None:
        try:
            spec = mujoco.MjSpec.from_file(str(path))
        except Exception as exc:  # mujoco raises ValueError with the parser's text
            raise ValueError(f"{path}: {exc}") from None
        body_name = spec.modelname if NAME_PATTERN.match(spec.modelname or "") else path.stem
        if not NAME_PATTERN.match(body_name):
            body_name = "robot"
    if not NAME_PATTERN.match(body_name):
        raise ValueError(f"body name {body_name!r}: use letters, digits and _, starting with a letter")
    world = build_world([ModelEntry(body_name, path)])
    body = Body(world, mujoco.MjData(world), body_name)
    return body, export_body(body)
