"""The Simulation: one World's physics clock and the robots that live in it.

One object steps pybullet and every robot in the right order (commands in, physics, state out), so
several agents share one clock and one set of contacts: they collide with each other as with the
house. The ROS node owns one and calls :meth:`Simulation.step` from its timer.
"""
from __future__ import annotations

from collections.abc import Sequence

import pybullet as pb

from ravh_sim.errors import UnknownNameError
from ravh_sim.robot.profile import load_profile
from ravh_sim.robot.robot import Robot
from ravh_sim.world.scene import World
from ravh_sim.world.settings import AgentSpec


class Simulation:
    """Robots for ``agents`` (default: the world's resolved agents) and the physics clock."""

    def __init__(self, world: World, agents: Sequence[AgentSpec] | None = None) -> None:
        self.world = world
        self.dt = 1.0 / world.physics_hz
        self.steps = 0
        self.robots: dict[str, Robot] = {}
        for spec in world.settings.agents if agents is None else agents:
            if spec.name in self.robots:
                raise ValueError(f"duplicate agent name {spec.name!r}")
            self.robots[spec.name] = Robot(world, load_profile(spec.profile), spec.name, spec.pose)

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
