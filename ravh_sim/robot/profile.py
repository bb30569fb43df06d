"""Robot profiles (``config/robots/*.yaml``): body, motion limits and sensor mounting in one place.

Loaded into frozen dataclasses so every consumer (physics, sensors, navigation, nodes) reads the same
validated numbers; a bad value names the file and the field.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from ravh_sim.errors import FileFieldError, UnknownNameError
from ravh_sim.paths import ROBOTS_DIR
from ravh_sim.render.backend import QUALITIES


@dataclass(frozen=True)
class LaserSpec:
    height: float            # m above the floor
    fov_deg: float
    resolution_deg: float
    range_min: float
    range_max: float
    rate: float              # Hz
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
    rate: float              # Hz
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
    laser: LaserSpec
    camera: CameraSpec
    camera_effects: tuple[tuple[str, Any], ...] = ()   # CameraOptions fields set by the profile


def available_profiles() -> list[str]:
    return sorted(p.stem for p in ROBOTS_DIR.glob("*.yaml"))


def load_profile(name_or_path: str | Path = "giraff") -> RobotProfile:
    path = Path(name_or_path)
    if path.suffix not in (".yaml", ".yml"):
        path = ROBOTS_DIR / f"{name_or_path}.yaml"
        if not path.exists():
            raise UnknownNameError("robot profile", str(name_or_path), available_profiles())
    try:
        data = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as e:
        raise FileFieldError(path, "-", f"cannot read robot profile: {e}") from None
    f = _Reader(data, str(path))
    lz, cam = f.sub("laser"), f.sub("camera")
    noise = f.sub("odometry_noise")
    return RobotProfile(
        name=str(data.get("name", path.stem)), radius=f.pos("footprint_radius"), height=f.pos("height"),
        mass=f.pos("mass"), max_linear_speed=f.pos("max_linear_speed"),
        max_angular_speed=math.radians(f.pos("max_angular_speed")),
        max_linear_acceleration=f.pos("max_linear_acceleration"),
        max_angular_acceleration=math.radians(f.pos("max_angular_acceleration")),
        odom_linear_sigma=noise.nonneg("linear_sigma"),
        odom_angular_sigma=math.radians(noise.nonneg("angular_sigma")),
        laser=LaserSpec(lz.pos("height"), lz.pos("fov"), lz.pos("resolution"), lz.pos("range_min"),
                        lz.pos("range_max"), lz.pos("rate"), lz.nonneg("noise_sigma")),
        camera=CameraSpec(cam.pos("height"), cam.num("pitch"), cam.num("forward"), int(cam.pos("width")),
                          int(cam.pos("height_px")), cam.pos("sensor_width"), cam.pos("sensor_height"),
                          cam.pos("focal_length"), cam.pos("near"), cam.pos("far"), cam.pos("rate"),
                          cam.choice("quality", QUALITIES, "realistic")),
        camera_effects=_effects(data.get("camera", {}).get("effects") or {}, str(path)),
    )


def _effects(effects: Any, source: str) -> tuple[tuple[str, Any], ...]:
    """The camera's realism effects, checked against CameraOptions so a typo names file and key."""
    from ravh_sim.sensors.camera import CameraOptions
    if not isinstance(effects, dict):
        raise FileFieldError(source, "camera.effects", "expected a mapping of effect: value")
    valid = set(CameraOptions.__dataclass_fields__)
    for key in effects:
        if key not in valid:
            raise FileFieldError(source, f"camera.effects.{key}", f"unknown effect; valid: {', '.join(sorted(valid))}")
    try:
        CameraOptions(**effects)
    except (TypeError, ValueError) as e:
        raise FileFieldError(source, "camera.effects", str(e)) from None
    return tuple(sorted((k, tuple(v) if isinstance(v, list) else v) for k, v in effects.items()))


class _Reader:
    def __init__(self, data: Any, source: str, prefix: str = "") -> None:
        if not isinstance(data, dict):
            raise FileFieldError(source, prefix or "(top level)", "expected a mapping")
        self.data, self.source, self.prefix = data, source, prefix

    def sub(self, key: str) -> _Reader:
        return _Reader(self.data.get(key), self.source, f"{self.prefix}{key}")

    def num(self, key: str) -> float:
        value = self.data.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise FileFieldError(self.source, f"{self.prefix and self.prefix + '.'}{key}",
                                 f"expected a finite number, got {value!r}")
        return float(value)

    def pos(self, key: str) -> float:
        value = self.num(key)
        if value <= 0:
            raise FileFieldError(self.source, f"{self.prefix and self.prefix + '.'}{key}",
                                 f"must be > 0, got {value}")
        return value

    def choice(self, key: str, options: tuple[str, ...], default: str) -> str:
        value = self.data.get(key, default)
        if value not in options:
            raise FileFieldError(self.source, f"{self.prefix and self.prefix + '.'}{key}",
                                 f"expected one of {', '.join(options)}, got {value!r}")
        return str(value)

    def nonneg(self, key: str) -> float:
        value = self.num(key)
        if value < 0:
            raise FileFieldError(self.source, f"{self.prefix and self.prefix + '.'}{key}",
                                 f"must be >= 0, got {value}")
        return value
