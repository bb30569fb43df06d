"""The sim node's parameters: their defaults, their checks, and the command-line flags that set them.

Every flag is also a ROS parameter (``--ros-args -p house:=15`` works too), and all are read-only: they
shape the world at start-up. They are checked in one place, without ROS, so a bad value is one clear
:class:`UserError` however it was given. Each sensor publishes at its robot profile's rate;
``camera_rate``, ``scan_rate`` and ``odom_rate`` override it for every agent when >= 0.
"""
from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from typing import Any

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node

from ravh_sim.errors import UserError
from ravh_sim.render.backend import BACKENDS
from ravh_sim.runtime import ODOM
from ravh_sim.sensors.suite import SENSORS

MAP_TF_MODES = ("auto", "on", "off")
FRAME_POLICIES = ("drop", "wait")       # a frame due while the last renders: skip it | hold sim time
FROM_PROFILE = -1.0                     # a rate parameter's default: each agent's robot profile says
# parameter -> rate key: camera_rate, scan_rate (one per sensor port) and odom_rate
RATE_PARAMETERS = {f"{key}_rate": key for key in (*(port.name for port in SENSORS), ODOM)}
PARAMETERS: dict[str, Any] = {
    "house": 15, "seed": -1, "config": "", "footprint": "", "renderer": "auto", "real_time_factor": 1.0,
    **dict.fromkeys(RATE_PARAMETERS, FROM_PROFILE), "clock_rate": 100.0,
    "cmd_vel_stamped": False, "map_tf": "auto", "lockstep": False, "frame_policy": "drop",
}


@dataclass(frozen=True)
class SimParams:
    """The parameters as the node uses them, checked."""

    house: int | str                    # a number, an imported home's name or a house file's path
    seed: int | None                    # None: a random one
    config: str | None
    footprint: str | None               # rebuild the world of this footprint file
    renderer: str
    rtf: float                          # real-time factor; 0 = as fast as possible
    rates: dict[str, float]             # rate key -> Hz, only those that override the robot profiles
    clock_rate: float                   # Hz of /clock, at least 1e-3
    cmd_vel_stamped: bool
    map_tf: str                         # one of MAP_TF_MODES
    lockstep: bool
    frame_policy: str                   # one of FRAME_POLICIES

    @classmethod
    def check(cls, p: dict[str, Any]) -> SimParams:
        """``p`` (every parameter by name) checked; a bad value raises :class:`UserError`."""
        rtf = float(p["real_time_factor"])
        if not math.isfinite(rtf) or rtf < 0:
            raise UserError(f"real_time_factor must be >= 0 (0 = as fast as possible), got {rtf}")
        map_tf = str(p["map_tf"])
        if map_tf not in MAP_TF_MODES:
            raise UserError(f"map_tf must be one of {', '.join(MAP_TF_MODES)}, got {map_tf!r}")
        rates = {key: float(p[param]) for param, key in RATE_PARAMETERS.items() if p[param] != FROM_PROFILE}
        for param, key in RATE_PARAMETERS.items():
            if key in rates and not (math.isfinite(rates[key]) and rates[key] >= 0):
                raise UserError(f"{param} must be >= 0 Hz (0 = never), got {rates[key]}")
        frame_policy = str(p["frame_policy"])
        if frame_policy not in FRAME_POLICIES:
            raise UserError(f"frame_policy must be one of {', '.join(FRAME_POLICIES)}, got {frame_policy!r}")
        house = int(p["house"]) if str(p["house"]).isdigit() else str(p["house"])
        return cls(house=house, seed=None if p["seed"] == -1 else p["seed"], config=p["config"] or None,
                   footprint=p["footprint"] or None, renderer=p["renderer"], rtf=rtf, rates=rates,
                   clock_rate=max(float(p["clock_rate"]), 1e-3), cmd_vel_stamped=bool(p["cmd_vel_stamped"]),
                   map_tf=map_tf, lockstep=bool(p["lockstep"]), frame_policy=frame_policy)

    @classmethod
    def declare(cls, node: Node) -> SimParams:
        """Declare every parameter on ``node`` (read-only) and check the values it was given."""
        read_only = ParameterDescriptor(read_only=True)
        named = ParameterDescriptor(read_only=True, dynamic_typing=True)      # house: a number or a name
        return cls.check({k: node.declare_parameter(k, v, named if k == "house" else read_only).value
                          for k, v in PARAMETERS.items()})


def parse_args(argv: list[str]) -> dict[str, Any]:
    """Command-line flags (each also a ROS parameter: ``--ros-args -p house:=15`` works too)."""
    p = argparse.ArgumentParser(prog="sim", description="ravh_sim: a Robot@VirtualHome house on ROS 2")
    p.add_argument("--house", help="house number, imported home's name or house file path")
    p.add_argument("--seed", type=int)
    p.add_argument("--config")
    p.add_argument("--footprint", help="rebuild the world of this footprint file (house and settings)")
    p.add_argument("--renderer", choices=BACKENDS)
    p.add_argument("--rtf", "--real-time-factor", dest="real_time_factor", type=float,
                   help="sim seconds per wall second; 0 = as fast as possible (default 1)")
    for param in RATE_PARAMETERS:
        p.add_argument("--" + param.replace("_", "-"), dest=param, type=float,
                       help="Hz of sim time for every agent (default: its robot profile's; 0 = never)")
    p.add_argument("--cmd-vel-stamped", dest="cmd_vel_stamped", action="store_true", default=None)
    p.add_argument("--map-tf", dest="map_tf", choices=MAP_TF_MODES,
                   help="who publishes map -> odom on /tf: auto (default: the sim unless another node "
                        "does), on (always the sim), off (never the sim)")
    p.add_argument("--lockstep", action="store_true", default=None,
                   help="advance sim time only as far as a behaviour grants on ravh/step (reproducible runs)")
    p.add_argument("--frame-policy", dest="frame_policy", choices=FRAME_POLICIES,
                   help="a camera frame due while the last one renders: drop (default: keep the real-time "
                        "factor, publish fewer frames) or wait (keep the camera rate, slow the sim)")
    args = p.parse_args(argv)
    return {k: v for k, v in vars(args).items() if v is not None}
