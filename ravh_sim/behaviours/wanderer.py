"""The Wanderer: room to room through the ceiling lights' floor projections, capturing while moving.

Rooms are visited in house order (``once``: one round; ``cyclic``: round after round) or in a fresh
random order each round (``random``). A waypoint the follower cannot reach (it reports FAILED after
its own recoveries) is skipped, so a blocked room never stalls the run.
"""
from __future__ import annotations

import random

from ravh_sim.behaviours.waypoints import Point, room_order
from ravh_sim.nav.follower import PathFollower, Status
from ravh_sim.nav.planner import Unreachable


class Wanderer:
    def __init__(self, follower: PathFollower, waypoints: dict[str, list[Point]], order: str = "cyclic",
                 capture_period: float = 0.5, seed: int = 0) -> None:
        self.follower = follower
        self.waypoints = waypoints
        self.order = order
        self.capture_period = capture_period
        self.rng = random.Random(f"{seed}/wanderer")
        self.queue: list[tuple[str, Point]] = []
        self.rounds = 0
        self.visited: set[str] = set()
        self.skipped: list[tuple[str, Point, str]] = []
        self.done = False
        self._room = ""
        self._since_capture = 0.0
        room_order(list(waypoints), order, self.rng)            # validates the order name

    def update(self, dt: float) -> list[str]:
        """One control tick; returns the captures to take now (each tagged with its reason)."""
        if self.done:
            return []
        status = self.follower.update(dt)
        if status in (Status.IDLE, Status.ARRIVED, Status.FAILED):
            if status is Status.ARRIVED:
                self.visited.add(self._room)
            elif status is Status.FAILED:
                self.skipped.append((self._room, self.follower.goal, self.follower.reason))
            self._next_goal()
            return []
        self._since_capture += dt
        if self._since_capture >= self.capture_period:
            self._since_capture = 0.0
            return ["moving"]
        return []

    def _next_goal(self) -> None:
        refills = 0
        while True:
            if not self.queue:
                if (self.order == "once" and self.rounds >= 1) or refills > 0:   # done, or nothing reachable
                    self._finish()
                    return
                refills += 1
                self.rounds += 1
                self.queue = [(room, p) for room in room_order(list(self.waypoints), self.order, self.rng)
                              for p in self.waypoints[room]]
            self._room, goal = self.queue.pop(0)
            try:
                self.follower.navigate_to(goal)
                return
            except Unreachable as e:
                self.skipped.append((self._room, goal, str(e)))

    def _finish(self) -> None:
        self.done = True
        self.follower.robot.set_command(0.0, 0.0)

