"""The laser scanner: one horizontal fan of rays through pybullet's collision world (REP 117 ranges).

Rays go out from the laser height in a few ray batches (:meth:`World.cast_rays`) of growing length (see
:meth:`Laser._trace`). Ranges follow REP 117: +inf where nothing is hit within ``range_max``, -inf
where the hit is closer than ``range_min``. The robot's own body must not shadow the scan: ignored
bodies sit in collision groups that the rays' mask leaves out (:meth:`World.ray_mask`), so no ray
ever hits them, wherever it starts (a ray starting inside a convex body may or may not hit it).
Open doors are moved out of the house by the World, so the laser sees through open doorways;
closed doors, walls and furniture parts (legs, not their bounding boxes) stop it. Noise is
Gaussian, seeded from the world seed, the agent and a scan counter. :class:`LaserSection` is the
laser's section of a robot profile, :data:`PORT` the laser as a sensor port (ravh_sim.sensors.ports).
"""
from __future__ import annotations

import io
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NamedTuple

import numpy as np
from pydantic import Field, model_validator

from ravh_msgs_py import names
from ravh_sim.poses import quaternion_from_matrix
from ravh_sim.schema import FINITE, Length, Range, Rate, Sigma, Strict
from ravh_sim.sensors.mount import LASER_FRAME, floor_at, mount_position, mount_rotation
from ravh_sim.sensors.ports import Carrier, Mount, SensorPort, Stored, Topic, noise_rng
from ravh_sim.sensors.readings import Scan

if TYPE_CHECKING:
    from ravh_sim.world.scene import World

NOISE_STREAM = 2            # noise generator stream of lasers (cameras use another)
MAX_RAYS = 16384            # pybullet's rayTestBatch limit: more ends the sim with "Number of rays exceed..."
STAGES = (1.5, 4.0, 10.0)   # m: ray lengths of the first cast stages (then range_max)
STAGE_OVERLAP = 0.01        # m: a stage starts this much before the previous one ended


@dataclass(frozen=True)
class LaserSpec:
    """What a laser is built with (from its profile section)."""
    height: float            # m above the floor
    fov_deg: float
    resolution_deg: float
    range_min: float
    range_max: float
    rate: float              # Hz: scans published (and LaserScan.scan_time)
    noise_sigma: float       # m

    @property
    def ray_count(self) -> int:
        """REP 117 / LaserScan counting: round((max - min) / increment) + 1 for a partial fan,
        one ray per increment for a full circle (the last ray would repeat the first)."""
        if self.fov_deg >= 360.0 - 1e-9:
            return int(round(360.0 / self.resolution_deg))
        return int(round(self.fov_deg / self.resolution_deg)) + 1


class LaserSection(Strict):
    """The ``laser:`` section of a robot profile."""
    height: Length
    fov: Annotated[float, Field(gt=0.0, le=360.0), FINITE]
    resolution: Annotated[float, Field(ge=0.01, le=360.0), FINITE]
    range_min: Range
    range_max: Range
    rate: Rate
    noise_sigma: Sigma

    @model_validator(mode="after")
    def _ordered(self) -> LaserSection:
        if self.range_min >= self.range_max:
            raise ValueError(f"range_min {self.range_min} must be below range_max {self.range_max}")
        if self.resolution > self.fov:
            raise ValueError(f"resolution {self.resolution} is wider than fov {self.fov}")
        if self.fov / self.resolution + 1 > MAX_RAYS:
            raise ValueError(f"fov {self.fov} / resolution {self.resolution} makes more than {MAX_RAYS} rays "
                             f"(what pybullet casts in one batch)")
        return self



class Laser:
    """A planar laser scanner mounted at the robot's base centre."""

    def __init__(self, world: World, spec: LaserSpec, agent: str = names.DEFAULT_AGENT) -> None:
        self.world, self.spec, self.agent = world, spec, agent
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
        bodies, distances = self._trace(np.array([x, y, z]), directions, self.world.ray_mask(ignore_bodies))
        ranges = distances.astype(np.float32)
        if spec.noise_sigma > 0:
            rng = noise_rng(self.world.state.seed, NOISE_STREAM, self.agent, self.count)
            noisy = ranges + rng.standard_normal(len(ranges)).astype(np.float32) * spec.noise_sigma
            ranges = np.where(np.isfinite(ranges), np.clip(noisy, spec.range_min, spec.range_max), ranges)
        ranges[ranges < spec.range_min] = -np.inf
        scan = Scan(LASER_FRAME, self.angle_min, self.angle_max, self.angle_increment,
                    self.scan_time / len(self.angles), self.scan_time, spec.range_min, spec.range_max,
                    ranges, bodies.astype(np.int32), self.count)
        self.count += 1
        return scan

    def _trace(self, origin: np.ndarray, directions: np.ndarray, mask: int) -> tuple[np.ndarray, np.ndarray]:
        """(first body hit or -1, its distance or +inf) per ray, among bodies that ``mask`` sees.

        Bullet's ray test walks every bounding box a ray crosses over its whole length, so a scan
        is cast in growing stages (STAGES, then range_max): a ray that hits something stops, the
        others go on from where they ended. Indoors most rays stop in the first stages, which
        halves the cost of one full-length batch.
        """
        n = len(directions)
        bodies, distances = np.full(n, -1, np.int64), np.full(n, np.inf)
        todo, start = np.arange(n), 0.0
        for end in [e for e in STAGES if e < self.spec.range_max] + [self.spec.range_max]:
            body, points = self.world.cast_rays(origin + directions[todo] * start,
                                                origin + directions[todo] * end, mask)
            found = body >= 0
            point = points[found]
            bodies[todo[found]] = body[found]
            distances[todo[found]] = np.einsum("ij,ij->i", point - origin, directions[todo[found]])
            todo, start = todo[~found], end - STAGE_OVERLAP
            if not todo.size:
                break
        return bodies, distances


# ---------------------------------------------------------------------------- the laser as a port

class StoredScan(NamedTuple):
    """One scan as a dataset stores it: angles (rad) and ranges (m) as published (inf/NaN kept)."""
    angles: np.ndarray
    ranges: np.ndarray
    range_min: float
    range_max: float


def float32(value: float) -> float:
    """``value`` as a float32 field of LaserScan carries it, so a sample stores the same numbers
    whether it was read here or decoded from the topic."""
    return float(np.float32(value))


def encode_scan(ranges: np.ndarray, angle_min: float, angle_increment: float) -> bytes:
    """.npy bytes of the (N, 2) float32 [angle, range] array stored per capture."""
    ranges = np.asarray(ranges, np.float32).reshape(-1)
    angles = angle_min + angle_increment * np.arange(len(ranges), dtype=np.float64)
    buf = io.BytesIO()
    np.save(buf, np.column_stack((angles.astype(np.float32), ranges)), allow_pickle=False)
    return buf.getvalue()


class LaserPort(SensorPort[LaserSpec, Laser, Scan]):
    """The laser: one scan topic, streamed and stored as a (N, 2) .npy with its limits in the row."""
    name = "scan"
    section = "laser"
    schema = LaserSection
    frame = names.LASER_FRAME
    captured = False
    topics = (Topic("scan", names.SCAN, "laser_scan", dataset=True, bag=True),)
    files = {"scan": ".npy"}

    def spec(self, section: LaserSection) -> LaserSpec:
        return LaserSpec(section.height, section.fov, section.resolution, section.range_min, section.range_max,
                         section.rate, section.noise_sigma)

    def rate(self, spec: LaserSpec) -> float:
        return spec.rate

    def mounts(self, spec: LaserSpec) -> list[Mount]:
        return [(names.BASE_FRAME, names.LASER_FRAME, tuple(mount_position(0.0, 0.0, 0.0, 0.0, spec.height)),
                 quaternion_from_matrix(mount_rotation(0.0)))]

    def build(self, world: World, spec: LaserSpec, agent: str, backend: str = "auto") -> Laser:
        return Laser(world, spec, agent)

    def read(self, sensor: Laser, carrier: Carrier) -> Scan:
        x, y, yaw = carrier.pose
        return sensor.scan(x, y, yaw, ignore_bodies=(carrier.body,))

    def value(self, key: str, data: Scan, sensor: Laser, frame: str) -> Scan:
        return data

    def encode(self, values: Mapping[str, Any]) -> Stored:
        scan: Scan = values["scan"]
        meta = {k: float32(getattr(scan, k)) for k in ("angle_min", "angle_increment", "range_min", "range_max")}
        return Stored({"scan": encode_scan(scan.ranges, meta["angle_min"], meta["angle_increment"])},
                      row={"scan": meta})

    def decode(self, kind: str, path: Path, row: Mapping[str, Any]) -> StoredScan:
        data = np.load(path, allow_pickle=False)
        return StoredScan(data[:, 0], data[:, 1], row["scan"]["range_min"], row["scan"]["range_max"])


PORT = LaserPort()
