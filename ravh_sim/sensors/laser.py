"""The laser scanner: one horizontal fan of rays through pybullet's collision world (REP 117 ranges).

All rays go out in one ``rayTestBatch`` from the laser height. Ranges follow REP 117: +inf where
nothing is hit within ``range_max``, -inf where the hit is closer than ``range_min``. The robot's own
body must not shadow the scan, but a batch cannot skip bodies: rays whose first hit is an ignored
body are cast again (one more batch for just those rays) from where they leave that body's bounding
box, so a scan costs one batch when nothing is ignored. Open doors are moved out of the house by the
World, so the laser sees through open doorways; closed doors, walls and furniture stop it. Noise is
Gaussian, seeded from the world seed and a scan counter.
"""
from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import pybullet as pb

from ravh_sim.robot.profile import LaserSpec
from ravh_sim.sensors.mount import LASER_FRAME, floor_at
from ravh_sim.world.scene import World

NOISE_STREAM = 2            # noise generator stream of lasers (cameras use another)
RECAST_GAP = 1e-3           # m beyond an ignored body's box where a re-cast ray starts


@dataclass
class Scan:
    """The fields of sensor_msgs/LaserScan."""
    frame_id: str
    angle_min: float
    angle_max: float
    angle_increment: float
    time_increment: float
    scan_time: float
    range_min: float
    range_max: float
    ranges: np.ndarray                     # float32, REP 117: +inf no return, -inf too close
    hit_bodies: np.ndarray                 # int32 pybullet body per ray, -1 none (ground truth)
    index: int


class Laser:
    """A planar laser scanner mounted at the robot's base centre."""

    def __init__(self, world: World, spec: LaserSpec) -> None:
        self.world, self.spec = world, spec
        n = spec.ray_count
        increment = math.radians(spec.resolution_deg)
        if spec.fov_deg >= 360.0 - 1e-9:
            self.angle_min = -math.pi
            increment = 2.0 * math.pi / n
        else:
            self.angle_min = -math.radians(spec.fov_deg) / 2.0
        self.angle_increment = increment
        self.angle_max = self.angle_min + (n - 1) * increment
        self.angles = self.angle_min + increment * np.arange(n)
        self.scan_time = 1.0 / spec.rate
        self.count = 0

    def scan(self, x: float, y: float, yaw: float, floor_z: float | None = None,
             ignore_bodies: Iterable[int] = ()) -> Scan:
        spec = self.spec
        z = (floor_at(self.world, x, y) if floor_z is None else floor_z) + spec.height
        directions = np.stack([np.cos(self.angles + yaw), np.sin(self.angles + yaw),
                               np.zeros(len(self.angles))], axis=1)
        origin = np.array([x, y, z])
        starts = np.broadcast_to(origin, directions.shape)
        ends = origin + directions * spec.range_max
        bodies, distances = self._cast(starts, ends, directions, origin)
        ignored = np.isin(bodies, list(ignore_bodies))
        if ignored.any():
            exits = np.array([_box_exit(origin, d, pb.getAABB(int(b), physicsClientId=self.world.client))
                              for d, b in zip(directions[ignored], bodies[ignored])]) + RECAST_GAP
            again = origin + directions[ignored] * np.minimum(exits, spec.range_max)[:, None]
            b2, d2 = self._cast(again, ends[ignored], directions[ignored], origin)
            bodies[ignored], distances[ignored] = b2, d2
        ranges = distances.astype(np.float32)
        if spec.noise_sigma > 0:
            rng = np.random.default_rng([self.world.settings.seed, NOISE_STREAM, self.count])
            noisy = ranges + rng.standard_normal(len(ranges)).astype(np.float32) * spec.noise_sigma
            ranges = np.where(np.isfinite(ranges), np.clip(noisy, spec.range_min, spec.range_max), ranges)
        ranges[ranges < spec.range_min] = -np.inf
        scan = Scan(LASER_FRAME, self.angle_min, self.angle_max, self.angle_increment,
                    self.scan_time / len(self.angles), self.scan_time, spec.range_min, spec.range_max,
                    ranges.astype(np.float32), bodies.astype(np.int32), self.count)
        self.count += 1
        return scan

    def _cast(self, starts: np.ndarray, ends: np.ndarray, directions: np.ndarray, origin: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
        """(body hit or -1, distance from ``origin`` or +inf) per ray."""
        hits = pb.rayTestBatch(starts.tolist(), ends.tolist(), physicsClientId=self.world.client)
        bodies = np.array([h[0] for h in hits], np.int64)
        points = np.array([h[3] for h in hits], float)
        distances = np.einsum("ij,ij->i", points - origin, directions)
        distances[bodies < 0] = np.inf
        return bodies, distances


def _box_exit(origin: np.ndarray, direction: np.ndarray, aabb) -> float:
    """Distance along a ray from ``origin`` to where it leaves an axis-aligned box (slab method)."""
    lo, hi = np.asarray(aabb[0]), np.asarray(aabb[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (lo - origin) / direction, (hi - origin) / direction
    far = np.where(direction != 0, np.maximum(t1, t2), np.inf)
    return float(max(far.min(), 0.0))
