"""The Navigation Manager: the maps of a house as it is now, and paths over it.

Two maps: :meth:`Navigation.map` is the robot's inflated free space (where its centre may go: what
the planner and behaviours use), :meth:`Navigation.obstacle_map` the uninflated obstacle map at laser
height (what a ROS map_server would load: the sim's /map).

It reads a :class:`~ravh_sim.world.state.WorldState` rather than the World itself, so the same object
serves the simulator (pass ``world.house, world.state``: the live state) and tools that never start
pybullet (``ravh map``: ``WorldState(resolved)``). The maps are rebuilt only when the state's
``layout_revision`` moved (a door or an object model changed), never by comparing doors and models.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from pathlib import Path as FilePath
from typing import Protocol

import numpy as np

from ravh_sim.nav.freespace import free_space
from ravh_sim.nav.grid import FREE, Grid, distance_to_obstacle, reachable
from ravh_sim.nav.mapio import write_map
from ravh_sim.nav.obstaclemap import obstacle_map
from ravh_sim.nav.planner import Path, Point, Unreachable, densify, plan_path
from ravh_sim.sensors.laser import LaserSpec
from ravh_sim.world.dressing import Dressed, dressing
from ravh_sim.world.house import House
from ravh_sim.world.state import WorldState

DEFAULT_RESOLUTION = 0.05        # m per cell, as the ROS map_server maps the project writes
START_SNAP = 0.3                 # m, as the planner: a start on the inflation uses the free cell nearby


class Body(Protocol):
    """What the maps need of a robot profile (a :class:`~ravh_sim.robot.profile.RobotProfile`): its
    size and its laser's height. Navigation sits below ravh_sim.robot, which starts agents on its free
    space, so it names what it reads instead of importing the profile."""

    @property
    def radius(self) -> float: ...

    @property
    def height(self) -> float: ...

    @property
    def laser(self) -> LaserSpec: ...


class Navigation:
    """Maps and planner for one robot profile (its radius, height and laser height shape the maps)."""

    def __init__(self, house: House, state: WorldState, profile: Body,
                 resolution: float = DEFAULT_RESOLUTION) -> None:
        self.house, self.state, self.profile, self.resolution = house, state, profile, resolution
        self._built_at = state.layout_revision
        self._grids: dict[str, Grid] = {}

    def map(self) -> Grid:
        """The inflated free-space grid for the current doors and models (the same object until they
        change): FREE where the robot's centre may go."""
        return self._current("free_space", lambda doors, models, dressed: free_space(
            self.house, doors, models, radius=self.profile.radius, height=self.profile.height,
            resolution=self.resolution, dressed=dressed))

    def walkable(self, radius: float) -> Grid:
        """Free space for a disc of ``radius`` at the robot's height (the paper's grid rule bakes its
        walkable area for a 0.1 m agent, narrower than our robot)."""
        return self._current(f"walkable {radius}", lambda doors, models, dressed: free_space(
            self.house, doors, models, radius=radius, height=self.profile.height, resolution=self.resolution,
            dressed=dressed))

    def obstacle_map(self) -> Grid:
        """The uninflated obstacle map at laser height for the current doors and models."""
        return self._current("obstacles", lambda doors, models, dressed: obstacle_map(
            self.house, doors, models, self.profile.laser.height, self.resolution, dressed=dressed))

    def dressed(self) -> tuple[Dressed, ...]:
        """The dressing the world shows now (its level, models and seed)."""
        return dressing(self.house, self.state.models, self.state.dressing, self.state.seed)

    def _current(self, kind: str, build: Callable[[Mapping[str, bool], Mapping[str, int], tuple[Dressed, ...]],
                                                  Grid]) -> Grid:
        """The cached grid of ``kind``, rebuilt when the layout revision moved since it was built."""
        if self.state.layout_revision != self._built_at:
            self._grids, self._built_at = {}, self.state.layout_revision
        if kind not in self._grids:
            self._grids[kind] = build(self.state.doors, self.state.models, self.dressed())
        return self._grids[kind]

    def closed_doors(self) -> list[str]:
        return [door for door, is_open in self.state.doors.items() if not is_open]

    def plan(self, start: Point, goal: Point) -> Path:
        """A path on the current map; raises :class:`~ravh_sim.nav.planner.Unreachable` naming the
        rooms and the closed doors when there is none."""
        closed = self.closed_doors()
        try:
            return plan_path(self.map(), start, goal, house=self.house, blocked_by=closed)
        except Unreachable as e:
            if e.end != "goal" or not closed:
                raise
            raise self._why_unreachable(start, goal, closed) from None

    def _why_unreachable(self, start: Point, goal: Point, closed: list[str]) -> Unreachable:
        """Name the closed doors that really cut the way: those on the path that would exist with every
        door open; if none would exist, walls or furniture are to blame, not the doors."""
        open_all = free_space(self.house, dict.fromkeys(self.state.doors, True), self.state.models,
                              radius=self.profile.radius, height=self.profile.height, resolution=self.resolution,
                              dressed=self.dressed())
        try:
            path = plan_path(open_all, start, goal)
        except Unreachable:
            blocking: list[str] = []
        else:
            points = densify(path.points, self.resolution)
            blocking = [d for d in closed if any(
                math.dist(p, self.house.door_by_id[d].position[:2]) < self.house.door_by_id[d].width / 2
                for p in points)]
        try:
            plan_path(self.map(), start, goal, house=self.house, blocked_by=blocking)
        except Unreachable as e:
            return e
        raise AssertionError("unreachable goal became reachable")

    def room_goal(self, room_id: str, start: Point | None = None) -> Point:
        """The free point of a room farthest from obstacles (where to send a robot told "go to the
        kitchen"), among the points reachable from ``start`` if given. Raises
        :class:`~ravh_sim.nav.planner.Unreachable` when the room has no such point."""
        room = self.house.room(room_id)
        grid = self.map()
        usable = grid.polygons_mask((room.floor, *room.extra_floors)) & (grid.data == FREE)
        if start is not None:
            usable &= reachable(grid, start, START_SNAP)
        score = np.where(usable, distance_to_obstacle(grid), -1.0)
        r, c = np.unravel_index(int(np.argmax(score)), score.shape)
        if score[r, c] <= 0:
            where = "" if start is None else f" reachable from ({start[0]:.2f}, {start[1]:.2f})"
            raise Unreachable("goal", f"room {room_id} has no free point{where}")
        return grid.center_of(int(r), int(c))

    def write_map(self, directory: str | FilePath, inflated: bool = False) -> tuple[FilePath, FilePath]:
        """``map.pgm`` and ``map.yaml`` (ROS map_server format) of the current obstacle map, or of the
        robot's inflated free space with ``inflated``."""
        return write_map(self.map() if inflated else self.obstacle_map(), directory)
