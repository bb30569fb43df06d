"""Robot profiles (``config/robots/*.yaml``): body, motion limits and sensor mounting in one place.

Validated by a pydantic schema (every field typed and bounded) and loaded into frozen dataclasses, so
every consumer (physics, sensors, navigation, nodes) reads the same checked numbers; a bad value names
the file and the field.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, model_validator

from ravh_msgs_py.names import DEFAULT_PROFILE
from ravh_sim.errors import UnknownNameError
from ravh_sim.paths import ROBOTS_DIR
from ravh_sim.render.backend import QUALITIES
from ravh_sim.schema import FINITE, Strict, load_yaml, read_text, validate
from ravh_sim.sensors.imaging import SensorModel


@dataclass(frozen=True)
class LaserSpec:
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


@dataclass(frozen=True)
class CameraSpec:
    height: float            # m above the floor
    pitch_deg: float         # down
    forward: float           # m ahead of the base centre
    width: int               # px
    height_px: int           # px
    sensor_width: float      # mm
    sensor_height: float     # mm
    focal_length: float      # mm
    near: float              # m
    far: float               # m
    rate: float              # Hz: frames published
    quality: str = "realistic"   # realistic | fast (ravh_sim.render.backend.QUALITIES)

    @property
    def fx(self) -> float:
        """The paper's formula: fx = f * rx / sx."""
        return self.focal_length * self.width / self.sensor_width

    @property
    def fy(self) -> float:
        return self.focal_length * self.height_px / self.sensor_height

    @property
    def cx(self) -> float:
        return self.width / 2.0

    @property
    def cy(self) -> float:
        return self.height_px / 2.0


@dataclass(frozen=True)
class RobotProfile:
    name: str
    radius: float
    height: float
    mass: float
    max_linear_speed: float          # m/s
    max_angular_speed: float         # rad/s
    max_linear_acceleration: float   # m/s^2
    max_angular_acceleration: float  # rad/s^2
    odom_linear_sigma: float         # m per metre driven
    odom_angular_sigma: float        # rad per radian turned
    odom_rate: float                 # Hz: odometry, ground-truth pose and /tf
    laser: LaserSpec
    camera: CameraSpec
    camera_effects: tuple[tuple[str, Any], ...] = ()   # CameraOptions fields set by the profile
    camera_sensor: SensorModel | None = None            # None: the ideal camera (no sensor model)


def available_profiles() -> list[str]:
    return sorted(p.stem for p in ROBOTS_DIR.glob("*.yaml"))


# bounds: anything a real mobile robot could have; beyond them a value is a slip (a 1e6 m radius,
# a 1e-7 degree laser resolution that would allocate gigabytes, a 0.5 px camera)
Length = Annotated[float, Field(gt=0.0, le=10.0), FINITE]           # m, body and mounting
Rate = Annotated[float, Field(gt=0.0, le=1000.0), FINITE]           # Hz
Sigma = Annotated[float, Field(ge=0.0, le=10.0), FINITE]
Range = Annotated[float, Field(gt=0.0, le=1000.0), FINITE]          # m
Pixels = Annotated[int, Field(ge=16, le=8192)]
Coefficient = Annotated[float, Field(ge=-10.0, le=10.0), FINITE]     # of lens distortion
MAX_RAYS = 16384           # pybullet's rayTestBatch limit: more ends the sim with "Number of rays exceed..."
MIN_NEAR = 0.001           # m, camera near plane: 1e-300 made the projection matrix singular


class _Odometry(Strict):
    rate: Rate
    linear_sigma: Sigma
    angular_sigma: Sigma


class _Laser(Strict):
    height: Length
    fov: Annotated[float, Field(gt=0.0, le=360.0), FINITE]
    resolution: Annotated[float, Field(ge=0.01, le=360.0), FINITE]
    range_min: Range
    range_max: Range
    rate: Rate
    noise_sigma: Sigma

    @model_validator(mode="after")
    def _ordered(self) -> _Laser:
        if self.range_min >= self.range_max:
            raise ValueError(f"range_min {self.range_min} must be below range_max {self.range_max}")
        if self.resolution > self.fov:
            raise ValueError(f"resolution {self.resolution} is wider than fov {self.fov}")
        if self.fov / self.resolution + 1 > MAX_RAYS:
            raise ValueError(f"fov {self.fov} / resolution {self.resolution} makes more than {MAX_RAYS} rays "
                             f"(what pybullet casts in one batch)")
        return self


class _Effects(Strict):
    """The bounds of the realism effects the profile sets; their defaults live in sensors.camera.CameraOptions
    (an effect left out or null takes that default)."""
    jpeg_quality: Annotated[int, Field(ge=1, le=100)] | None = None
    jpeg_roundtrip: bool | None = None
    pixel_noise: Annotated[float, Field(ge=0.0, le=255.0), FINITE] | None = None
    distortion: Annotated[tuple[Coefficient, Coefficient, Coefficient, Coefficient, Coefficient],
                          Field(strict=False)] | None = None
    motion_blur: bool | None = None
    exposure: Annotated[float, Field(gt=0.0, le=1.0), FINITE] | None = None
    depth_noise: Annotated[float, Field(ge=0.0, le=1.0), FINITE] | None = None
    manual_exposure: Annotated[float, Field(gt=0.0, le=100.0), FINITE] | None = None


class _Sensor(Strict):
    """The camera sensor model (ravh_sim.sensors.imaging.SensorModel); a field left out takes its default."""
    enabled: bool = True
    exposure_min: Annotated[float, Field(gt=0.0, le=1.0), FINITE] | None = None        # s
    exposure_max: Annotated[float, Field(gt=0.0, le=1.0), FINITE] | None = None        # s
    gain_max: Annotated[float, Field(ge=1.0, le=1000.0), FINITE] | None = None
    full_well: Annotated[float, Field(gt=0.0, le=1e7), FINITE] | None = None           # e-
    read_noise: Annotated[float, Field(ge=0.0, le=1000.0), FINITE] | None = None       # e- rms
    sensitivity: Annotated[float, Field(gt=0.0, le=1e12), FINITE] | None = None       # e- / s / radiance
    target: Annotated[float, Field(gt=0.0, le=1.0), FINITE] | None = None
    adc_bits: Annotated[int, Field(ge=1, le=16)] | None = None
    white_balance: bool | None = None
    white_balance_limit: Annotated[float, Field(ge=1.0, le=100.0), FINITE] | None = None
    reference_exposure: Annotated[float, Field(gt=0.0, le=100.0), FINITE] | None = None

    @model_validator(mode="after")
    def _ordered(self) -> _Sensor:
        model = self.model()
        if model is not None and model.exposure_min > model.exposure_max:
            raise ValueError(f"exposure_min {model.exposure_min} must not exceed exposure_max {model.exposure_max}")
        return self

    def model(self) -> SensorModel | None:
        if not self.enabled:
            return None
        return SensorModel(**self.model_dump(exclude_none=True, exclude={"enabled"}))


class _Camera(Strict):
    height: Length
    pitch: Annotated[float, Field(ge=-90.0, le=90.0), FINITE]
    forward: Annotated[float, Field(ge=-10.0, le=10.0), FINITE]
    width: Pixels
    height_px: Pixels
    sensor_width: Annotated[float, Field(gt=0.0, le=100.0), FINITE]     # mm
    sensor_height: Annotated[float, Field(gt=0.0, le=100.0), FINITE]
    focal_length: Annotated[float, Field(gt=0.0, le=1000.0), FINITE]
    near: Annotated[float, Field(ge=MIN_NEAR, le=1000.0), FINITE]      # m
    far: Range
    rate: Rate
    quality: Literal[QUALITIES] = "realistic"         # type: ignore[valid-type]
    effects: _Effects = _Effects()
    sensor: _Sensor = _Sensor(enabled=False)

    @model_validator(mode="after")
    def _ordered(self) -> _Camera:
        if self.near >= self.far:
            raise ValueError(f"near {self.near} must be below far {self.far}")
        return self


class ProfileFile(Strict):
    """The schema of config/robots/*.yaml."""
    name: Annotated[str, Field(min_length=1, max_length=64)]
    footprint_radius: Length
    height: Length
    mass: Annotated[float, Field(gt=0.0, le=10_000.0), FINITE]
    max_linear_speed: Annotated[float, Field(gt=0.0, le=10.0), FINITE]             # m/s
    max_angular_speed: Annotated[float, Field(gt=0.0, le=1000.0), FINITE]          # deg/s
    max_linear_acceleration: Annotated[float, Field(gt=0.0, le=100.0), FINITE]     # m/s^2
    max_angular_acceleration: Annotated[float, Field(gt=0.0, le=10_000.0), FINITE] # deg/s^2
    odometry: _Odometry
    laser: _Laser
    camera: _Camera


def load_profile(name_or_path: str | Path = DEFAULT_PROFILE) -> RobotProfile:
    path = Path(name_or_path)
    if path.suffix not in (".yaml", ".yml"):
        path = ROBOTS_DIR / f"{name_or_path}.yaml"
        if not path.exists():
            raise UnknownNameError("robot profile", str(name_or_path), available_profiles())
    data = load_yaml(read_text(path, "robot profile"), path)
    f = validate(ProfileFile, data, path)
    lz, cam, effects = f.laser, f.camera, f.camera.effects
    return RobotProfile(
        name=f.name, radius=f.footprint_radius, height=f.height, mass=f.mass,
        max_linear_speed=f.max_linear_speed, max_angular_speed=math.radians(f.max_angular_speed),
        max_linear_acceleration=f.max_linear_acceleration,
        max_angular_acceleration=math.radians(f.max_angular_acceleration),
        odom_linear_sigma=f.odometry.linear_sigma,
        odom_angular_sigma=math.radians(f.odometry.angular_sigma), odom_rate=f.odometry.rate,
        laser=LaserSpec(lz.height, lz.fov, lz.resolution, lz.range_min, lz.range_max, lz.rate, lz.noise_sigma),
        camera=CameraSpec(cam.height, cam.pitch, cam.forward, cam.width, cam.height_px, cam.sensor_width,
                          cam.sensor_height, cam.focal_length, cam.near, cam.far, cam.rate, cam.quality),
        camera_effects=tuple(sorted(effects.model_dump(exclude_none=True).items())),
        camera_sensor=cam.sensor.model(),
    )
