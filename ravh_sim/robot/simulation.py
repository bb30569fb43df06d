"""The Simulation: one World's physics clock and the robots that live in it.

One object steps pybullet and every robot in the right order (commands in, physics, state out), so
several agents share one clock and one set of contacts: they collide with each other as with the
house. The ROS node owns one and calls :meth:`Simulation.step` from its timer.

A start pose that overlaps something a little (a station close to a wall) is moved just clear of it
(see ``Robot._place``); the world's state then records where the robot really starts, so the
footprint never claims a pose the robot is not at, and a world rebuilt from that footprint starts the
robot exactly there. A start that cannot be freed that way (inside a sofa, wedged between a shower
and a basin) is refused with a UserError that names the nearest free pose on the free-space map.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import pybullet as pb

from ravh_sim.errors import UnknownNameError, UserError
from ravh_sim.nav.freespace import free_space
from ravh_sim.nav.grid import FREE
from ravh_sim.robot.profile import RobotProfile, load_profile
from ravh_sim.robot.robot import Robot
from ravh_sim.world.dressing import dressing
from ravh_sim.world.scene import World
from ravh_sim.world.settings import AgentSpec

START_MOVED = 1e-4       # m: a start moved further than this is recorded where the robot is


class Simulation:
    """Robots for ``agents`` (default: the world's resolved agents) and the physics clock."""

    def __init__(self, world: World, agents: Sequence[AgentSpec] | None = None) -> None:
        self.world = world
        self.dt = 1.0 / world.physics_hz
        self.steps = 0
        self.robots: dict[str, Robot] = {}
        specs = world.state.agents if agents is None else agents
        for spec in specs:
            if spec.name in self.robots:
                raise ValueError(f"duplicate agent name {spec.name!r}")
            profile = load_profile(spec.profile)
            self.robots[spec.name] = robot = Robot(world, profile, spec.name, spec.pose)
            if not robot.is_clear():
                raise UserError(f"agent {spec.name!r}: start pose {list(spec.pose)} is inside an obstacle; "
                                f"nearest free pose: {_nearest_free_pose(world, profile, spec.pose)}")
        if agents is None:
            world.state.write(agents=[self._started(spec) for spec in specs])

    def _started(self, spec: AgentSpec) -> AgentSpec:
        """``spec`` with the pose its robot really starts at, if placing moved it."""
        x, y, _ = self.robots[spec.name].pose
        if math.dist((x, y), spec.pose[:2]) <= START_MOVED:
            return spec
        return replace(spec, pose=(round(x, 4), round(y, 4), spec.pose[2]))

    @property
    def time(self) -> float:
        """Simulated seconds since the start."""
        return self.steps * self.dt

    def robot(self, name: str) -> Robot:
        try:
            return self.robots[name]
        except KeyError:
            raise UnknownNameError("agent", name, list(self.robots)) from None

    def step(self, n: int = 1) -> None:
        """Advance ``n`` physics steps of ``dt`` seconds."""
        robots = list(self.robots.values())
        for _ in range(n):
            for robot in robots:
                robot.step()
            pb.stepSimulation(physicsClientId=self.world.client)
            for robot in robots:
                robot.sync()
        self.steps += n


def _nearest_free_pose(world: World, profile: RobotProfile, pose: tuple[float, float, float]) -> list[float]:
    """[x, y, yaw]: the free-space map's free cell nearest ``pose`` (yaw kept), where the robot fits."""
    state = world.state
    grid = free_space(world.house, state.doors, state.models, profile.radius, profile.height,
                      dressed=dressing(world.house, state.models, state.dressing, state.seed))
    xs, ys = grid.cell_centres()
    d2 = np.where(grid.data == FREE, (xs - pose[0]) ** 2 + (ys - pose[1]) ** 2, np.inf)
    row, col = np.unravel_index(int(np.argmin(d2)), d2.shape)
    return [round(float(xs[row, col]), 3), round(float(ys[row, col]), 3), pose[2]]
