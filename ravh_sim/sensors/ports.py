"""Sensor ports: each kind of sensor an agent carries, described once (after habitat-lab's Sensor).

A :class:`SensorPort` says what a sensor is called, how often it runs (its rate, from the robot
profile), where it sits (its mounts, for /tf_static), which topics it publishes and of what message
kind, how to build and read it on an agent (ROS-free: the read returns the sensor's own data object)
and how one sample of it is stored in a dataset. The runtime (which sensors are due), the sim node
(publishers and publishing), the recorder (which parts make a capture) and the dataset writer all
iterate over the suite (:data:`ravh_sim.sensors.suite.SENSORS`); the ROS side of each message kind
lives in ``ravh_sim.nodes.convert.KINDS``. Adding a sensor: one module with the sensor and its port,
one line in the suite.
"""
from __future__ import annotations

import zlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ravh_sim.robot.profile import RobotProfile
    from ravh_sim.robot.robot import Robot
    from ravh_sim.world.scene import World

# (parent frame, child frame, xyz, quaternion xyzw) of a sensor mount, as on /tf_static
Mount = tuple[str, str, tuple[float, ...], tuple[float, ...]]


@dataclass(frozen=True)
class Topic:
    """One topic a sensor publishes; ``key`` names it in the sim node, the recorder and the dataset values."""
    key: str                 # "rgb", "scan", ...: unique over the suite
    base: str                # its name in ravh_msgs_py.names (prefixed for agents after the first)
    kind: str                # message kind: a key of ravh_sim.nodes.convert.KINDS (type and conversions)
    dataset: bool            # part of a dataset sample (the recorder waits for it)
    bag: bool                # recorded in the bag
    value: Callable[[Any, Any, str], Any]   # (data read, the sensor, frame id) -> the value published


@dataclass(frozen=True)
class Stored:
    """What one sensor adds to a dataset sample (see ravh_sim/dataset/README.md)."""
    files: dict[str, bytes]                                   # file kind (SensorPort.files) -> bytes
    row: dict[str, Any] = field(default_factory=dict)         # fields of the sample's captures.jsonl line
    agent_facts: dict[str, Any] = field(default_factory=dict)  # side file (camera.json) -> this agent's entry


@dataclass(frozen=True)
class SensorPort:
    """A kind of sensor, as the runtime, the nodes and the dataset see it."""
    name: str                                        # rate key (profile, sim node overrides) and sensor key
    frame: str                                       # the frame its data is stamped in (ravh_msgs_py.names)
    captured: bool                                   # recorded only for requested captures (else streamed)
    topics: tuple[Topic, ...]
    files: dict[str, str]                            # its files in a dataset sample: kind (folder) -> extension
    rate: Callable[[RobotProfile], float]            # Hz of sim time
    mounts: Callable[[RobotProfile], list[Mount]]    # its frames on base_link (floor level)
    build: Callable[[World, RobotProfile, str], Any]  # (world, profile, agent name) -> the sensor
    read: Callable[[Any, Robot], Any]                # (sensor, robot) -> its data now
    store: Callable[[Mapping[str, Any]], Stored]     # dataset values by topic key -> files and fields


def noise_rng(seed: int, stream: int, agent: str, count: int) -> np.random.Generator:
    """The noise generator of one reading: the world seed, the sensor kind's stream, the agent (a
    stable hash of its name, so two agents' sensors differ) and the sensor's reading counter."""
    return np.random.default_rng([seed, stream, zlib.crc32(agent.encode()), count])
