"""Where a sensor sits: from a robot pose on the floor to the sensor's pose in the house frame.

A robot pose is (x, y, yaw) on the floor (REP 103, z up); sensors are mounted at a height above that
floor, possibly ahead of the base centre and pitched down. Frame names come from
:mod:`ravh_msgs_py.names`, so the images, the scans and the TF tree agree.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ravh_msgs_py.names import CAMERA_OPTICAL_FRAME, LASER_FRAME
from ravh_sim.poses import rotation_y, rotation_z

if TYPE_CHECKING:
    from ravh_sim.world.scene import World

__all__ = ["CAMERA_OPTICAL_FRAME", "LASER_FRAME", "LINK_TO_OPTICAL", "floor_at", "mount_position",
           "mount_rotation"]

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
    return rotation_z(yaw) @ rotation_y(pitch_down)


def mount_position(x: float, y: float, yaw: float, floor_z: float, height: float,
                   forward: float = 0.0) -> np.ndarray:
    return np.array([x + forward * math.cos(yaw), y + forward * math.sin(yaw), floor_z + height])
