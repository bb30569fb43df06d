"""Poses and rotations: planar poses, angles and quaternions, in plain Python and numpy.

The one place for these facts. It imports neither ROS nor pybullet nor the world, so navigation and
the behaviours (which run in processes without a simulator) can use it. Conventions are ROS's
(REP 103): x forward, y left, z up, yaw counter-clockwise about +z; quaternions are (x, y, z, w).
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

Pose2D = tuple[float, float, float]                  # x, y (m), yaw (rad)
Quaternion = tuple[float, float, float, float]       # x, y, z, w


def wrap_angle(a: float) -> float:
    """``a`` in [-pi, pi)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def compose(a: Pose2D, b: Pose2D) -> Pose2D:
    """The pose ``b`` (given in frame ``a``) in ``a``'s parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle(a[2] + b[2]))


def relative(a: Pose2D, b: Pose2D) -> Pose2D:
    """The pose ``b`` seen from ``a`` (both in one frame): ``compose(a, relative(a, b)) == b``."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, wrap_angle(b[2] - a[2]))


def quaternion_from_yaw(yaw: float) -> Quaternion:
    """(x, y, z, w) of a rotation about +z."""
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def yaw_from_quaternion(z: float, w: float) -> float:
    """The yaw of a rotation about +z given by its quaternion's z and w (x = y = 0)."""
    return 2.0 * math.atan2(z, w)


def quaternion_from_matrix(r: np.ndarray) -> Quaternion:
    """(x, y, z, w) of a rotation matrix (Shepperd's method, numerically stable)."""
    m = r
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s)
    sign = 1.0 if q[3] >= 0 else -1.0
    x, y, z, w = (float(sign * v) for v in q)
    return (x, y, z, w)


def matrix_from_quaternion(q: Sequence[float]) -> np.ndarray:
    """The 3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def pose_matrix(position: Sequence[float], orientation: Sequence[float]) -> np.ndarray:
    """3x4 [R | t] of a position and a quaternion (x, y, z, w), as pybullet gives a body's pose."""
    return np.hstack([matrix_from_quaternion(orientation), np.asarray(position, np.float64)[:, None]])


def rotation_z(angle: float) -> np.ndarray:
    """3x3 rotation about +z (yaw); exact for multiples of a quarter turn, so a model turned by
    90 degrees keeps its axis-aligned faces exactly axis-aligned."""
    quarter = angle / (math.pi / 2)
    if abs(quarter - round(quarter)) <= 1e-12:
        c, s = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[round(quarter) % 4]
    else:
        c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_y(angle: float) -> np.ndarray:
    """3x3 rotation about +y: a positive angle tips +x down towards -z (a sensor pitched down)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
