"""Laser against depth: do the two sensors see the same surfaces at the same distance?

The laser reads pybullet's collision shapes, the camera renders the visual meshes; they agree only
where the colliders are the shapes the camera draws. Each laser hit is projected into a depth image
taken from the same robot pose; where the pixel shows the same instance the beam hit (so nothing
stands between the camera and that point), the depth image's z is compared with the hit point's z
in the optical frame. Per class of surface (walls, objects, doors) the median of those differences
is the bias between the sensors: positive when the laser hits nearer than the surface the camera
sees.
"""
from __future__ import annotations

import numpy as np

from ravh_sim.poses import matrix_from_quaternion
from ravh_sim.sensors.camera import Capture
from ravh_sim.sensors.laser import Laser
from ravh_sim.sensors.mount import floor_at
from ravh_sim.sensors.readings import Scan

CLASSES = {"walls": "walls", "object": "objects", "window": "objects", "door": "doors"}
"""Instance kind -> surface class reported."""


def laser_minus_depth(laser: Laser, scan: Scan, capture: Capture, pose: tuple[float, float, float],
                      per_instance: bool = False) -> dict:
    """Per class (or, with ``per_instance``, per instance id), depth-image z minus hit z (metres) of
    every beam of ``scan`` whose hit point the camera sees on the same instance; both sensors at
    robot pose ``pose``."""
    x, y, yaw = pose
    world = laser.world
    assert scan.hit_bodies is not None, "agreement needs a simulated scan (with the bodies hit)"
    hit = np.isfinite(scan.ranges)
    angles = laser.angles[hit] + yaw
    z = floor_at(world, x, y) + laser.spec.height
    points = np.stack([x + scan.ranges[hit] * np.cos(angles), y + scan.ranges[hit] * np.sin(angles),
                       np.full(hit.sum(), z)], axis=1)
    rotation = matrix_from_quaternion(capture.orientation)
    local = (points - capture.position) @ rotation            # optical frame: x right, y down, z ahead
    ahead = local[:, 2] > 1e-6
    uv = local[:, :2] / np.where(ahead, local[:, 2], 1.0)[:, None] * np.diag(capture.K)[:2] + capture.K[:2, 2]
    col, row = np.round(uv[:, 0]).astype(int), np.round(uv[:, 1]).astype(int)
    height, width = capture.depth.shape
    inside = ahead & (col >= 0) & (col < width) & (row >= 0) & (row < height)
    lut = world.body_to_instance_lut()
    instance = lut[scan.hit_bodies[hit]]
    seen = np.zeros(len(points), bool)
    seen[inside] = capture.instance[row[inside], col[inside]] == instance[inside]
    differences = capture.depth[row[seen], col[seen]] - local[seen, 2]
    if per_instance:
        return {int(i): differences[instance[seen] == i] for i in np.unique(instance[seen])}
    kinds = {inst.id: CLASSES.get(inst.kind) for inst in world.instances}
    labels = np.array([kinds.get(int(i)) for i in instance[seen]], dtype=object)
    return {name: differences[labels == name] for name in set(CLASSES.values())}
