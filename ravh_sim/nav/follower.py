"""Following a planned path with a differential-drive robot, and recovering when blocked.

The controller is a pure function, :func:`steer` (pose and path in, (v, w) out): pure pursuit
towards a point ``lookahead`` metres further along the path, turning on the spot when that point
is far off the heading (a Giraff cannot turn tighter than v / w_max, and a path corner taken at
speed would clip the wall). :class:`PathFollower` wraps it with what needs memory: progress along
the path, arrival, the final heading, and blocked detection with recovery:

* the map changed under the path just ahead (a door closed): replan at once;
* commanded forward but not moving for ``stall_time`` (bumped into something the map does not
  have, such as another robot): back off, then replan from where the robot is;
* no progress along the path for ``progress_timeout``: replan.

Replanning uses the navigation's current map, which it rebuilds itself when doors changed. After
``max_recoveries`` recoveries, or when no path is left, the follower stops with FAILED and a reason.
"""
from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Protocol

from ravh_sim.nav.grid import Grid
from ravh_sim.nav.planner import Path, Point, Unreachable
from ravh_sim.poses import Pose2D, wrap_angle

CONTROL_PERIOD = 0.05            # s between follower updates in :func:`drive` (20 Hz, as nav2)


class Status(Enum):
    ACTIVE = "active"            # following (or turning to the final heading)
    ARRIVED = "arrived"
    BLOCKED = "blocked"          # recovering: backing off or replanning; ACTIVE again after
    FAILED = "failed"            # stopped; ``PathFollower.reason`` says why
    IDLE = "idle"                # no goal yet, or cancelled


@dataclass(frozen=True)
class FollowerConfig:
    lookahead: float = 0.3               # m along the path to the pursuit point
    goal_tolerance: float = 0.1          # m from the goal counts as arrived
    yaw_tolerance: float = math.radians(5.0)
    turn_in_place: float = math.radians(45.0)  # heading error beyond which v = 0
    heading_gain: float = 2.0            # rad/s per rad of heading error when turning on the spot
    slow_radius: float = 0.3             # m from the goal where the speed starts to drop
    min_speed: float = 0.05              # m/s, the least forward speed while following
    search_ahead: float = 1.0            # m of path searched for the robot's projection
    check_ahead: float = 1.0             # m of path checked against map changes
    stall_time: float = 2.0              # s commanded forward without moving -> blocked
    stall_ratio: float = 0.2             # moving slower than this share of the command is a stall
    progress_timeout: float = 20.0       # s without getting closer along the path -> blocked
    min_progress: float = 0.05           # m that counts as getting closer
    backoff_distance: float = 0.25       # m driven backwards after a stall
    backoff_speed: float = 0.1           # m/s
    max_recoveries: int = 3


@dataclass(frozen=True)
class Steering:
    v: float
    w: float
    along: float         # m along the path to the robot's projection
    remaining: float     # m of path left after the projection


class Track:
    """A polyline with arc lengths: projection of a point and the point at a given length."""

    def __init__(self, points: Sequence[Point]) -> None:
        if len(points) < 2:
            points = [points[0], points[0]]
        self.points = [(float(x), float(y)) for x, y in points]
        self.cumulative = [0.0]
        for a, b in zip(self.points, self.points[1:]):
            self.cumulative.append(self.cumulative[-1] + math.dist(a, b))

    @property
    def length(self) -> float:
        return self.cumulative[-1]

    def project(self, xy: Point, along: float, search: float) -> float:
        """Arc length of the point nearest ``xy`` on the stretch [along, along + search] of the path:
        the projection moves forward only, and never jumps to a later part of a path that comes
        back near itself."""
        lo, hi = along, min(along + search, self.length)
        best_d, best_s = math.inf, lo
        first = max(bisect.bisect_right(self.cumulative, lo) - 1, 0)
        for i in range(first, len(self.points) - 1):
            start, end = self.cumulative[i], self.cumulative[i + 1]
            if start > hi:
                break
            (ax, ay), (bx, by) = self.points[i], self.points[i + 1]
            seg = end - start
            if seg == 0.0:
                continue
            t = ((xy[0] - ax) * (bx - ax) + (xy[1] - ay) * (by - ay)) / (seg * seg)
            t = min(max(t, (lo - start) / seg, 0.0), (hi - start) / seg, 1.0)
            d = math.hypot(ax + t * (bx - ax) - xy[0], ay + t * (by - ay) - xy[1])
            if d < best_d:
                best_d, best_s = d, start + t * seg
        return best_s

    def point_at(self, s: float) -> Point:
        s = min(max(s, 0.0), self.length)
        i = min(max(bisect.bisect_right(self.cumulative, s) - 1, 0), len(self.points) - 2)
        seg = self.cumulative[i + 1] - self.cumulative[i]
        t = 0.0 if seg == 0.0 else (s - self.cumulative[i]) / seg
        (ax, ay), (bx, by) = self.points[i], self.points[i + 1]
        return ax + t * (bx - ax), ay + t * (by - ay)


def steer(pose: Pose2D, track: Track, along: float, max_v: float, max_w: float,
          config: FollowerConfig) -> Steering:
    """Pure pursuit with turning on the spot: the (v, w) that takes ``pose`` along ``track``,
    given how far along it the robot was (its projection only moves forward)."""
    x, y, yaw = pose
    along = track.project((x, y), along, config.search_ahead)
    carrot = track.point_at(along + config.lookahead)
    gx, gy = track.points[-1]
    to_goal = math.hypot(gx - x, gy - y)
    distance = math.hypot(carrot[0] - x, carrot[1] - y)
    if distance < 1e-6:
        return Steering(0.0, 0.0, along, track.length - along)
    alpha = wrap_angle(math.atan2(carrot[1] - y, carrot[0] - x) - yaw)
    if abs(alpha) > config.turn_in_place:
        w = min(max(config.heading_gain * alpha, -max_w), max_w)
        return Steering(0.0, w, along, track.length - along)
    v = max(min(max_v, max_v * to_goal / config.slow_radius), min(config.min_speed, max_v))
    curvature = 2.0 * math.sin(alpha) / distance
    w = v * curvature
    if abs(w) > max_w:                   # keep the curvature, slow down
        w = math.copysign(max_w, w)
        v = max_w / abs(curvature)
    return Steering(v, w, along, track.length - along)


class Drivable(Protocol):
    """What the follower needs of a robot (a :class:`~ravh_sim.robot.robot.Robot`, or a fake)."""

    @property
    def pose(self) -> Pose2D: ...

    def set_command(self, v: float, w: float) -> None: ...


class SpeedLimits(Protocol):
    """What the follower needs of a robot profile (a :class:`~ravh_sim.robot.profile.RobotProfile`):
    navigation sits below ravh_sim.robot, so it names what it reads instead of importing the profile."""

    @property
    def max_linear_speed(self) -> float: ...

    @property
    def max_angular_speed(self) -> float: ...


class Clock(Protocol):
    """What :func:`drive` needs of a simulation (a :class:`~ravh_sim.robot.simulation.Simulation`)."""

    @property
    def dt(self) -> float: ...

    @property
    def time(self) -> float: ...

    def step(self, n: int = 1) -> None: ...


class MapProvider(Protocol):
    """What the follower needs of navigation (a :class:`~ravh_sim.nav.navigation.Navigation`)."""

    def map(self) -> Grid: ...

    def plan(self, start: Point, goal: Point) -> Path: ...


class _Phase(Enum):
    FOLLOW = "follow"
    ALIGN = "align"
    BACK_OFF = "back_off"


class PathFollower:
    """Drives ``robot`` along paths from ``navigation`` within ``profile``'s speed limits.

    Call :meth:`navigate_to` (or :meth:`follow`), then :meth:`update` at the control rate.
    """

    def __init__(self, robot: Drivable, navigation: MapProvider, profile: SpeedLimits,
                 config: FollowerConfig | None = None) -> None:
        self.robot, self.navigation, self.profile = robot, navigation, profile
        self.config = config or FollowerConfig()
        self.status = Status.IDLE
        self.reason = ""
        self.recoveries = 0
        self.path: Path | None = None
        self.goal: Point = (0.0, 0.0)
        self.goal_yaw: float | None = None
        self._track = Track([(0.0, 0.0)])
        self._planned_on: Grid | None = None
        self._phase = _Phase.FOLLOW
        self._along = 0.0
        self._remaining = 0.0
        self._last_pose: Pose2D = robot.pose
        self._last_v = 0.0
        self._stalled = 0.0
        self._best = math.inf
        self._since_progress = 0.0
        self._backoff_from: Pose2D = robot.pose
        self._backoff_time = 0.0

    # ------------------------------------------------------------------ goals
    def navigate_to(self, goal: Point | Pose2D) -> Path:
        """Plan from the robot's pose to ``goal`` ((x, y) or (x, y, yaw)) and start following.
        Raises :class:`~ravh_sim.nav.planner.Unreachable` when there is no path."""
        x, y, *yaw = goal
        path = self.navigation.plan(self.robot.pose[:2], (x, y))
        self.follow(path, yaw[0] if yaw else None)
        return path

    def follow(self, path: Path, yaw: float | None = None) -> None:
        """Follow ``path`` to its last point, then turn to ``yaw`` if given."""
        self.goal, self.goal_yaw = path.points[-1], yaw
        self.recoveries, self.reason = 0, ""
        self._start(path)

    def cancel(self) -> None:
        """Stop the robot and drop the goal."""
        self.robot.set_command(0.0, 0.0)
        self.status, self.reason = Status.IDLE, "cancelled"

    @property
    def remaining(self) -> float:
        """Metres of path left to the goal (as of the last update)."""
        return self._remaining

    def _start(self, path: Path) -> None:
        self.path, self._track = path, Track(path.points)
        self._planned_on = self.navigation.map()
        self.status, self._phase = Status.ACTIVE, _Phase.FOLLOW
        self._along, self._remaining = 0.0, self._track.length
        self._last_pose, self._last_v, self._stalled = self.robot.pose, 0.0, 0.0
        self._best, self._since_progress = math.inf, 0.0

    # ------------------------------------------------------------------ control
    def update(self, dt: float) -> Status:
        """One control tick of ``dt`` seconds: read the pose, command the robot, report."""
        if self.status in (Status.IDLE, Status.ARRIVED, Status.FAILED):
            return self.status
        pose = self.robot.pose
        if self._phase is _Phase.BACK_OFF:
            return self._back_off(pose, dt)
        if self._phase is _Phase.ALIGN:
            return self._align(pose)
        cfg = self.config
        s = steer(pose, self._track, self._along, self.profile.max_linear_speed,
                  self.profile.max_angular_speed, cfg)
        self._along, self._remaining = s.along, s.remaining
        if math.hypot(self.goal[0] - pose[0], self.goal[1] - pose[1]) <= cfg.goal_tolerance:
            self._remaining = 0.0
            self._phase = _Phase.ALIGN
            return self._align(pose)
        cause = self._map_blocks_ahead(s.along)
        if cause:
            return self._recover(cause, back_off=False)
        cause = self._stall(pose, dt) or self._no_progress(s.remaining, dt)
        if cause:
            return self._recover(cause, back_off=True)
        self.robot.set_command(s.v, s.w)
        self._last_v = s.v
        self.status = Status.ACTIVE
        return self.status

    def _align(self, pose: Pose2D) -> Status:
        error = 0.0 if self.goal_yaw is None else wrap_angle(self.goal_yaw - pose[2])
        if abs(error) <= self.config.yaw_tolerance:
            self.robot.set_command(0.0, 0.0)
            self.status = Status.ARRIVED
            return self.status
        w_max = self.profile.max_angular_speed
        self.robot.set_command(0.0, min(max(self.config.heading_gain * error, -w_max), w_max))
        self.status = Status.ACTIVE
        return self.status

    # ------------------------------------------------------------------ blocked
    def _map_blocks_ahead(self, along: float) -> str:
        """A reason if the next ``check_ahead`` metres of path cross cells that were free when the
        path was planned and are not free on the map now."""
        grid = self.navigation.map()
        planned = self._planned_on
        if grid is planned or planned is None:
            return ""
        step = grid.resolution / 2
        s, end = along, min(along + self.config.check_ahead, self._track.length)
        while s <= end:
            x, y = self._track.point_at(s)
            if planned.is_free(x, y) and not grid.is_free(x, y):
                return f"the map changed: the path is blocked at ({x:.2f}, {y:.2f})"
            s += step
        return ""

    def _stall(self, pose: Pose2D, dt: float) -> str:
        moved = math.hypot(pose[0] - self._last_pose[0], pose[1] - self._last_pose[1])
        self._last_pose = pose
        cfg = self.config
        if self._last_v >= cfg.min_speed and moved < cfg.stall_ratio * self._last_v * dt:
            self._stalled += dt
        else:
            self._stalled = 0.0
        if self._stalled >= cfg.stall_time:
            return f"no motion for {self._stalled:.1f} s at ({pose[0]:.2f}, {pose[1]:.2f})"
        return ""

    def _no_progress(self, remaining: float, dt: float) -> str:
        if remaining < self._best - self.config.min_progress:
            self._best, self._since_progress = remaining, 0.0
            return ""
        self._since_progress += dt
        if self._since_progress >= self.config.progress_timeout:
            return f"no progress along the path for {self._since_progress:.1f} s"
        return ""

    def _recover(self, cause: str, back_off: bool) -> Status:
        self.recoveries += 1
        self.reason = cause
        if self.recoveries > self.config.max_recoveries:
            return self._fail(f"gave up after {self.config.max_recoveries} recoveries; last: {cause}")
        if not back_off:
            return self._replan()
        self._phase, self._backoff_from, self._backoff_time = _Phase.BACK_OFF, self.robot.pose, 0.0
        self.robot.set_command(-self.config.backoff_speed, 0.0)
        self.status = Status.BLOCKED
        return self.status

    def _back_off(self, pose: Pose2D, dt: float) -> Status:
        cfg = self.config
        self._backoff_time += dt
        moved = math.hypot(pose[0] - self._backoff_from[0], pose[1] - self._backoff_from[1])
        patience = 2.0 * cfg.backoff_distance / cfg.backoff_speed
        if moved < cfg.backoff_distance and self._backoff_time < patience:
            return self.status
        self.robot.set_command(0.0, 0.0)
        return self._replan()

    def _replan(self) -> Status:
        try:
            path = self.navigation.plan(self.robot.pose[:2], self.goal)
        except Unreachable as e:
            return self._fail(str(e))
        self._start(path)
        self.status = Status.BLOCKED
        return self.status

    def _fail(self, reason: str) -> Status:
        self.robot.set_command(0.0, 0.0)
        self.status, self.reason = Status.FAILED, reason
        return self.status


def drive(simulation: Clock, follower: PathFollower, timeout: float,
          period: float = CONTROL_PERIOD) -> Status:
    """Run ``simulation`` with ``follower`` in the loop every ``period`` seconds until it arrives or
    fails, or ``timeout`` simulated seconds pass (then the robot keeps its last command)."""
    steps = max(1, round(period / simulation.dt))
    end = simulation.time + timeout
    status = follower.status
    while simulation.time < end:
        status = follower.update(steps * simulation.dt)
        if status in (Status.ARRIVED, Status.FAILED, Status.IDLE):
            break
        simulation.step(steps)
    return status
