"""The virtual robot, the simulation clock, the path follower and the Navigation Manager.

Physics checks measure against the house model (wall, door and object boxes), not against what
pybullet reports about itself, so a robot that sinks into a wall fails them whatever pybullet says.
"""
from __future__ import annotations

import dataclasses
import math
import random
from collections.abc import Callable

import numpy as np
import pybullet as pb
import pytest

from ravh_sim.cli import main as cli_main
from ravh_sim.errors import UserError
from ravh_sim.nav.follower import FollowerConfig, PathFollower, Status, Track, drive, steer
from ravh_sim.nav.grid import FREE, OCCUPIED, Grid
from ravh_sim.nav.mapio import read_map
from ravh_sim.nav.navigation import Navigation
from ravh_sim.nav.planner import Path, Unreachable, densify
from ravh_sim.paths import ROBOTS_DIR
from ravh_sim.poses import relative, wrap_angle
from ravh_sim.robot.profile import load_profile
from ravh_sim.robot.robot import Odometry, Robot
from ravh_sim.robot.simulation import Simulation
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.footprint import make_footprint
from ravh_sim.world.scene import World
from ravh_sim.world.settings import AgentSpec, resolve
from ravh_sim.world.solids import DOOR_LEAF_THICKNESS, object_parts

GIRAFF = load_profile("giraff")
R = GIRAFF.radius
VMAX, WMAX = GIRAFF.max_linear_speed, GIRAFF.max_angular_speed
TOUCH = 0.02            # m: a robot pressed against something is at most this far beyond its radius
SINK = 0.01             # m: the most a robot may ever overlap anything
STEPS_PER_TICK = 12     # physics steps per follower update (20 Hz at 240 Hz)


@pytest.fixture
def make_world(houses, default_settings):
    """Build worlds (TinyRenderer, no GL) and close them after the test."""
    made: list[World] = []

    def make(number: int, agents: list[AgentSpec] | None = None, dressing: str | None = None) -> World:
        house = houses[number]
        settings = resolve(default_settings, house)
        if agents is not None:
            settings = settings.changed(agents=tuple(agents))
        if dressing is not None:
            settings = settings.changed(dressing=dressing)
        world = World(house, settings)
        made.append(world)
        return world

    yield make
    for world in made:
        world.close()


# --------------------------------------------------------------------------- geometry

Rect = tuple[tuple[float, float], tuple[float, float], float]     # centre, (along, across), yaw


def rect_distance(xy, rect: Rect) -> float:
    (cx, cy), (length, width), yaw = rect
    dx, dy = xy[0] - cx, xy[1] - cy
    lx = dx * math.cos(yaw) + dy * math.sin(yaw)
    ly = -dx * math.sin(yaw) + dy * math.cos(yaw)
    return math.hypot(max(abs(lx) - length / 2, 0.0), max(abs(ly) - width / 2, 0.0))


def wall_rects(house) -> list[Rect]:
    """Every wall piece a robot of the profile's height can touch."""
    floor = {room.id: room.floor_z for room in house.rooms}
    out = []
    for w in house.walls:
        if w.z0 < floor[w.room] + GIRAFF.height and w.z1 > floor[w.room]:
            (ax, ay), (bx, by) = w.a, w.b
            centre = ((ax + bx) / 2, (ay + by) / 2)
            out.append((centre, (w.length, w.thickness), math.atan2(by - ay, bx - ax)))
    return out


def door_leaf_rect(door) -> Rect:
    """The closed leaf's box: the drawn leaf model's width and thickness."""
    return door.position[:2], (door.leaf[0], DOOR_LEAF_THICKNESS), door.yaw


def part_rects(world: World, obj_id: str) -> list[Rect]:
    """The floor rectangles of an object's model parts (a closed door: its leaf) that a robot can
    touch: the surfaces it stops at (a door slab or a closet's fronts lie inside their box)."""
    obj = world.house.object(obj_id)
    floor = world.house.room(obj.room).floor_z
    if obj_id in world.house.door_by_id:
        floor = min(world.house.room(r).floor_z for r in world.house.door_by_id[obj_id].rooms)
    placed = object_parts(world.house, obj, world.state.models[obj_id])
    return list(placed.footprints(floor + 0.02, floor + GIRAFF.height))


def object_rect(world, obj) -> Rect:
    box = obj.box(world.state.models[obj.id])
    return box.position[:2], box.size[:2], obj.yaw


def approaches(grid: Grid, rect: Rect, angle: float = 0.0, run: float = 1.0):
    """(start pose, side normal) for driving into the middle of each side of ``rect`` from ``run``
    metres away, ``angle`` off the side's normal, where the map shows a clear run up to contact."""
    (cx, cy), (length, width), yaw = rect
    for normal, half in ((yaw + math.pi / 2, width / 2), (yaw - math.pi / 2, width / 2),
                         (yaw, length / 2), (yaw + math.pi, length / 2)):
        nx, ny = math.cos(normal), math.sin(normal)
        contact = (cx + nx * (half + R), cy + ny * (half + R))
        dx, dy = math.cos(normal + angle), math.sin(normal + angle)
        if all(grid.is_free(contact[0] + dx * s, contact[1] + dy * s) for s in np.linspace(0.06, run, 50)):
            start = (contact[0] + dx * run, contact[1] + dy * run)
            yield (start[0], start[1], math.atan2(-dy, -dx)), (nx, ny)


def ram(world: World, pose, seconds: float, watch: list[Rect] | Callable[[tuple], float]
        ) -> tuple[list[float], Robot]:
    """Drive a robot from ``pose`` at full speed for ``seconds``; the least distance from its centre
    to any of ``watch`` (rectangles, or a distance function of the centre) after every physics step."""
    sim = Simulation(world, [AgentSpec("robot", "giraff", pose)])
    robot = sim.robot("robot")
    robot.set_command(VMAX, 0.0)
    distances = []
    for _ in range(int(seconds * world.physics_hz)):
        sim.step()
        xy = robot.pose[:2]
        distances.append(watch(xy) if callable(watch) else min(rect_distance(xy, r) for r in watch))
    return distances, robot


def model_distance(world: World, obj_id: str) -> Callable[[tuple], float]:
    """Distance on the floor plan from a point to the drawn triangles of a library model that reach
    into the robot's height band (0 inside one): computed from the model itself, not its colliders."""
    obj = world.house.object(obj_id)
    placed = object_parts(world.house, obj, world.state.models[obj_id])
    assert placed.model is not None
    floor = world.house.room(obj.room).floor_z
    c, s = math.cos(placed.yaw), math.sin(placed.yaw)
    local = placed.model.vertices
    xyz = np.column_stack([placed.position[0] + c * local[:, 0] - s * local[:, 1],
                           placed.position[1] + s * local[:, 0] + c * local[:, 1],
                           placed.position[2] + local[:, 2]])
    triangles = xyz[placed.model.faces]
    band = (triangles[:, :, 2].max(axis=1) > floor + 0.02) & (triangles[:, :, 2].min(axis=1) < floor + GIRAFF.height)
    flat = triangles[band][:, :, :2]

    def distance(xy) -> float:
        p = np.asarray(xy, float)
        a, b, c_ = flat[:, 0], flat[:, 1], flat[:, 2]
        cross = [(v - u)[:, 0] * (p - u)[:, 1] - (v - u)[:, 1] * (p - u)[:, 0] for u, v in ((a, b), (b, c_), (c_, a))]
        inside = ((cross[0] >= 0) & (cross[1] >= 0) & (cross[2] >= 0)) | ((cross[0] <= 0) & (cross[1] <= 0)
                                                                         & (cross[2] <= 0))
        if inside.any():
            return 0.0
        edges = []
        for u, v in ((a, b), (b, c_), (c_, a)):
            d = v - u
            t = np.clip(np.einsum("ij,ij->i", p - u, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-12), 0, 1)
            edges.append(np.linalg.norm(u + t[:, None] * d - p, axis=1))
        return float(np.min(edges))
    return distance


# --------------------------------------------------------------------------- collisions

@pytest.mark.parametrize("angle_deg", [0, 40])
def test_full_speed_into_a_wall_stops_at_the_wall(make_world, angle_deg):
    """The bare wall: with dressing, the nearest wall may hold a picture, whose 4 cm frame stops the
    robot's head first."""
    world = make_world(15, dressing="none")
    walls = wall_rects(world.house)
    nav = Navigation(world.house, world.state, GIRAFF)
    room = world.house.room("KitchenLivingRoom_1")
    goal = nav.room_goal(room.id)
    _, wall, (pose, (nx, ny)) = min(((rect_distance(goal, w), w, a) for w in walls
                                     for a in approaches(nav.map(), w, math.radians(angle_deg))
                                     if room.contains(*a[0][:2])), key=lambda c: c[0])
    distances, robot = ram(world, pose, seconds=1.0 / VMAX + 4.0, watch=walls)
    assert min(distances) >= R - SINK, f"sank {R - min(distances):.3f} m into a wall"
    assert distances[-1] <= R + TOUCH, "never reached the wall"
    side = (robot.pose[0] - wall[0][0]) * nx + (robot.pose[1] - wall[0][1]) * ny
    assert side > 0, "ended on the far side of the wall"
    assert world.house.room_at(*robot.pose[:2]) is room


def test_full_speed_into_a_closed_door_stops_at_the_leaf(make_world):
    world = make_world(15)
    nav = Navigation(world.house, world.state, GIRAFF)
    open_map = nav.map()                                        # doorways free: a clear run up to them
    for door in world.house.doors:
        if world.state.doors[door.id] and len(door.rooms) == 2:
            leaf = door_leaf_rect(door)
            found = next(approaches(open_map, leaf), None)
            if found:
                break
    assert found, "no open door in house 15 with a clear approach"
    pose, (nx, ny) = found
    Appearance(world).set_door(door.id, False)
    distances, robot = ram(world, pose, seconds=1.0 / VMAX + 4.0,
                           watch=[*part_rects(world, door.id), *wall_rects(world.house)])
    assert min(distances) >= R - SINK
    to_leaf = rect_distance(robot.pose[:2], leaf)
    assert to_leaf <= R + TOUCH, "never reached the door"
    assert (robot.pose[0] - leaf[0][0]) * nx + (robot.pose[1] - leaf[0][1]) * ny > 0, "passed the door"


@pytest.mark.parametrize("kind", ["Bed", "Closet", "Chair", "Refrigerator"])
def test_full_speed_into_furniture_stops_at_it(make_world, kind):
    world = make_world(15)
    nav = Navigation(world.house, world.state, GIRAFF)
    for obj in world.house.objects:
        if obj.type == kind:
            rect = object_rect(world, obj)
            found = next(approaches(nav.map(), rect), None)
            if found:
                break
    assert found, f"no {kind} with a clear approach in house 15"
    pose, (nx, ny) = found
    drawn = object_parts(world.house, obj, world.state.models[obj.id]).model is not None
    distances, robot = ram(world, pose, seconds=1.0 / VMAX + 4.0,
                           watch=model_distance(world, obj.id) if drawn else part_rects(world, obj.id))
    assert min(distances) >= R - SINK, f"sank {R - min(distances):.3f} m into {obj.id}"
    assert distances[-1] <= R + TOUCH, f"never reached {obj.id}"
    assert (robot.pose[0] - rect[0][0]) * nx + (robot.pose[1] - rect[0][1]) * ny > 0


def test_a_start_overlapping_a_wall_is_pushed_out_and_stays_put(make_world):
    """House 3's station is 10 cm inside a wall's reach: the robot starts just clear of it instead
    of being flung out by the contact solver."""
    world = make_world(3)
    station = world.house.station.position[:2]
    assert min(rect_distance(station, w) for w in wall_rects(world.house)) < R - 0.05
    sim = Simulation(world)
    robot = sim.robot("robot")
    start = robot.pose
    assert min(rect_distance(start[:2], w) for w in wall_rects(world.house)) >= R - SINK
    assert math.dist(start[:2], station) < 0.15
    sim.step(240)
    assert math.dist(robot.pose[:2], start[:2]) < 1e-3
    recorded = world.state.agents[0].pose                      # the footprint says where it started
    assert recorded[:2] == pytest.approx(start[:2], abs=1e-4) and recorded[:2] != pytest.approx(station)
    assert make_footprint(world.house, world.state.settings())["settings"]["agents"][0]["pose"] == list(recorded)


def test_a_start_inside_furniture_is_refused_naming_the_nearest_free_pose(make_world):
    """House 15: a start wedged between the shower and the basin cannot be pushed clear; it is
    refused, and the pose the error names is one where the robot starts clear and stays."""
    asked = (-0.25, 0.95, 0.0)
    with pytest.raises(UserError, match=r"'robot': start pose \[-0.25, 0.95, 0.0\] is inside an obstacle; "
                                        r"nearest free pose: \[") as refused:
        Simulation(make_world(15, [AgentSpec("robot", "giraff", asked)]))
    named = str(refused.value).split("nearest free pose: [")[1].rstrip("]")
    suggested = tuple(float(v) for v in named.split(","))
    world = make_world(15, [AgentSpec("robot", "giraff", suggested)])
    sim = Simulation(world)
    robot = sim.robot("robot")
    assert math.dist(suggested[:2], asked[:2]) < 1.0                # the bathroom is cramped
    assert robot.is_clear() and world.state.agents[0].pose == suggested
    sim.step(240)
    assert math.dist(robot.pose[:2], suggested[:2]) < 1e-3


# --------------------------------------------------------------------------- limits and commands

def open_ground(world: World) -> tuple[float, float]:
    """A point on the ground slab well outside the house: nothing to hit."""
    xmin, ymin, xmax, ymax = world.house.bounds
    return xmax + 6.0, ymax + 6.0


def test_speed_and_acceleration_limits_hold(make_world):
    world = make_world(20)
    x, y = open_ground(world)
    sim = Simulation(world, [AgentSpec("robot", "giraff", (x, y, 0.0))])
    robot = sim.robot("robot")
    poses = [robot.pose]
    for v, w, seconds in ((5.0, 9.0, 2.0), (-5.0, -9.0, 1.5), (0.0, 0.0, 1.0)):
        robot.set_command(v, w)
        assert robot.command == (math.copysign(VMAX, v) if v else 0.0, math.copysign(WMAX, w) if w else 0.0)
        for _ in range(int(seconds * world.physics_hz)):
            sim.step()
            poses.append(robot.pose)
    p = np.asarray(poses)
    dt = sim.dt
    heading = p[:-1, 2]
    forward = ((p[1:, 0] - p[:-1, 0]) * np.cos(heading) + (p[1:, 1] - p[:-1, 1]) * np.sin(heading)) / dt
    turn = np.array([wrap_angle(b - a) for a, b in zip(p[:-1, 2], p[1:, 2])]) / dt
    assert np.abs(forward).max() <= VMAX * 1.01 and np.abs(turn).max() <= WMAX * 1.01
    assert forward.max() >= VMAX * 0.99 and forward.min() <= -VMAX * 0.99        # the limits are reached
    assert turn.max() >= WMAX * 0.99 and turn.min() <= -WMAX * 0.99
    lin_acc, ang_acc = np.abs(np.diff(forward)) / dt, np.abs(np.diff(turn)) / dt
    assert lin_acc.max() <= GIRAFF.max_linear_acceleration * 1.05
    assert ang_acc.max() <= GIRAFF.max_angular_acceleration * 1.05
    assert lin_acc.max() >= GIRAFF.max_linear_acceleration * 0.9                 # and used
    assert robot.velocity == pytest.approx((0.0, 0.0), abs=1e-6)


@pytest.mark.parametrize("bad", [(math.nan, 0.0), (0.0, math.inf), (-math.inf, math.nan)])
def test_non_finite_commands_raise_and_keep_the_last_command(make_world, bad):
    world = make_world(20)
    robot = Simulation(world).robot("robot")
    robot.set_command(0.1, 0.2)
    with pytest.raises(ValueError, match="finite"):
        robot.set_command(*bad)
    assert robot.command == (0.1, 0.2)


def test_teleport_puts_the_robot_at_rest_and_odometry_does_not_see_it(make_world):
    world = make_world(20)
    x, y = open_ground(world)
    sim = Simulation(world, [AgentSpec("robot", "giraff", (x, y, 0.0))])
    robot = sim.robot("robot")
    robot.set_command(VMAX, WMAX)
    sim.step(240)
    odom = robot.odometry
    robot.teleport(x + 3.0, y - 2.0, 1.0)
    assert robot.pose == pytest.approx((x + 3.0, y - 2.0, 1.0), abs=1e-9)
    assert robot.velocity == (0.0, 0.0) and robot.command == (0.0, 0.0)
    sim.step(10)
    assert robot.odometry == pytest.approx(odom, abs=1e-9)
    assert robot.pose == pytest.approx((x + 3.0, y - 2.0, 1.0), abs=1e-6)


# --------------------------------------------------------------------------- several agents

def test_two_agents_move_independently_and_collide(make_world, tmp_path):
    small = tmp_path / "small.yaml"
    small.write_text((ROBOTS_DIR / "giraff.yaml").read_text()
                     .replace("footprint_radius: 0.25", "footprint_radius: 0.15"))
    world = make_world(20)
    x, y = open_ground(world)
    sim = Simulation(world, [AgentSpec("a", "giraff", (x, y, 0.0)),
                             AgentSpec("b", str(small), (x + 2.0, y, math.pi))])
    a, b = sim.robot("a"), sim.robot("b")
    assert b.profile.radius == 0.15 and a.profile.radius == R
    with pytest.raises(Exception, match="unknown agent 'c'"):
        sim.robot("c")
    b_start = b.pose
    a.set_command(VMAX, 0.0)
    sim.step(2 * 240)
    assert a.pose[0] - x == pytest.approx(2 * VMAX, abs=0.02)
    assert b.pose == b_start and b.odometry == (0.0, 0.0, 0.0)
    b.set_command(VMAX, 0.0)
    gaps = []
    for _ in range(6 * 240):
        sim.step()
        gaps.append(math.dist(a.pose[:2], b.pose[:2]))
    assert min(gaps) >= R + 0.15 - SINK, "the robots overlap"
    assert gaps[-1] <= R + 0.15 + TOUCH, "the robots never met"
    assert sim.time == pytest.approx(8.0)


# --------------------------------------------------------------------------- odometry

def drive_odometry(sigma_l: float, sigma_a: float, runs: int, steps: int, length: float,
                   turn: float) -> np.ndarray:
    """Final odometry errors (x, y, yaw) of ``runs`` straight drives of ``length`` metres, turning
    ``turn`` radians on the way, in ``steps`` increments."""
    errors = []
    rng = random.Random(7)
    for _ in range(runs):
        odom = Odometry((0.0, 0.0, 0.0), sigma_l, sigma_a, rng)
        for k in range(1, steps + 1):
            odom.update((length * k / steps, 0.0, turn * k / steps))
        errors.append(relative((length, 0.0, turn), odom.pose))
    return np.asarray(errors)


@pytest.mark.parametrize("steps", [10, 200])
def test_odometry_noise_has_the_configured_spread_at_any_rate(steps):
    sigma_l, sigma_a = GIRAFF.odom_linear_sigma, GIRAFF.odom_angular_sigma
    straight = drive_odometry(sigma_l, sigma_a, runs=1500, steps=steps, length=1.0, turn=0.0)
    assert straight[:, 0].std() == pytest.approx(sigma_l, rel=0.1)
    assert abs(straight[:, 0].mean()) < 4 * sigma_l / math.sqrt(1500)
    assert np.abs(straight[:, 2]).max() == 0.0                 # no turning, no heading noise
    far = drive_odometry(sigma_l, sigma_a, runs=1500, steps=steps, length=4.0, turn=0.0)
    assert far[:, 0].std() == pytest.approx(sigma_l * 2.0, rel=0.1)   # grows with sqrt(distance)
    spin = drive_odometry(sigma_l, sigma_a, runs=1500, steps=steps, length=0.0, turn=1.0)
    assert spin[:, 2].std() == pytest.approx(sigma_a, rel=0.1)
    assert abs(spin[:, 2].mean()) < 4 * sigma_a / math.sqrt(1500)


def test_zero_noise_odometry_is_exact_and_noisy_odometry_drifts(make_world):
    world = make_world(20)
    x, y = open_ground(world)
    exact = dataclasses.replace(GIRAFF, odom_linear_sigma=0.0, odom_angular_sigma=0.0)
    start = (x, y, 0.7)
    perfect = Robot(world, exact, "perfect", start)
    noisy = Robot(world, GIRAFF, "noisy", (x, y + 5.0, 0.7))
    twin = Robot(world, GIRAFF, "noisy", (x, y + 10.0, 0.7))     # same name and seed: same noise
    robots = [perfect, noisy, twin]
    for v, w in ((VMAX, 0.0), (VMAX, WMAX), (-VMAX, -WMAX), (0.0, WMAX)):
        for robot in robots:
            robot.set_command(v, w)
        for _ in range(3 * 240):
            for robot in robots:
                robot.step()
            pb.stepSimulation(physicsClientId=world.client)
            for robot in robots:
                robot.sync()
    truth = relative(start, perfect.pose)
    assert math.hypot(truth[0], truth[1]) > 0.5
    assert perfect.odometry == pytest.approx(truth, abs=1e-9)
    noisy_truth = relative((x, y + 5.0, 0.7), noisy.pose)
    error = math.dist(noisy.odometry[:2], noisy_truth[:2])
    assert 1e-4 < error < 0.5
    assert twin.odometry == pytest.approx(noisy.odometry, abs=1e-9)


# --------------------------------------------------------------------------- pure controller

def test_steer_pursues_the_path_and_turns_on_the_spot():
    track = Track([(0.0, 0.0), (5.0, 0.0)])
    cfg = FollowerConfig()
    on_path = steer((0.0, 0.0, 0.0), track, 0.0, VMAX, WMAX, cfg)
    assert on_path.v == VMAX and on_path.w == pytest.approx(0.0)
    left = steer((1.0, 0.2, 0.0), track, 0.0, VMAX, WMAX, cfg)
    assert 0 < left.v <= VMAX and -WMAX <= left.w < 0                    # turn right, back onto it
    assert left.along == pytest.approx(1.0)
    facing_away = steer((1.0, 0.0, math.pi / 2), track, 0.0, VMAX, WMAX, cfg)
    assert facing_away.v == 0.0 and facing_away.w == -WMAX
    near_goal = steer((4.9, 0.0, 0.0), track, 4.0, VMAX, WMAX, cfg)
    assert 0 < near_goal.v < VMAX and near_goal.remaining == pytest.approx(0.1)


def test_track_projection_never_jumps_to_a_later_part_of_the_path():
    hairpin = Track([(0.0, 0.0), (5.0, 0.0), (5.0, 0.5), (0.0, 0.5)])
    assert hairpin.length == pytest.approx(10.5)
    assert hairpin.project((1.0, 0.45), 0.5, 1.0) == pytest.approx(1.0)   # not 9.5 on the way back
    assert hairpin.project((1.0, 0.0), 3.0, 1.0) == pytest.approx(3.0)    # never backwards
    assert hairpin.point_at(5.25) == pytest.approx((5.0, 0.25))


class FakeRobot:
    """A unicycle that moves exactly as commanded (or not at all when ``stuck``)."""

    def __init__(self, pose=(0.0, 0.0, 0.0)) -> None:
        self.pose, self.cmd, self.stuck, self.commands = pose, (0.0, 0.0), False, []

    def set_command(self, v: float, w: float) -> None:
        self.cmd = (v, w)
        self.commands.append(self.cmd)

    def advance(self, dt: float) -> None:
        if not self.stuck:
            x, y, yaw = self.pose
            v, w = self.cmd
            self.pose = (x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw), wrap_angle(yaw + w * dt))


class FakeNavigation:
    """An open 20 m square; plans go through ``via`` when set; ``unreachable`` fails every plan."""

    def __init__(self) -> None:
        self.grid = Grid(np.full((400, 400), FREE, np.int8), (-10.0, -10.0), 0.05)
        self.via: list[tuple[float, float]] = []
        self.unreachable = ""
        self.plans = 0

    def map(self) -> Grid:
        return self.grid

    def plan(self, start, goal) -> Path:
        self.plans += 1
        if self.unreachable:
            raise Unreachable("goal", self.unreachable)
        return Path((tuple(start), *self.via, tuple(goal)))


def run_fake(follower: PathFollower, robot: FakeRobot, seconds: float, dt: float = 0.05) -> list[Status]:
    statuses = []
    for _ in range(int(seconds / dt)):
        statuses.append(follower.update(dt))
        if statuses[-1] in (Status.ARRIVED, Status.FAILED):
            break
        robot.advance(dt)
    return statuses


def test_follower_reaches_the_goal_and_heading_within_limits():
    robot, nav = FakeRobot(), FakeNavigation()
    nav.via = [(3.0, 0.0), (3.0, 3.0)]
    follower = PathFollower(robot, nav, GIRAFF)
    follower.navigate_to((1.0, 3.0, -math.pi / 2))
    statuses = run_fake(follower, robot, 60.0)
    assert statuses[-1] is Status.ARRIVED and follower.recoveries == 0
    assert math.dist(robot.pose[:2], (1.0, 3.0)) <= follower.config.goal_tolerance
    assert abs(wrap_angle(robot.pose[2] + math.pi / 2)) <= follower.config.yaw_tolerance
    assert robot.cmd == (0.0, 0.0)
    assert max(abs(v) for v, _ in robot.commands) <= VMAX and max(abs(w) for _, w in robot.commands) <= WMAX
    assert len(statuses) * 0.05 < (3 + 3 + 2) / VMAX + 20                    # no dawdling


def test_follower_stalled_backs_off_replans_and_gives_up():
    robot, nav = FakeRobot(), FakeNavigation()
    follower = PathFollower(robot, nav, GIRAFF)
    follower.navigate_to((5.0, 0.0))
    robot.stuck = True
    statuses = run_fake(follower, robot, 60.0)
    assert statuses[-1] is Status.FAILED
    assert Status.BLOCKED in statuses
    assert any(v < 0 for v, _ in robot.commands), "never backed off"
    assert nav.plans == 1 + follower.config.max_recoveries
    assert "gave up after 3 recoveries" in follower.reason and "no motion" in follower.reason
    assert robot.cmd == (0.0, 0.0)


def test_follower_fails_with_the_planner_reason_when_no_path_is_left():
    robot, nav = FakeRobot(), FakeNavigation()
    follower = PathFollower(robot, nav, GIRAFF)
    follower.navigate_to((5.0, 0.0))
    run_fake(follower, robot, 2.0)
    robot.stuck = True
    nav.unreachable = "goal is not reachable: every path is blocked (closed doors: Door_9)"
    statuses = run_fake(follower, robot, 30.0)
    assert statuses[-1] is Status.FAILED and follower.reason == nav.unreachable
    follower.cancel()
    assert follower.update(0.05) is Status.IDLE


# --------------------------------------------------------------------------- navigation

def far_goal(nav: Navigation, start) -> tuple[tuple[float, float], float]:
    """The goal of the room whose path from ``start`` is longest, and that length."""
    best = ((0.0, 0.0), -1.0)
    for room in nav.house.rooms:
        try:
            goal = nav.room_goal(room.id, start)
            length = nav.plan(start, goal).length
        except Unreachable:
            continue
        if length > best[1]:
            best = (goal, length)
    return best


def follow_in_sim(sim: Simulation, follower: PathFollower, seconds: float, on_tick=None) -> list[Status]:
    """Run the follower in the loop; also check after every tick that the robot overlaps nothing."""
    robot = follower.robot
    statuses = []
    while sim.time < seconds:
        statuses.append(follower.update(STEPS_PER_TICK * sim.dt))
        if statuses[-1] in (Status.ARRIVED, Status.FAILED):
            break
        if on_tick:
            on_tick()
        sim.step(STEPS_PER_TICK)
        deepest = min((c[8] for c in pb.getContactPoints(robot.body, physicsClientId=sim.world.client)),
                      default=0.0)
        assert deepest >= -SINK, f"robot overlaps something by {-deepest:.3f} m at {robot.pose}"
    return statuses


@pytest.mark.parametrize("number", [15, 20, 23])
def test_follower_drives_from_the_station_to_the_farthest_room(make_world, number):
    world = make_world(number)
    sim = Simulation(world)
    robot = sim.robot("robot")
    nav = Navigation(world.house, world.state, robot.profile)
    goal, length = far_goal(nav, robot.pose[:2])
    assert length > 4.0
    follower = PathFollower(robot, nav, robot.profile)
    follower.navigate_to(goal)
    budget = 1.5 * length / VMAX + 15.0
    statuses = follow_in_sim(sim, follower, budget)
    assert statuses[-1] is Status.ARRIVED, f"{statuses[-1]} after {sim.time:.0f} s: {follower.reason}"
    assert math.dist(robot.pose[:2], goal) <= follower.config.goal_tolerance
    assert follower.recoveries == 0 and follower.remaining == 0.0


def test_drive_helper_runs_the_loop(make_world):
    world = make_world(20)
    sim = Simulation(world)
    robot = sim.robot("robot")
    nav = Navigation(world.house, world.state, robot.profile)
    follower = PathFollower(robot, nav, robot.profile)
    follower.navigate_to(nav.room_goal("Bedroom_1", robot.pose[:2]))
    assert drive(sim, follower, timeout=2.0) is Status.ACTIVE and sim.time == pytest.approx(2.0, abs=0.06)
    assert drive(sim, follower, timeout=120.0) is Status.ARRIVED


def test_closing_the_only_door_makes_a_room_unreachable(make_world):
    world = make_world(20)
    sim = Simulation(world)
    robot = sim.robot("robot")
    nav = Navigation(world.house, world.state, robot.profile)
    goal = nav.room_goal("Bedroom_1", robot.pose[:2])
    before = nav.map()
    assert nav.map() is before                                  # unchanged doors: no rebuild
    nav.plan(robot.pose[:2], goal)
    Appearance(world).set_door("Door_1", False)
    assert nav.map() is not before
    with pytest.raises(Unreachable, match=r"in room Bedroom_1 is not reachable .*closed doors: .*Door_1"):
        nav.plan(robot.pose[:2], goal)
    follower = PathFollower(robot, nav, robot.profile)
    with pytest.raises(Unreachable, match="Door_1"):
        follower.navigate_to(goal)
    Appearance(world).set_door("Door_1", True)
    assert nav.plan(robot.pose[:2], goal).length > 0


def test_follower_replans_around_a_door_closed_on_its_way(make_world):
    """House 27: Corridor_1 is reached through Door_4, or the long way round through the bedroom."""
    world = make_world(27)
    sim = Simulation(world)
    robot = sim.robot("robot")
    nav = Navigation(world.house, world.state, robot.profile)
    door = world.house.door_by_id["Door_4"]
    goal = nav.room_goal("Corridor_1", robot.pose[:2])
    follower = PathFollower(robot, nav, robot.profile)
    first = follower.navigate_to(goal)
    assert min(math.dist(p, door.position[:2]) for p in densify(first.points, 0.05)) < 0.2

    leaf = world.instance("Door_4").body
    touched = []

    def close_door_half_way() -> None:
        if world.state.doors["Door_4"] and follower.remaining < first.length - 4.0:
            Appearance(world).set_door("Door_4", False)
        touched.extend(pb.getContactPoints(robot.body, leaf, physicsClientId=world.client))

    statuses = follow_in_sim(sim, follower, 200.0, close_door_half_way)
    assert not world.state.doors["Door_4"]
    assert Status.BLOCKED in statuses and follower.recoveries == 1
    assert "map changed" in follower.reason
    assert statuses[-1] is Status.ARRIVED, follower.reason
    assert min(math.dist(p, door.position[:2]) for p in densify(follower.path.points, 0.05)) > 0.4
    assert not touched, "the robot ran into the closed door instead of seeing it on the map"


def test_follower_fails_with_a_reason_when_the_only_door_closes_on_its_way(make_world):
    world = make_world(20)
    sim = Simulation(world)
    robot = sim.robot("robot")
    nav = Navigation(world.house, world.state, robot.profile)
    follower = PathFollower(robot, nav, robot.profile)
    first = follower.navigate_to(nav.room_goal("Bedroom_1", robot.pose[:2]))

    leaf = world.instance("Door_1").body
    touched = []

    def close_door() -> None:
        if world.state.doors["Door_1"] and follower.remaining < first.length - 1.0:
            Appearance(world).set_door("Door_1", False)
        touched.extend(pb.getContactPoints(robot.body, leaf, physicsClientId=world.client))

    statuses = follow_in_sim(sim, follower, 60.0, close_door)
    assert statuses[-1] is Status.FAILED
    assert "not reachable" in follower.reason and "Door_1" in follower.reason
    assert robot.command == (0.0, 0.0) and not touched


def test_map_files_match_the_navigation_map(make_world, tmp_path):
    world = make_world(20)
    nav = Navigation(world.house, world.state, GIRAFF)
    nav.write_map(tmp_path / "obstacles")
    nav.write_map(tmp_path / "free", inflated=True)
    for folder, grid in (("obstacles", nav.obstacle_map()), ("free", nav.map())):
        loaded = read_map(tmp_path / folder / "map.yaml")
        assert np.array_equal(loaded.data, grid.data) and loaded.origin == pytest.approx(grid.origin)


def test_cli_map_writes_map_server_files_with_the_chosen_doors(tmp_path, houses):
    door = houses[20].door_by_id["Door_1"]
    assert cli_main(["map", "20", "--doors", "closed", "--resolution", "0.1", "-o", str(tmp_path / "c")]) == 0
    assert cli_main(["map", "20", "--doors", "open", "-o", str(tmp_path / "o")]) == 0
    closed, opened = read_map(tmp_path / "c" / "map.yaml"), read_map(tmp_path / "o" / "map.yaml")
    assert closed.resolution == 0.1 and opened.resolution == 0.05
    assert closed.data[closed.cell_of(*door.position[:2])] == OCCUPIED
    assert opened.data[opened.cell_of(*door.position[:2])] == FREE
    assert cli_main(["map", "20", "--doors", "open", "--inflated", "-o", str(tmp_path / "i")]) == 0
    inflated = read_map(tmp_path / "i" / "map.yaml")
    assert (inflated.data == FREE).sum() < 0.7 * (opened.data == FREE).sum()      # the robot's radius off every wall
    with pytest.raises(SystemExit):
        cli_main(["map", "20", "--resolution", "0", "-o", str(tmp_path / "x")])


def test_follower_gives_up_on_a_robot_standing_in_the_only_doorway(make_world):
    """Another robot is not on the map: the follower bumps into it, backs off, replans the same way
    and after ``max_recoveries`` tries stops with FAILED and the reason."""
    world = make_world(20)
    door = world.house.door_by_id["Door_1"]
    station = world.house.station
    sim = Simulation(world, [AgentSpec("robot", "giraff", (*station.position[:2], station.yaw)),
                             AgentSpec("blocker", "giraff", (*door.position[:2], door.yaw))])
    robot, blocker = sim.robot("robot"), sim.robot("blocker")
    nav = Navigation(world.house, world.state, robot.profile)
    follower = PathFollower(robot, nav, robot.profile)
    follower.navigate_to(nav.room_goal("Bedroom_1", robot.pose[:2]))
    statuses = follow_in_sim(sim, follower, 120.0)
    assert statuses[-1] is Status.FAILED
    assert follower.reason.startswith("gave up after 3 recoveries") and "no motion" in follower.reason
    assert statuses.count(Status.BLOCKED) > 3
    assert math.dist(robot.pose[:2], blocker.pose[:2]) >= 2 * R - SINK
    assert math.dist(blocker.pose[:2], door.position[:2]) < 0.1
