"""Build one MuJoCo world from several MJCF model files.

Choreonoid loads a world item with body items under it; here a project names
the model files and :func:`build_world` attaches each under its own name
prefix (``Tank/``) to an empty ``MjSpec``, so two robots can share joint
names and every element stays traceable to the body it came from.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import mujoco


@dataclass
class ModelEntry:
    """One model placed in the world.

    Attributes:
        name: the body name, e.g. ``Tank``; also the prefix of its elements and
            the first part of its ROS topics (``/Tank/joint_state``).
        file: path of the MJCF file.
        position: (3,) placement of the model's frame in the world, m.
        yaw: rotation of the model's frame about +Z, rad.
    """

    name: str
    file: Path
    position: Sequence[float] = (0.0, 0.0, 0.0)
    yaw: float = 0.0
    controllers: list = field(default_factory=list)


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
        The compiled model; each entry's elements are named ``<name>/<element>``.

    Raises:
        ValueError: a model file does not parse or the world does not compile
            (MuJoCo's message, with the file name).

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
        try:
            child = mujoco.MjSpec.from_file(str(entry.file))
        except Exception as exc:  # mujoco raises ValueError with the parser's text
            raise ValueError(f"{entry.file}: {exc}") from exc
        half = entry.yaw / 2.0
        frame = spec.worldbody.add_frame(
            pos=list(entry.position), quat=[math.cos(half), 0.0, 0.0, math.sin(half)]
        )
        with warnings.catch_warnings():
            # MuJoCo warns when a child's <option> differs from the world's;
            # the world's (the project's) settings are the ones we want.
            warnings.simplefilter("ignore")
            spec.attach(child, prefix=f"{entry.name}/", frame=frame)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return spec.compile()
    except Exception as exc:
        raise ValueError(f"the world does not compile: {exc}") from exc
