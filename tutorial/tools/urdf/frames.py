"""Transforms as 4x4 matrices (m, rad): a pose from MuJoCo's position and quaternion, URDF's roll-pitch-yaw.

Any thread may call these functions.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

_IDENTITY_TOL = 1e-12


def pose_matrix(pos, quat) -> np.ndarray:
    """A 4x4 transform from a position (3,) m and a quaternion (4,) w, x, y, z (normalised here)."""
    q = np.asarray(quat, dtype=float)
    q = q / np.linalg.norm(q)
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, q)
    out = np.eye(4)
    out[:3, :3] = mat.reshape(3, 3)
    out[:3, 3] = pos
    return out


def translation(v) -> np.ndarray:
    out = np.eye(4)
    out[:3, 3] = v
    return out


def rotation(axis, angle: float) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_axisAngle2Quat(q, np.asarray(axis, dtype=float), float(angle))
    return pose_matrix((0.0, 0.0, 0.0), q)


def is_identity(t: np.ndarray) -> bool:
    return bool(np.abs(t - np.eye(4)).max() <= _IDENTITY_TOL)


def rpy_from_matrix(matrix: np.ndarray) -> tuple[float, float, float]:
    """URDF's roll, pitch, yaw (rad) of a rotation: ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``.

    At pitch +-90 degrees (gimbal lock) roll and yaw turn about one axis: yaw is 0 there.
    """
    r = matrix[:3, :3]
    cy = math.hypot(r[0, 0], r[1, 0])
    if cy > 4 * np.finfo(float).eps:
        return math.atan2(r[2, 1], r[2, 2]), math.atan2(-r[2, 0], cy), math.atan2(r[1, 0], r[0, 0])
    return math.atan2(-r[1, 2], r[1, 1]), math.atan2(-r[2, 0], cy), 0.0
