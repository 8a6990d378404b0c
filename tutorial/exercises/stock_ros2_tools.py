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

from tutorial.exercises.grader import Case, CaseFailed, Result, grade, hidden_random
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
    """What a learner's answer was, in a line: a pose, an array of another shape, a tuple or list of such, or
    its repr (None: no return)."""
    if m is None or isinstance(m, str):
        return repr(m)
    try:
        a = np.asarray(m, dtype=float)
    except (TypeError, ValueError):
        if isinstance(m, (tuple, list)):
            return f"a {type(m).__name__} of {len(m)} ({', '.join(_show(x) for x in m)})"
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

    While grading, hidden trees drawn by the same rules (tilted about every
    axis, a root other than ``world``, children sent again with stamps a
    second later) are judged by :func:`_pose_in_root`.
    """

    def case(label: str, transforms: list[Transform], frame: str, expected, hint: str, hidden=False) -> Case:
        call = label if hidden else f"lookup({label}, {frame!r})"

        def run():
            if expected is KeyError:
                try:
                    got = func(list(transforms), frame)
                except KeyError:
                    return
                raise CaseFailed(f"{call} returned {_show(got)}, expected a KeyError.", hint)
            got = func(list(transforms), frame)
            try:
                ok = np.asarray(got, dtype=float).shape == (4, 4) and np.allclose(got, expected, atol=1e-9)
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise CaseFailed(f"{call} returned {_show(got)}, expected {_show(expected)}.", hint)

        return Case(call, run, hint, hidden)

    def drawn(rng, label: str, kind: str) -> Case:
        """A hidden case: a tree drawn by ``kind``'s rules, its frame's pose found by the statement's rules."""
        transforms, frame = _random_tree(rng, kind)
        hint = "follow each rule of the statement: (x, y, z, w), pose(parent) @ transform, the newest counts."
        return case(label, transforms, frame, _pose_in_root(transforms, frame), hint, True)

    rng = hidden_random("9.1")  # while grading: this learner's own trees, by the statement's rules
    hidden = (
        [
            drawn(rng, "a chain of frames tilted about every axis", "tilted"),
            drawn(rng, "a tree whose root is not world", "root"),
            drawn(rng, "a child sent several times, its stamps a second or more apart", "newest"),
            drawn(rng, "the root of a random tree", "the root"),
            drawn(rng, "a frame no transform names, in a random tree", "missing"),
            drawn(rng, "a random tree, listed in any order, tilted", "any"),
        ]
        if rng
        else []
    )

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
            *hidden,
        ],
    )


def _rotation(q) -> np.ndarray:
    """The 3x3 rotation of a unit quaternion (x, y, z, w), ROS's order, written out (not the library's)."""
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _pose_in_root(transforms: list[Transform], frame: str):
    """The statement's rules: ``frame``'s pose in the root, the last transform of each child counting; the root's
    pose the identity; ``KeyError`` (the class) for a frame no transform names."""
    newest = {t.child: t for t in transforms}
    if frame not in newest and frame not in {t.parent for t in transforms}:
        return KeyError
    pose = np.eye(4)
    while frame in newest:
        step = np.eye(4)
        step[:3, :3], step[:3, 3] = _rotation(newest[frame].rotation), newest[frame].translation
        pose, frame = step @ pose, newest[frame].parent
    return pose


def _random_tree(rng, kind: str) -> tuple[list[Transform], str]:
    """A tree of transforms, listed in any order, and the frame to look up (``kind`` in the hidden cases).

    Rotations are random unit quaternions (tilted about every axis, ``w`` of either sign), translations up to
    2 m; the root is ``world`` or another name; for ``newest`` and ``any``, frames on the way up are sent again
    later in the list, stamped a second later with fewer nanoseconds (``(sec, nanosec)``).
    """
    others = ("map", "odom", "base_link")
    root = rng.choice(others if kind == "root" else ("world", *others) if kind in ("the root", "any") else ("world",))
    frames = [root] + [f"F{k}" for k in range(rng.randrange(3, 8))]
    chain = kind == "tilted"
    parents = {child: frames[k if chain else rng.randrange(k + 1)] for k, child in enumerate(frames[1:])}

    def transform(child: str, sec: int, nanosec: int) -> Transform:
        q = [rng.gauss(0.0, 1.0) for _ in range(4)]
        q = [v / math.sqrt(sum(a * a for a in q)) for v in q]
        t = [rng.uniform(-2.0, 2.0) for _ in range(3)]
        return Transform((sec, nanosec), parents[child], child, tuple(t), tuple(q))

    stamp = rng.randrange(1, 1000)
    transforms = [transform(child, stamp, rng.randrange(5 * 10**8, 10**9)) for child in frames[1:]]
    rng.shuffle(transforms)
    leaves = [f for f in frames[1:] if f not in parents.values()]
    frame = {"the root": root, "missing": rng.choice(("GUN", "F9", "camera"))}.get(kind, rng.choice(leaves))
    path = [frame] if frame in parents else []
    while path and parents[path[-1]] != root:
        path.append(parents[path[-1]])
    for child in rng.sample(path, min(2, len(path))) if kind in ("newest", "any") else ():
        for _ in range(rng.randrange(1, 3)):
            stamp += 1  # a later second, fewer nanoseconds than the older ones
            last = max(k for k, t in enumerate(transforms) if t.child == child)
            transforms.insert(
                rng.randrange(last + 1, len(transforms) + 1), transform(child, stamp, rng.randrange(10**8))
            )
    return transforms, frame
