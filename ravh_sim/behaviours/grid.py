"""The Grid behaviour: lattice nodes every 0.5 m, no captures while travelling, a 360 degree turn
with N captures (one every 360/N degrees) at each node.

The turn is done in N stops: rotate to the next heading, stand still for ``settle`` seconds, ask for a
capture, so every image is taken at rest at a known heading.
"""
from __future__ import annotations

import math

from ravh_sim.behaviours.waypoints import Point
from ravh_sim.nav.follower import PathFollower, Status
from ravh_sim.nav.planner import Unreachable
from ravh_sim.poses import wrap_angle

TURN_GAIN = 2.0                 # rad/s per rad of heading error
HEADING_TOLERANCE = math.radians(2.0)


class GridSweep:
    def __init__(self, follower: PathFollower, nodes: list[Point], captures_per_node: int = 10,
                 settle: float = 0.2) -> None:
        if captures_per_node < 1:
            raise ValueError("captures_per_node must be >= 1")
        self.follower = follower
        self.nodes = list(nodes)
        self.n = captures_per_node
        self.settle = settle
        self.index = -1
        self.done = False
        self.visited_nodes: list[Point] = []
        self.skipped: list[tuple[Point, str]] = []
        self._turning = False
        self._shot = 0
        self._heading0 = 0.0
        self._still = 0.0

    @property
    def robot(self):
        return self.follower.robot

    def update(self, dt: float) -> list[str]:
        if self.done:
            return []
        if self._turning:
            return self._turn(dt)
        status = self.follower.update(dt)
        if status is Status.ARRIVED:
            self.visited_nodes.append(self.nodes[self.index])
            self._turning, self._shot, self._still = True, 0, 0.0
            self._heading0 = self.robot.pose[2]
            return []
        if status in (Status.IDLE, Status.FAILED):
            if status is Status.FAILED:
                self.skipped.append((self.nodes[self.index], self.follower.reason))
            self._next_node()
        return []

    def _turn(self, dt: float) -> list[str]:
        target = self._heading0 + 2 * math.pi * self._shot / self.n
        error = wrap_angle(target - self.robot.pose[2])
        if abs(error) > HEADING_TOLERANCE:
            w_max = self.follower.profile.max_angular_speed
            self.robot.set_command(0.0, max(-w_max, min(w_max, TURN_GAIN * error)))
            self._still = 0.0
            return []
        self.robot.set_command(0.0, 0.0)
        self._still += dt
        if self._still < self.settle:
            return []
        self._shot += 1
        self._still = 0.0
        if self._shot >= self.n:
            self._turning = False
            self._next_node()
        return [f"node {self.index} shot {self._shot}/{self.n}"]

    def _next_node(self) -> None:
        while True:
            self.index += 1
            if self.index >= len(self.nodes):
                self.done = True
                self.robot.set_command(0.0, 0.0)
                return
            try:
                self.follower.navigate_to(self.nodes[self.index])
                return
            except Unreachable as e:
                self.skipped.append((self.nodes[self.index], str(e)))
