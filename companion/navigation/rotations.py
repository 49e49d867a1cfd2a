"""Quaternions (w, x, y, z; body→NED) and the few rotation helpers the navigators need.

Plain floats and small numpy arrays: this is the INS hot path.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

Quat = tuple[float, float, float, float]


def euler_to_quaternion(roll: float, pitch: float, yaw: float) -> Quat:
    """ZYX Euler angles to a body→NED quaternion."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )


def quaternion_to_euler(q: Quat) -> tuple[float, float, float]:
    """(roll, pitch, yaw) of a body→NED quaternion; yaw in [-π, π]."""
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def multiply(a: Quat, b: Quat) -> Quat:
    """Hamilton product a ⊗ b."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def rotation_vector_quaternion(rx: float, ry: float, rz: float) -> Quat:
    """exp of a rotation vector (radians) as a quaternion."""
    angle = math.sqrt(rx * rx + ry * ry + rz * rz)
    if angle < 1e-9:
        return (1.0, 0.5 * rx, 0.5 * ry, 0.5 * rz)
    s = math.sin(angle / 2) / angle
    return (math.cos(angle / 2), rx * s, ry * s, rz * s)


def normalized(q: Quat) -> Quat:
    """q scaled to unit length, sign chosen so w ≥ 0."""
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if w < 0:
        n = -n
    return (w / n, x / n, y / n, z / n)


def rotation_matrix_rows(q: Quat) -> list[list[float]]:
    """The body→NED direction cosine matrix of q, as rows of floats."""
    w, x, y, z = q
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def rotation_matrix(q: Quat) -> np.ndarray:
    """The body→NED direction cosine matrix of q."""
    return np.array(rotation_matrix_rows(q))


def skew(v: Sequence[float] | np.ndarray) -> np.ndarray:
    """The cross-product matrix [v]×."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def tilt_compensated_heading(mag_body: np.ndarray, roll: float, pitch: float) -> float:
    """Magnetic heading (radians from magnetic north) of a body-frame field, levelled."""
    mx, my, mz = mag_body
    sr, cr, sp, cp = math.sin(roll), math.cos(roll), math.sin(pitch), math.cos(pitch)
    xh = mx * cp + my * sr * sp + mz * cr * sp
    yh = my * cr - mz * sr
    return math.atan2(-yh, xh)
