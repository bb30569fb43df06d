"""Sensor ports: each kind of sensor an agent carries, described once (after habitat-lab's Sensor).

A :class:`SensorPort` says what a sensor is called, its section of a robot profile (the schema that
validates it and the spec the sensor is built with), how often it runs (its rate), where it sits (its
mounts, for /tf_static), which topics it publishes and of what message kind, how to build and read it
on an agent (ROS-free: the read returns the sensor's own data object), what each topic carries, and
how one sample of it is stored in a dataset and read back. The robot profile, the runtime (which
sensors are due), the sim node (publishers and publishing), the recorder (which parts make a capture),
the dataset writer and the dataset reader all iterate over the suite
(:data:`ravh_sim.sensors.suite.SENSORS`); the ROS side of each message kind lives in
``ravh_sim.nodes.convert.KINDS``. Adding a sensor: one module with the sensor, its profile section
and its port class; one line in the suite; its spec's field in ``RobotProfile`` and its section in the
profiles (config/robots/).
"""
from __future__ import annotations

import zlib
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Generic, Protocol, TypeVar

import numpy as np

from ravh_sim.poses import Pose2D
from ravh_sim.schema import Strict

if TYPE_CHECKING:
    from ravh_sim.world.scene import World

# (parent frame, child frame, xyz, quaternion xyzw) of a sensor mount, as on /tf_static
Mount = tuple[str, str, tuple[float, ...], tuple[float, ...]]

SpecT = TypeVar("SpecT")          # what the sensor is built with, from its profile section (LaserSpec)
SensorT = TypeVar("SensorT")      # the sensor object an agent carries (Laser, SmartCamera)
DataT = TypeVar("DataT")          # what one read of it returns (Scan, Capture)


@dataclass(frozen=True)
class Topic:
    """One topic a sensor publishes; ``key`` names it in the sim node, the recorder and the dataset values."""
    key: str                 # "rgb", "scan", ...: unique over the suite
    base: str                # its name in ravh_msgs_py.names (prefixed for agents after the first)
    kind: str                # message kind: a key of ravh_sim.nodes.convert.KINDS (type and conversions)
    dataset: bool            # part of a dataset sample (the recorder waits for it)
    bag: bool                # recorded in the bag


@dataclass(frozen=True)
class Stored:
    """What one sensor adds to a dataset sample (see ravh_sim/dataset/README.md)."""
    files: dict[str, bytes]                                   # file kind (SensorPort.files) -> bytes
    row: dict[str, Any] = field(default_factory=dict)         # fields of the sample's captures.jsonl line
    agent_facts: dict[str, Any] = field(default_factory=dict)  # side file (camera.json) -> this agent's entry


class Carrier(Protocol):
    """What a sensor reads of the robot carrying it (a ravh_sim.robot.robot.Robot)."""
    body: int                            # its pybullet body (the laser does not see it)

    @property
    def pose(self) -> Pose2D: ...

    @property
    def velocity(self) -> tuple[float, float]: ...


class SensorPort(ABC, Generic[SpecT, SensorT, DataT]):
    """A kind of sensor, as the robot profile, the runtime, the nodes and the dataset see it."""
    name: ClassVar[str]                  # rate key (sim node overrides) and sensor key
    section: ClassVar[str]               # its section in a robot profile (config/robots/*.yaml)
    schema: ClassVar[type[Strict]]       # that section's model, validated with the profile
    frame: ClassVar[str]                 # the frame its data is stamped in (ravh_msgs_py.names)
    captured: ClassVar[bool]             # recorded only for requested captures (else streamed)
    topics: ClassVar[tuple[Topic, ...]]
    files: ClassVar[dict[str, str]]      # its files in a dataset sample: kind (folder) -> extension

    @abstractmethod
    def spec(self, section: Any) -> SpecT:
        """What the sensor is built with, from its validated profile section (a ``schema``)."""

    @abstractmethod
    def rate(self, spec: SpecT) -> float:
        """Hz of sim time."""

    @abstractmethod
    def mounts(self, spec: SpecT) -> list[Mount]:
        """Its frames on base_link (floor level)."""

    @abstractmethod
    def build(self, world: World, spec: SpecT, agent: str, backend: str = "auto") -> SensorT:
        """The sensor of agent ``agent``; ``backend``: the renderer backend a sensor that draws uses
        (auto | gl | tiny, :mod:`ravh_sim.render.backend`)."""

    @abstractmethod
    def read(self, sensor: SensorT, carrier: Carrier) -> DataT:
        """Its data now."""

    @abstractmethod
    def value(self, key: str, data: DataT, sensor: SensorT, frame: str) -> Any:
        """What topic ``key`` publishes of ``data`` (stamped in ``frame``)."""

    @abstractmethod
    def encode(self, values: Mapping[str, Any]) -> Stored:
        """Its files and fields of one dataset sample, from the dataset values by topic key."""

    @abstractmethod
    def decode(self, kind: str, path: Path, row: Mapping[str, Any]) -> Any:
        """The data of its stored file of ``kind`` at ``path`` (``row``: the sample's captures.jsonl line)."""


def noise_rng(seed: int, stream: int, agent: str, count: int) -> np.random.Generator:
    """The noise generator of one reading: the world seed, the sensor kind's stream, the agent (a
    stable hash of its name, so two agents' sensors differ) and the sensor's reading counter."""
    return np.random.default_rng([seed, stream, zlib.crc32(agent.encode()), count])
