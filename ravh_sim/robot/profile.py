"""Robot profiles (``config/robots/*.yaml``): body, motion limits and sensor mounting in one place.

Validated by a pydantic schema (every field typed and bounded) and loaded into frozen dataclasses, so
every consumer (physics, sensors, navigation, nodes) reads the same checked numbers; a bad value names
the file and the field. Each sensor declares its own section (its port's ``schema``, named by
``section``) and what it is built with (``spec``): the schema of a profile is the body's fields plus
every sensor's section, and a new sensor adds only its spec's field to :class:`RobotProfile`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

from pydantic import Field, create_model

from ravh_msgs_py.names import DEFAULT_PROFILE
from ravh_sim.errors import UnknownNameError
from ravh_sim.paths import ROBOTS_DIR
from ravh_sim.schema import FINITE, Length, Rate, Sigma, Strict, load_yaml, read_text, validate
from ravh_sim.sensors.camera import CameraSpec
from ravh_sim.sensors.laser import LaserSpec
from ravh_sim.sensors.ports import SensorPort, SpecT
from ravh_sim.sensors.suite import SENSORS


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
    # every sensor's spec, by its port's section (ravh_sim.sensors.suite.SENSORS)
    laser: LaserSpec
    camera: CameraSpec

    def spec(self, port: SensorPort[SpecT, Any, Any]) -> SpecT:
        """The spec of ``port``'s sensor."""
        spec: SpecT = getattr(self, port.section)
        return spec


def available_profiles() -> list[str]:
    return sorted(p.stem for p in ROBOTS_DIR.glob("*.yaml"))


class _Odometry(Strict):
    rate: Rate
    linear_sigma: Sigma
    angular_sigma: Sigma


class _Body(Strict):
    """The fields of config/robots/*.yaml besides the sensors' sections."""
    name: Annotated[str, Field(min_length=1, max_length=64)]
    footprint_radius: Length
    height: Length
    mass: Annotated[float, Field(gt=0.0, le=10_000.0), FINITE]
    max_linear_speed: Annotated[float, Field(gt=0.0, le=10.0), FINITE]             # m/s
    max_angular_speed: Annotated[float, Field(gt=0.0, le=1000.0), FINITE]          # deg/s
    max_linear_acceleration: Annotated[float, Field(gt=0.0, le=100.0), FINITE]     # m/s^2
    max_angular_acceleration: Annotated[float, Field(gt=0.0, le=10_000.0), FINITE] # deg/s^2
    odometry: _Odometry


# The schema of config/robots/*.yaml: the body and every sensor's section.
ProfileFile = create_model("ProfileFile", __base__=_Body,
                           **{port.section: (port.schema, ...) for port in SENSORS})   # type: ignore[call-overload]


def load_profile(name_or_path: str | Path = DEFAULT_PROFILE) -> RobotProfile:
    path = Path(name_or_path)
    if path.suffix not in (".yaml", ".yml"):
        path = ROBOTS_DIR / f"{name_or_path}.yaml"
        if not path.exists():
            raise UnknownNameError("robot profile", str(name_or_path), available_profiles())
    data = load_yaml(read_text(path, "robot profile"), path)
    f = validate(ProfileFile, data, path)
    specs: dict[str, Any] = {port.section: port.spec(getattr(f, port.section)) for port in SENSORS}
    return RobotProfile(
        name=f.name, radius=f.footprint_radius, height=f.height, mass=f.mass,
        max_linear_speed=f.max_linear_speed, max_angular_speed=math.radians(f.max_angular_speed),
        max_linear_acceleration=f.max_linear_acceleration,
        max_angular_acceleration=math.radians(f.max_angular_acceleration),
        odom_linear_sigma=f.odometry.linear_sigma,
        odom_angular_sigma=math.radians(f.odometry.angular_sigma), odom_rate=f.odometry.rate, **specs)
