"""Laser against depth: do the two sensors see the same surfaces at the same distance?

The laser reads pybullet's collision shapes, the camera renders the visual meshes; they agree only
where the colliders are the shapes the camera draws. Three checks, each from one robot pose with both
sensors on it:

- :func:`laser_minus_depth`, the bias: each laser hit is projected into the depth image; where the
  pixel shows the same instance the beam hit (so nothing stands between the camera and that point),
  the depth image's z is compared with the hit point's z in the optical frame. Per class of surface
  (walls, objects, doors) the median of those differences is the bias between the sensors: positive
  when the laser hits nearer than the surface the camera sees.
- :func:`laser_beyond_depth`, nothing the camera draws is missing for the laser: every pixel of the
  depth image that shows a surface crossing the laser's plane (:func:`plane_pixels`) gets laser rays
  of its own, cast from the laser along that pixel's bearing; they must end on that surface or
  before it, never beyond (a wall piece pybullet had dropped from its compound let them through,
  ``ravh_sim.world.scene.COMPOUND_LIMIT``).
- :func:`depth_beyond_laser`, nothing the laser hits is missing for the camera: each beam's hit is
  projected into the depth image, and the depth image must not see past it.

Why "crossing" and not "near": a surface near the plane that does not cross it is not at laser
height. The shower tray of house 15's ``ShowerCabin_0`` tops out 14.7 mm under the laser's plane
(0.235 m above the floor, the laser at 0.25 m; the cabin's clear glass is not modelled, see
:mod:`ravh_sim.world.library`): the depth image shows that rim within 15 mm of the plane and the
laser rightly passes over it, through the open cabin to the wall behind. A band of a couple of
centimetres counts every such rim, table top or seat edge as a surface the laser "passes through"
(from a 1 m grid of house 15, 8 headings each, a 2 cm band counted 954 rays on ShowerCabin_0 and
hundreds on tables, stools and armchairs); a pixel whose neighbours lie both above and below the
plane shows a surface the plane really cuts (none of those).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ravh_sim.poses import matrix_from_quaternion
from ravh_sim.sensors.camera import Capture
from ravh_sim.sensors.laser import Laser
from ravh_sim.sensors.mount import floor_at
from ravh_sim.sensors.readings import Scan

CLASSES = {"walls": "walls", "object": "objects", "window": "objects", "door": "doors", "dressing": "dressing"}
"""Instance kind -> surface class reported."""
PLANE_BAND = 0.003
"""m: a depth pixel whose point lies this close to the laser's plane is on it (a pixel of the camera
spans 5-10 mm at 2-4 m, so a surface crossing the plane has a pixel within 3 mm of it)."""
PLANE_CROSSING = 0.001
"""m: the pixel's 3x3 neighbourhood reaches this far above and below the plane: the surface crosses
the plane rather than touching it (a table top exactly at the laser's height is seen edge-on by the
laser, a ray along it may or may not hit it)."""
CONTINUOUS = 0.02
"""m: every neighbour's point lies this close to the pixel's, on the same instance: one surface, not a
silhouette (a pixel at a silhouette lies on the edge of a triangle, where a ray may slip past)."""
NEIGHBOURS = tuple((dv, du) for dv in (-1, 0, 1) for du in (-1, 0, 1) if dv or du)


@dataclass(frozen=True)
class Overshoot:
    """Rays of one check and how far each went beyond what the other sensor saw (m; +inf: the ray
    reached nothing at all; <= 0: it stopped on the surface or before it)."""
    excess: np.ndarray             # (N,) float64
    instance: np.ndarray           # (N,) the instance the depth image shows (laser_beyond_depth) or
                                   # the laser hit (depth_beyond_laser)
    beam: np.ndarray               # (N,) the scan's beam nearest each ray's bearing
    distance: np.ndarray           # (N,) m from the laser to the pixel or the hit, along the floor

    def beyond(self, tolerance: float) -> np.ndarray:
        """Which rays went more than ``tolerance`` beyond."""
        return self.excess > tolerance

    def beyond_in_runs(self, tolerance: float, beams: int) -> np.ndarray:
        """Which rays went more than ``tolerance`` beyond on a beam in a run of at least ``beams``
        consecutive beams that all did: a surface one sensor misses over that many beams (a beam
        alone may graze an edge or a wire finer than a pixel, which the camera's raster misses)."""
        beyond = self.beyond(tolerance)
        hit = np.unique(self.beam[beyond])
        if not len(hit):
            return beyond
        starts = np.flatnonzero(np.diff(hit, prepend=hit[0] - 2) != 1)
        lengths = np.diff(np.append(starts, len(hit)))
        long = hit[np.repeat(lengths >= beams, lengths)]
        return beyond & np.isin(self.beam, long)


def laser_minus_depth(laser: Laser, scan: Scan, capture: Capture, pose: tuple[float, float, float],
                      per_instance: bool = False) -> dict:
    """Per class (or, with ``per_instance``, per instance id), depth-image z minus hit z (metres) of
    every beam of ``scan`` whose hit point the camera sees on the same instance; both sensors at
    robot pose ``pose``."""
    x, y, yaw = pose
    world = laser.world
    assert scan.hit_bodies is not None, "agreement needs a simulated scan (with the bodies hit)"
    hit = np.isfinite(scan.ranges)
    points = _hit_points(laser, scan, pose, hit)
    local, row, col, inside = _project(capture, points)
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


def plane_pixels(laser: Laser, capture: Capture, pose: tuple[float, float, float]
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(points (N, 3) in the house frame, instance ids (N,), farthest (N,)) of the depth pixels that
    show a surface crossing the plane of ``laser`` at robot pose ``pose``: within PLANE_BAND of the
    plane, their 3x3 neighbourhood on the same instance, within CONTINUOUS of them, reaching
    PLANE_CROSSING above and below the plane. ``farthest``: the largest distance from the laser,
    along the floor, of the pixel's neighbourhood, where the surface crosses the plane at the latest
    (a groove or a ledge finer than a pixel lies between the pixel and its neighbours)."""
    x, y, _ = pose
    plane = floor_at(laser.world, x, y) + laser.spec.height
    points = _depth_points(capture)
    along_floor = np.hypot(points[..., 0] - x, points[..., 1] - y)
    instance = capture.instance.astype(np.int64)
    height, width = instance.shape
    candidate = np.zeros((height, width), bool)
    candidate[1:-1, 1:-1] = True
    candidate &= (instance > 0) & (np.abs(points[..., 2] - plane) <= PLANE_BAND)   # NaN depth compares False
    rows, cols = np.nonzero(candidate)
    centre = points[rows, cols]
    keep = np.ones(len(rows), bool)
    low, high = np.full(len(rows), np.inf), np.full(len(rows), -np.inf)
    farthest = along_floor[rows, cols]
    for dv, du in NEIGHBOURS:
        neighbour = points[rows + dv, cols + du]
        keep &= instance[rows + dv, cols + du] == instance[rows, cols]
        keep &= np.linalg.norm(neighbour - centre, axis=1) < CONTINUOUS
        low, high = np.fmin(low, neighbour[:, 2]), np.fmax(high, neighbour[:, 2])
        farthest = np.fmax(farthest, along_floor[rows + dv, cols + du])
    keep &= (low < plane - PLANE_CROSSING) & (high > plane + PLANE_CROSSING)
    return centre[keep], instance[rows[keep], cols[keep]], farthest[keep]


def laser_beyond_depth(laser: Laser, capture: Capture, pose: tuple[float, float, float]) -> Overshoot:
    """For every pixel of :func:`plane_pixels`: how far the laser, cast at it, goes beyond it. Two
    level rays start at the laser (robot pose ``pose``), one at the laser's height and one at the
    pixel's (within PLANE_BAND of it), and run along the pixel's bearing through pybullet's
    collision world, as the laser's beams do; the excess is where the nearer one ends minus the
    farthest distance of the pixel's neighbourhood (+inf: neither hit anything within range_max), so
    a ray may enter a groove finer than a pixel, never pass a surface. The ray at the pixel's height
    meets a slanted surface exactly at the pixel, the one at the laser's height meets the side of a
    board whose top edge the pixel shows. One ray per pixel, not per beam: a beam's fixed angle
    would pass beside a thin leg that the pixels next to it show."""
    x, y, yaw = pose
    plane = floor_at(laser.world, x, y) + laser.spec.height
    points, instance, farthest = plane_pixels(laser, capture, pose)
    flat = points[:, :2] - np.array([x, y])
    distance = np.linalg.norm(flat, axis=1)
    keep = (distance > laser.spec.range_min) & (farthest < laser.spec.range_max)
    points, instance, flat = points[keep], instance[keep], flat[keep]
    distance, farthest = distance[keep], farthest[keep]
    directions = np.column_stack([flat / distance[:, None], np.zeros(len(distance))])
    reached = np.full(len(distance), np.inf)
    for height in (points[:, 2], np.full(len(distance), plane)):
        starts = np.column_stack([np.full(len(distance), x), np.full(len(distance), y), height])
        for first in range(0, len(distance), _RAYS_PER_BATCH):
            batch = slice(first, first + _RAYS_PER_BATCH)
            bodies, hits = laser.world.cast_rays(starts[batch],
                                                 starts[batch] + directions[batch] * laser.spec.range_max)
            along = np.einsum("ij,ij->i", np.nan_to_num(hits - starts[batch]), directions[batch])
            reached[batch] = np.fmin(reached[batch], np.where(bodies >= 0, along, np.inf))
    bearing = np.arctan2(flat[:, 1], flat[:, 0]) - yaw
    return Overshoot(reached - farthest, instance, _nearest_beam(laser, bearing), distance)


PIXEL_SLACK = 2.0
"""Pixels' footprint at a laser hit that the depth image may see past it: an edge seen at a grazing
angle lies up to that far in depth from the pixel centres beside it (2.3 cm a pixel at 12 m)."""


def depth_beyond_laser(laser: Laser, scan: Scan, capture: Capture, pose: tuple[float, float, float],
                       far: float) -> Overshoot:
    """For every beam of ``scan`` that hit something the camera frames (robot pose ``pose``) nearer
    than its far clip plane ``far`` (m): how far past the hit the depth image sees, along the
    camera's line of sight to it: the nearest depth of the 3x3 pixels around the hit's projection
    minus the hit's depth, less PIXEL_SLACK pixels' footprint there (+inf: those pixels show
    nothing). Positive where the camera sees through what the laser hit; anything in front of the
    hit (an occluder above the laser's plane) only makes it more negative."""
    assert scan.hit_bodies is not None, "agreement needs a simulated scan (with the bodies hit)"
    hit = np.flatnonzero(np.isfinite(scan.ranges))
    points = _hit_points(laser, scan, pose, hit)
    local, row, col, inside = _project(capture, points)
    height, width = capture.depth.shape
    inside &= (row >= 1) & (row < height - 1) & (col >= 1) & (col < width - 1) & (local[:, 2] < far)
    hit, local, row, col = hit[inside], local[inside], row[inside], col[inside]
    nearest = np.full(len(hit), np.inf)
    for dv, du in (*NEIGHBOURS, (0, 0)):
        nearest = np.fmin(nearest, np.nan_to_num(capture.depth[row + dv, col + du], nan=np.inf))
    instance = laser.world.body_to_instance_lut()[scan.hit_bodies[hit]]
    footprint = local[:, 2] / min(capture.K[0, 0], capture.K[1, 1])       # m a pixel spans at the hit
    return Overshoot(nearest - local[:, 2] - PIXEL_SLACK * footprint, instance, hit,
                     scan.ranges[hit].astype(np.float64))


_RAYS_PER_BATCH = 16000            # below pybullet's rayTestBatch limit (ravh_sim.sensors.laser.MAX_RAYS)


def _hit_points(laser: Laser, scan: Scan, pose: tuple[float, float, float], beams: np.ndarray) -> np.ndarray:
    """(N, 3) house-frame end points of the ``beams`` (a mask or indices) of a scan that hit something."""
    x, y, yaw = pose
    angles = laser.angles[beams] + yaw
    z = floor_at(laser.world, x, y) + laser.spec.height
    ranges = scan.ranges[beams].astype(np.float64)
    return np.stack([x + ranges * np.cos(angles), y + ranges * np.sin(angles), np.full(len(ranges), z)], axis=1)


def _project(capture: Capture, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points in the optical frame (x right, y down, z ahead), the row and column of the pixel each
    falls in, and which fall in front of the camera inside the image."""
    rotation = matrix_from_quaternion(capture.orientation)
    local = (points - capture.position) @ rotation
    ahead = local[:, 2] > 1e-6
    uv = local[:, :2] / np.where(ahead, local[:, 2], 1.0)[:, None] * np.diag(capture.K)[:2] + capture.K[:2, 2]
    col, row = np.round(uv[:, 0]).astype(int), np.round(uv[:, 1]).astype(int)
    height, width = capture.depth.shape
    return local, row, col, ahead & (col >= 0) & (col < width) & (row >= 0) & (row < height)


def _depth_points(capture: Capture) -> np.ndarray:
    """(H, W, 3) house-frame point of every pixel of the depth image (NaN where it shows nothing)."""
    height, width = capture.depth.shape
    rows, cols = np.mgrid[0:height, 0:width]
    k = capture.K
    rays = np.stack([(cols - k[0, 2]) / k[0, 0], (rows - k[1, 2]) / k[1, 1], np.ones((height, width))], axis=-1)
    return (rays * capture.depth[..., None]) @ matrix_from_quaternion(capture.orientation).T + capture.position


def _nearest_beam(laser: Laser, bearing: np.ndarray) -> np.ndarray:
    """Index of the scan's beam nearest each bearing (rad, robot frame)."""
    count = len(laser.angles)
    index = np.round((bearing - laser.angle_min) / laser.angle_increment).astype(int)
    return np.mod(index, count) if laser.spec.fov_deg >= 360.0 - 1e-9 else np.clip(index, 0, count - 1)
