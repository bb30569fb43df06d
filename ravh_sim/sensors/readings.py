"""What sensors return, as plain data: the values the ports publish and the recorder decodes.

Kept apart from the sensors themselves (which need pybullet and a renderer), so the message
conversions (ravh_sim.nodes.convert) and nodes that only read topics can use them without loading a
simulator.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CameraInfo:
    """The fields of sensor_msgs/CameraInfo (row-major matrices)."""
    frame_id: str
    width: int
    height: int
    distortion_model: str
    D: tuple[float, ...]
    K: tuple[float, ...]
    R: tuple[float, ...]
    P: tuple[float, ...]


@dataclass
class Scan:
    """The fields of sensor_msgs/LaserScan, and what only the simulator knows (``hit_bodies``, ``index``)."""
    frame_id: str
    angle_min: float
    angle_max: float
    angle_increment: float
    time_increment: float
    scan_time: float
    range_min: float
    range_max: float
    ranges: np.ndarray                     # float32, REP 117: +inf no return, -inf too close
    hit_bodies: np.ndarray | None = None   # int32 pybullet body per ray, -1 none (ground truth)
    index: int = -1                        # scan counter (noise stream); -1 when decoded from a message
