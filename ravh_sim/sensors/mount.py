"""Where a sensor sits: from a robot pose on the floor to the sensor's pose in the house frame.

A robot pose is (x, y, yaw) on the floor (REP 103, z up); sensors are mounted at a height above that
floor, possibly ahead of the base centre and pitched down. Frame names come from
:mod:`ravh_msgs_py.names`, so the images, the scans and the TF tree agree.
"""
from __future__ import annotations

import math

import numpy as np

from ravh_msgs_py.names import CAMERA_OPTICAL_FRAME, LASER_FRAME
from ravh_sim.world.scene import World

__all__ = ["CAMERA_OPTICAL_FRAME", "LASER_FRAME", "LINK_TO_OPTICAL", "floor_at", "mount_position",
           "mount_rotation", "quaternion_from_matrix"]

# Columns: the optical frame's axes (x right, y down, z forward) in the camera_link frame; as a
# quaternion (x, y, z, w) this is the usual (-0.5, 0.5, -0.5, 0.5).
LINK_TO_OPTICAL = np.array([[0.0, 0.0, 1.0],
                            [-1.0, 0.0, 0.0],
                            [0.0, -1.0, 0.0]])


def floor_at(world: World, x: float, y: float) -> float:
    """Floor height under (x, y): the room's floor, or the house's usual floor outside every room."""
    room = world.house.room_at(x, y)
    return room.floor_z if room is not None else world.floor_z


def mount_rotation(yaw: float, pitch_down: float = 0.0) -> np.ndarray:
    """Rotation (3x3, columns = axes in the house frame) of a sensor link yawed then pitched down."""
    cy, sy = math.cos(yaw), math.sin(yaw)
    cp, sp = math.cos(pitch_down), math.sin(pitch_down)
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])   # +pitch about y tips x down
    return rz @ ry


def mount_position(x: float, y: float, yaw: float, floor_z: float, height: float,
                   forward: float = 0.0) -> np.ndarray:
    return np.array([x + forward * math.cos(yaw), y + forward * math.sin(yaw), floor_z + height])


def quaternion_from_matrix(r: np.ndarray) -> tuple[float, float, float, float]:
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
    return tuple(float(sign * v) for v in q)
