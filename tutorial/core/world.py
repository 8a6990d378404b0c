"""Build one MuJoCo world from several MJCF model files.

Choreonoid loads a world item with body items under it; here a project names
the model files and :func:`build_world` attaches each under its own name
prefix (``Tank/``) to an empty ``MjSpec``, so two robots can share joint
names and every element stays traceable to the body it came from.

Models that other packages ship often leave bodies and joints unnamed, and
MuJoCo does not prefix an element without a name.  So before attaching,
:func:`name_unnamed_elements` gives every unnamed body, joint, geom and site
of a model a stable name (the rule is in its docstring): in the world, every
element of a model is then named ``<model name>/...``, and the world's
top-level bodies so named are the model's roots (:class:`tutorial.core.body.Body`
owns their kinematic subtrees).

A model file MuJoCo cannot load (an XML error, junk bytes, a mesh it cannot
find) or one with nothing in it is a bad *file*, not a failed simulation:
:func:`build_world` raises :class:`ModelError`, one line naming the file
(``rtt-run`` exits with status 2 for it).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import mujoco

# The kinds of element that get a name when they have none: the ones a Body
# owns by its kinematic tree (bodies, and what hangs on them), and the one
# whose name goes on the wire (joints).  (MjSpec list attribute, name stem.)
NAMED_KINDS = (("bodies", "body"), ("joints", "joint"), ("geoms", "geom"), ("sites", "site"))


class ModelError(ValueError):
    """A model file that cannot be loaded, or models that do not compile together.

    Attributes:
        entry: the :class:`ModelEntry` at fault, or None when no one file is
            (the models load alone but not together).

    The message is one line: the file, then MuJoCo's reason.
    """

    def __init__(self, message: str, entry: ModelEntry | None = None):
        super().__init__(message)
        self.entry = entry


def _reason(exc: BaseException) -> str:
    """MuJoCo's error text (often several lines: the error, then the element and line) as one line."""
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    return "; ".join(lines)[:300] or type(exc).__name__


@dataclass
class ModelEntry:
    """One model placed in the world.

    Attributes:
        name: the body name, e.g. ``Tank``; also the prefix of its elements and
            the first part of its ROS topics (``/Tank/joint_state``).
        file: path of the MJCF file; None when the model comes from ``text``.
        position: (3,) placement of the model's frame in the world, m.
        yaw: rotation of the model's frame about +Z, rad.
        description: a robot-description topic to take the model from instead
            of a file (a viewer project); whoever receives it sets ``text``.
        text: the model as text (MJCF, or a robot description prepared by
            :func:`tutorial.tools.urdf.mujoco_load.mujoco_text`), used instead of ``file``.
        odometry: an odometry topic a viewer places the model's root link by
            (:mod:`tutorial.tools.standalone.floating_base`); the root then gets a free
            joint if it has none, so it can be placed anywhere.
    """

    name: str
    file: Path | None
    position: Sequence[float] = (0.0, 0.0, 0.0)
    yaw: float = 0.0
    controllers: list = field(default_factory=list)
    description: str | None = None
    text: str | None = None
    odometry: str | None = None


def build_world(
    entries: Sequence[ModelEntry],
    time_step: float = 0.001,
    gravity: Sequence[float] = (0.0, 0.0, -9.80665),
) -> mujoco.MjModel:
    """Compile the models into one ``MjModel``.

    Args:
        entries: the models, attached in this order.
        time_step: simulation step, s.
        gravity: (3,) gravity vector, m/s^2.

    Returns:
        The compiled model; each entry's bodies, joints, geoms and sites are
        named ``<name>/<element>``, unnamed ones by the rule of
        :func:`name_unnamed_elements`.

    Raises:
        ModelError: a model file does not load, does not compile, or has no
            body, geom or site; or the models do not compile together
            (MuJoCo's message, in one line, with the file name).

    Any thread may call this; the returned model is read-only for everyone.
    """
    spec = mujoco.MjSpec()
    spec.modelname = "world"
    spec.option.timestep = time_step
    spec.option.gravity = list(gravity)
    # implicitfast treats the velocity actuators of the tracks implicitly, so
    # their stiff gains stay stable at 1 ms.
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.compiler.degree = False
    for entry in entries:
        child = _load(entry)
        half = entry.yaw / 2.0
        frame = spec.worldbody.add_frame(pos=list(entry.position), quat=[math.cos(half), 0.0, 0.0, math.sin(half)])
        try:
            with warnings.catch_warnings():
                # MuJoCo warns when a child's <option> differs from the world's;
                # the world's (the project's) settings are the ones we want.
                warnings.simplefilter("ignore")
                spec.attach(child, prefix=f"{entry.name}/", frame=frame)
        except Exception as exc:  # noqa: BLE001 - MuJoCo's own errors, each a property of the file
            raise ModelError(f"{entry.file}: cannot be added to the world: {_reason(exc)}", entry) from None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = spec.compile()
    except Exception as exc:  # noqa: BLE001 - find the file at fault, if one is
        for entry in entries:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    _load(entry).compile()
            except Exception as alone:  # noqa: BLE001
                raise ModelError(f"{entry.file}: does not compile: {_reason(alone)}", entry) from None
        raise ModelError(f"the models do not compile together: {_reason(exc)}") from None
    for entry in entries:
        if not _has_elements(model, f"{entry.name}/"):
            raise ModelError(f"{entry.file}: the model has no body, geom or site: nothing to simulate or show", entry)
    return model


def _load(entry: ModelEntry) -> mujoco.MjSpec:
    """The model parsed (its file, or its text), its unnamed elements named, its root floating if it follows
    odometry; :class:`ModelError` if MuJoCo cannot read it, or a description-only entry's text has not been
    received."""
    child = _parse(entry)
    if entry.odometry is not None:
        _float_root(child, entry)
    return child


def _float_root(spec: mujoco.MjSpec, entry: ModelEntry) -> None:
    """Give the model's root link a free joint, if it has none, so odometry can place it (in place).

    A URDF's root link is welded to the world when MuJoCo reads it; a model
    file's root may already float (the tank's has a free joint).  A root that
    moves on other joints (a hinge to the world) cannot take a pose.
    """
    root = spec.worldbody.first_body()
    if root is None:
        raise ModelError(f"model {entry.name}: follows {entry.odometry}, but has no link to place", entry)
    tops = [b for b in spec.bodies if b.parent is not None and b.parent.name == spec.worldbody.name]
    if len(tops) > 1:  # one pose places one root: the others would stay behind
        raise ModelError(
            f"model {entry.name}: follows {entry.odometry}, but has {len(tops)} top-level bodies "
            f"({', '.join(b.name or '?' for b in tops)}): odometry places one root link",
            entry,
        )
    joints = list(root.joints)
    if any(j.type == mujoco.mjtJoint.mjJNT_FREE for j in joints):
        return
    if joints:
        raise ModelError(
            f"model {entry.name}: follows {entry.odometry}, but its root link {root.name} moves on "
            f"{len(joints)} other joint(s): an odometry pose needs a root free of the world",
            entry,
        )
    taken = {j.name for j in spec.joints}
    name = next(
        n for n in ("floating_base", *(f"floating_base_{i}" for i in range(1, len(taken) + 2))) if n not in taken
    )
    root.add_freejoint(name=name)


def drawing_spec(text: str) -> mujoco.MjSpec:
    """The ``MjSpec`` of a model that is drawn, never simulated (a received robot description; any thread).

    Each mesh's inertia is its surface's (MuJoCo's ``inertia="shell"``): a
    mesh's inertia only places it in its geom, and a thin or open visual
    mesh has no volume for MuJoCo's default to measure ("mesh volume is too
    small").  Computing a surface's is also faster.

    Raises:
        ValueError: MuJoCo cannot read the text.
    """
    spec = mujoco.MjSpec.from_string(text)
    for mesh in spec.meshes:
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
    return spec


def _parse(entry: ModelEntry) -> mujoco.MjSpec:
    if entry.text is not None:
        try:
            child = drawing_spec(entry.text) if entry.description else mujoco.MjSpec.from_string(entry.text)
            name_unnamed_elements(child)
        except Exception as exc:  # noqa: BLE001 - mujoco raises ValueError with the parser's text
            raise ModelError(
                f"model {entry.name} ({entry.description or 'text'}): not a model MuJoCo can load: {_reason(exc)}",
                entry,
            ) from None
        return child
    if entry.file is None:
        raise ModelError(
            f"model {entry.name}: no model file, and its description {entry.description} not received", entry
        )
    try:
        # MJCF is XML in UTF-8; a name in another encoding would load, then fail where Python reads it.
        Path(entry.file).read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError(
            f"{entry.file}: not UTF-8 text (byte {exc.start}): an MJCF file is XML in UTF-8", entry
        ) from None
    except (OSError, ValueError) as exc:
        raise ModelError(f"{entry.file}: cannot read it: {_reason(exc)}", entry) from None
    try:
        child = mujoco.MjSpec.from_file(str(entry.file))
        name_unnamed_elements(child)
    except Exception as exc:  # noqa: BLE001 - mujoco raises ValueError with the parser's text
        raise ModelError(f"{entry.file}: not a model MuJoCo can load: {_reason(exc)}", entry) from None
    return child


def _has_elements(model: mujoco.MjModel, prefix: str) -> bool:
    """Whether any top-level body, or any geom or site, of the world is named ``<prefix>...``."""
    kinds = (
        (mujoco.mjtObj.mjOBJ_BODY, range(1, model.nbody)),
        (mujoco.mjtObj.mjOBJ_GEOM, range(model.ngeom)),
        (mujoco.mjtObj.mjOBJ_SITE, range(model.nsite)),
    )
    return any((mujoco.mj_id2name(model, kind, i) or "").startswith(prefix) for kind, ids in kinds for i in ids)


def name_unnamed_elements(spec: mujoco.MjSpec) -> int:
    """Name every unnamed body, joint, geom and site of one model, in place.

    The rule: an unnamed element is named after its kind and its id in the
    model file compiled on its own (its index in ``MjModel``'s arrays of
    that kind, as ``mujoco.MjModel.from_xml_path(file)`` numbers it; the
    world body is body 0): ``body4``, ``joint0``, ``geom12``, ``site3``.
    The name is stable as long as the file is: the simulation and a viewer
    that load the same file agree on it.  If the model already uses that
    name for another element of the kind, ``_1``, ``_2``, ... is appended
    until it is free.  Named elements keep their names.

    Args:
        spec: a model's ``MjSpec`` before it is attached or compiled.

    Returns:
        How many elements were named.

    The ids come from the order of ``MjSpec.bodies`` (``joints``, ...), which is
    the order MuJoCo's compiler numbers them in (depth first, frames
    included).  Any thread may call this on a spec no other thread uses.
    """
    named = 0
    for attribute, stem in NAMED_KINDS:
        elements = list(getattr(spec, attribute))
        taken = {e.name for e in elements if e.name}
        for index, element in enumerate(elements):
            if element.name:
                continue
            name, n = f"{stem}{index}", 0
            while name in taken:
                n += 1
                name = f"{stem}{index}_{n}"
            element.name = name
            taken.add(name)
            named += 1
    return named
