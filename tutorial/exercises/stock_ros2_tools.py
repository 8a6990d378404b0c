"""Checks for the exercise of notebook 09 (the stock ROS 2 tools).

Exercise 9.1, look a frame up as tf2 does: ``lookup(transforms, frame) -> 4x4``,
the pose of ``frame`` in the root frame of the tree the transforms make
(:class:`tutorial.interfaces.tf.Transform`: parent, child, translation in m,
rotation x, y, z, w), the newest transform of each child counting.

Every case is a small tree with known answers, so the check is exact and
needs no ROS.
"""

from __future__ import annotations

import math

import numpy as np

from tutorial.exercises.grader import Case, CaseFailed, Result, grade
from tutorial.interfaces.tf import Transform

STAMP = (0, 0)
H = math.sqrt(0.5)  # cos and sin of 45 degrees


def _t(parent: str, child: str, translation=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0, 1.0)) -> Transform:
    return Transform(STAMP, parent, child, tuple(float(v) for v in translation), tuple(float(v) for v in rotation))


def _pose(position, rotation_z: float = 0.0) -> np.ndarray:
    """A 4x4 pose: ``position`` (3,) m, turned ``rotation_z`` rad about z."""
    c, s = math.cos(rotation_z), math.sin(rotation_z)
    out = np.eye(4)
    out[:3, :3] = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    out[:3, 3] = position
    return out


def _show(m) -> str:
    try:
        a = np.asarray(m, dtype=float)
    except (TypeError, ValueError):
        return repr(m)
    if a.shape != (4, 4):
        return f"an array of shape {a.shape}"
    (x, y, z) = a[:3, 3]
    yaw = math.atan2(a[1, 0], a[0, 0])
    return f"a pose at ({x:.3f}, {y:.3f}, {z:.3f}) m, yaw {yaw:.3f} rad"


def check_lookup(func) -> Result:
    """Check ``func(transforms, frame) -> (4, 4) array``: ``frame``'s pose in the tree's root frame.

    The root is the frame that is no transform's child (``world`` in every
    case); each transform places its child in its parent; of several
    transforms of one child, the last in the list (the newest) counts; the
    root's own pose is the identity; a frame that is not in the tree raises
    ``KeyError``.
    """

    def case(label: str, transforms: list[Transform], frame: str, expected: np.ndarray, hint: str) -> Case:
        call = f"lookup({label}, {frame!r})"

        def run():
            got = func(list(transforms), frame)
            try:
                ok = np.asarray(got, dtype=float).shape == (4, 4) and np.allclose(got, expected, atol=1e-9)
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise CaseFailed(f"{call} returned {_show(got)}, expected {_show(expected)}.", hint)

        return Case(call, run, hint)

    def missing() -> None:
        call = "lookup(world -> CHASSIS, 'GUN')"
        try:
            got = func([_t("world", "CHASSIS", (1, 0, 0))], "GUN")
        except KeyError:
            return
        raise CaseFailed(f"{call} returned {_show(got)}, expected a KeyError: no transform names GUN.")

    chassis = _t("world", "CHASSIS", (1.0, 2.0, 0.1), (0.0, 0.0, H, H))  # turned 90 degrees left
    turret = _t("CHASSIS", "TURRET", (0.5, 0.0, 0.2))
    barrel = _t("TURRET", "BARREL", (0.3, 0.0, 0.0), (0.0, 0.0, -H, H))  # turned 90 degrees right
    return grade(
        "Exercise 9.1, look a frame up as tf2 does",
        [
            case(
                "world -> CHASSIS, moved only",
                [_t("world", "CHASSIS", (1.0, 2.0, 0.1))],
                "CHASSIS",
                _pose((1.0, 2.0, 0.1)),
                "rotation (0, 0, 0, 1) is x, y, z, w: no turn (w is last in ROS), so the child is only "
                "moved, by the translation.",
            ),
            case("world -> CHASSIS", [chassis], "world", np.eye(4), "the root frame's pose in itself is the identity."),
            case(
                "world -> CHASSIS, turned 90 degrees left",
                [chassis],
                "CHASSIS",
                _pose((1.0, 2.0, 0.1), math.pi / 2),
                "rotation is (x, y, z, w), w last, as ROS writes it; MuJoCo's quaternions put w first.",
            ),
            case(
                "world -> CHASSIS -> TURRET",
                [chassis, turret],
                "TURRET",
                _pose((1.0, 2.5, 0.3), math.pi / 2),
                "the child's translation is in the parent's axes: pose(child) = pose(parent) @ transform.",
            ),
            case(
                "three transforms, children listed before parents",
                [barrel, turret, chassis],
                "BARREL",
                _pose((1.0, 2.8, 0.3), 0.0),
                "walk from the frame up to the root, whatever the order of the list.",
            ),
            case(
                "CHASSIS sent twice, the second newer",
                [chassis, turret, _t("world", "CHASSIS", (3.0, 0.0, 0.1))],
                "TURRET",
                _pose((3.5, 0.0, 0.3)),
                "a later transform of the same child replaces the earlier one (it is newer).",
            ),
            Case("lookup(world -> CHASSIS, 'GUN')", missing, "raise KeyError for a frame no transform names."),
        ],
    )
