"""Smart camera, laser scanner, lighting and appearance managers, checked against known geometry.

Most tests use a synthetic two-room house whose every wall is known: room A is [0, 6] x [0, 4],
room B is [6.2, 9] x [0, 4], a 1 m doorway joins them at x = 6.1, y in [1, 2]. Floors at z = 0.
"""
from __future__ import annotations

import contextlib
import json
import math
from dataclasses import replace

import cv2
import numpy as np
import pybullet as pb
import pytest

from ravh_msgs_py import names
from ravh_sim.cli import main
from ravh_sim.errors import UserError
from ravh_sim.look.lighting import sun_light
from ravh_sim.nav.follower import PathFollower, Status
from ravh_sim.nav.navigation import Navigation
from ravh_sim.nav.planner import Unreachable
from ravh_sim.poses import quaternion_from_matrix
from ravh_sim.render.backend import resolve_backend
from ravh_sim.render.projection import projection_from_K
from ravh_sim.robot.profile import load_profile
from ravh_sim.robot.simulation import Simulation
from ravh_sim.sensors.camera import CameraOptions, SmartCamera
from ravh_sim.sensors.imaging import encode_jpeg, jpeg_roundtrip
from ravh_sim.sensors.laser import Laser
from ravh_sim.sensors.mount import LINK_TO_OPTICAL
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.footprint import make_footprint
from ravh_sim.world.house import HOUSE_FORMAT, house_from_dict
from ravh_sim.world.scene import World
from ravh_sim.world.settings import load_settings, resolve
from ravh_sim.world.solids import DOOR_LEAF_THICKNESS, object_parts

PROFILE = load_profile("giraff")
WALL = 0.1
ROOM_A = (0.0, 0.0, 6.0, 4.0)
DOOR_Y = (1.0, 2.0)
CEILING = 2.8


# ----------------------------------------------------------------------------- the synthetic house

def _walls(room: str, x0: float, y0: float, x1: float, y1: float, gap_east=None, gap_west=None) -> list:
    """Four walls just outside a rectangle; an optional doorway (y range) in the east or west wall."""
    h = WALL / 2
    out = [{"room": room, "kind": "wall", "a": [x0 - WALL, y0 - h], "b": [x1 + WALL, y0 - h]},
           {"room": room, "kind": "wall", "a": [x0 - WALL, y1 + h], "b": [x1 + WALL, y1 + h]}]
    for x, gap in ((x1 + h, gap_east), (x0 - h, gap_west)):
        if gap is None:
            out.append({"room": room, "kind": "wall", "a": [x, y0 - WALL], "b": [x, y1 + WALL]})
        else:
            out += [{"room": room, "kind": "wall", "a": [x, y0 - WALL], "b": [x, gap[0]]},
                    {"room": room, "kind": "wall", "a": [x, gap[1]], "b": [x, y1 + WALL]},
                    {"room": room, "kind": "lintel", "a": [x, gap[0]], "b": [x, gap[1]], "z0": 2.1}]
    for w in out:
        w.setdefault("z0", 0.0)
        w.update(thickness=WALL, z1=CEILING)
    return out


def _object(oid: str, otype: str, room: str, position, size, yaw=0.0, prefab=None) -> dict:
    return {"id": oid, "type": otype, "tags": [otype], "room": room, "prefab": prefab or otype, "yaw": yaw,
            "size_estimated": False, "default_model": 0, "inherits_model_from": None,
            "models": [{"position": list(position), "size": list(size)}]}


def _box_house():
    rect = lambda x0, y0, x1, y1: [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]  # noqa: E731
    data = {
        "format": HOUSE_FORMAT, "house": 99,
        "rooms": [{"id": "A", "type": "LivingRoom", "name": "A", "floor": rect(*ROOM_A),
                   "floor_z": 0.0, "ceiling_z": CEILING},
                  {"id": "B", "type": "Bedroom", "name": "B", "floor": rect(6.2, 0.0, 9.0, 4.0),
                   "floor_z": 0.0, "ceiling_z": CEILING}],
        "walls": _walls("A", *ROOM_A, gap_east=DOOR_Y) + _walls("B", 6.2, 0.0, 9.0, 4.0, gap_west=DOOR_Y),
        "doors": [{"id": "Door_0", "rooms": ["A", "B"], "position": [6.1, 1.5, 1.05], "yaw": math.pi / 2,
                   "width": 1.0, "height": 2.1, "thickness": 0.2, "leaf": [0.9, 0.05, 2.05],
                   "default_open": True}],
        "windows": [{"id": "Wall_0", "room": "A", "position": [-0.05, 2.0, 1.5], "yaw": -math.pi / 2,
                     "width": 1.2, "height": 1.0, "thickness": 0.17}],
        "lights": [{"id": "Light_0", "kind": "ceiling", "room": "A", "position": [3.0, 2.0, 2.65],
                    "intensity": 1.0, "range": 10.0, "color": [1.0, 0.8, 0.45]},
                   {"id": "Light_1", "kind": "ceiling", "room": "B", "position": [7.6, 2.0, 2.65],
                    "intensity": 1.0, "range": 10.0, "color": [1.0, 0.8, 0.45]}],
        "objects": [_object("Door_0", "Door", "A", (6.1, 1.5, 1.05), (0.2, 1.0, 2.1)),
                    _object("Wall_0", "Wall", "A", (-0.05, 2.0, 1.5), (1.2, 0.17, 1.0), -math.pi / 2,
                            "Window"),
                    _object("Light_0", "Light", "A", (3.0, 2.0, 2.75), (0.36, 0.36, 0.08)),
                    _object("Light_1", "Light", "B", (7.6, 2.0, 2.75), (0.36, 0.36, 0.08)),
                    _object("Closet_0", "Closet", "B", (8.6, 3.0, 1.0), (0.6, 1.2, 2.0)),
                    _object("Station_0", "Station", "A", (1.0, 0.5, 0.01), (0.5, 0.5, 0.02))],
        "station": {"position": [1.0, 0.5, 0.0], "yaw": 0.0, "object_id": "Station_0"},
    }
    return house_from_dict(data, "synthetic")


@pytest.fixture(scope="module")
def box_house():
    return _box_house()


def _world(house, seed=0):
    """The house with the default settings, undressed: these tests measure sensors against its known
    walls and objects (dressing has tests of its own, test_dressing.py)."""
    return World(house, resolve(load_settings(), house, seed).changed(dressing="none"))


@pytest.fixture(scope="module")
def world(box_house):
    with _world(box_house) as w:
        yield w


def gl_box_world():
    """The box house drawn by the GL renderer (tests of light need its shading, not the TinyRenderer's)."""
    with _world(_box_house()) as w:
        if resolve_backend("auto") != "gl":
            pytest.fail("the GL renderer must start on this machine (EGL + llvmpipe)")
        yield w


def restored_appearance(world):
    """Run-time appearance manager; restores the world's settings after each test."""
    app = Appearance(world)
    before = world.state.settings()
    yield app
    app.apply(before)


appearance = pytest.fixture()(restored_appearance)


@pytest.fixture(scope="module")
def camera(world):
    return SmartCamera(world, PROFILE.camera)


def _ids(world, kind=None, name=None):
    return {i.id for i in world.instances
            if (kind is None or i.kind == kind) and (name is None or i.name == name)}


# ----------------------------------------------------------------------------- camera geometry

def test_K_follows_the_paper_formula(camera):
    spec = PROFILE.camera
    fx = spec.focal_length * spec.width / spec.sensor_width
    fy = spec.focal_length * spec.height_px / spec.sensor_height
    assert camera.K == pytest.approx(np.array([[fx, 0, 320.0], [0, fy, 240.0], [0, 0, 1]]))
    assert fx == pytest.approx(548.571, abs=1e-3) and fy == pytest.approx(568.421, abs=1e-3)
    info = camera.camera_info
    assert info.distortion_model == "plumb_bob" and info.D == (0.0,) * 5
    assert info.P == pytest.approx((fx, 0, 320, 0, 0, fy, 240, 0, 0, 0, 1, 0))
    assert (info.width, info.height) == (640, 480)


def test_projection_matrix_maps_K_pixels_to_ndc():
    K = np.array([[500.0, 0, 300.0], [0, 520.0, 200.0], [0, 0, 1]])
    proj = projection_from_K(K, 640, 480, 0.1, 10.0)
    point = np.array([0.3, -0.2, 2.5])                         # optical frame: x right, y down, z fwd
    u, v = (K @ point)[:2] / point[2]
    clip = proj @ np.array([point[0], -point[1], -point[2], 1.0])   # GL eye frame
    ndc = clip[:3] / clip[3]
    assert (ndc[0] + 1) * 640 / 2 - 0.5 == pytest.approx(u)       # window x = u + 0.5
    assert 480 - (ndc[1] + 1) * 480 / 2 - 0.5 == pytest.approx(v)  # image rows run down
    assert ndc[2] == pytest.approx((1 / 0.1 - 1 / 2.5) / (1 / 0.1 - 1 / 10.0) * 2 - 1)


@pytest.mark.parametrize("renderer", ["auto", "tiny"])
def test_points_projected_with_K_land_where_they_render(renderer, world, box_house):
    """Edges of known geometry fall within half a pixel of where K puts them, sub-pixel shifts
    included (the floor is raised by fractions of a pixel)."""
    with (_world(box_house) if renderer == "tiny" else contextlib.nullcontext(world)) as w:
        camera = SmartCamera(w, PROFILE.camera, backend=renderer)
        a_walls, a_floor, b_walls = (w.instance(n).id for n in ("A/walls", "A/floor", "B/walls"))
        for lift in np.linspace(0.0, 0.006, 4):
            # Where room A's floor meets its east wall (x = 6), at y = 3.3: wall above, floor below.
            x, y, yaw = 2.0, 3.0, 0.0
            cap = camera.capture(x, y, yaw, floor_z=lift)
            u, v = camera.project(np.array([[6.0, 3.3, 0.0]]), x, y, yaw, floor_z=lift)[0]
            col = cap.instance[:, int(round(u))]
            boundary = np.flatnonzero((col[:-1] == a_walls) & (col[1:] == a_floor))
            assert len(boundary) == 1 and abs(boundary[0] + 0.5 - v) <= 0.51
            # The doorway's jamb at y = 2: room A's wall piece ends at x = 6.1 where room B's begins.
            x, y, yaw = 2.0, 1.5 + lift, 0.0
            cap = camera.capture(x, y, yaw)
            u, v = camera.project(np.array([[6.1, 2.0, 1.0]]), x, y, yaw)[0]
            row = cap.instance[int(round(v))]
            edges = np.flatnonzero((row[:-1] == a_walls) & (row[1:] == b_walls))
            assert len(edges) == 1 and abs(edges[0] + 0.5 - u) <= 0.51


def _plane_depth(camera, x, y, yaw, row, plane_x=6.0):
    """Expected z-depth along image ``row`` of the vertical plane x = plane_x."""
    position, rotation = camera.optical_pose(x, y, yaw)
    us = np.arange(camera.width)
    rays = np.linalg.inv(camera.K) @ np.stack([us, np.full(len(us), row), np.ones(len(us))])
    return (plane_x - position[0]) / (rotation @ rays)[0]


def test_depth_of_a_wall_is_z_depth_within_a_centimetre(camera, world):
    x, y, yaw = 2.0, 0.6, 0.0                          # facing the east wall below the doorway
    cap = camera.capture(x, y, yaw)
    expected = _plane_depth(camera, x, y, yaw, 240)
    position, rotation = camera.optical_pose(x, y, yaw)
    rays = np.linalg.inv(camera.K) @ np.stack([np.arange(640), np.full(640, 240), np.ones(640)])
    hit_y = position[1] + expected * (rotation @ rays)[1]           # where each pixel meets x = 6
    east = (hit_y > 0.02) & (hit_y < DOOR_Y[0] - 0.02)
    row = cap.depth[240]
    assert east[300:340].all() and east.sum() > 100
    assert (cap.instance[240][east] == world.instance("A/walls").id).all()
    assert np.abs(row[east] - expected[east]).max() < 0.01
    axis = (6.0 - position[0]) / math.cos(math.radians(PROFILE.camera.pitch_deg))
    assert row[320] == pytest.approx(axis, abs=0.01)   # z-depth on the optical axis
    assert abs(row[east].max() - row[320]) < 0.01      # z-depth, not ray length: flat across


def test_nothing_hit_is_nan_and_instance_zero(camera):
    cap = camera.capture(3.0, 2.0, math.pi)
    looking_up = SmartCamera(camera.world, replace(PROFILE.camera, pitch_deg=-80.0))
    up = looking_up.capture(3.0, 2.0, 0.0, floor_z=10.0)
    assert np.isfinite(cap.depth).all() and (cap.instance > 0).all()
    assert np.isnan(up.depth).mean() > 0.9 and (up.instance[np.isnan(up.depth)] == 0).all()


def test_object_straight_ahead_is_the_most_frequent_instance_at_the_centre(camera, world):
    cap = camera.capture(6.8, 3.0, 0.0)
    patch = cap.instance[230:250, 310:330]
    assert np.bincount(patch.ravel()).argmax() == world.instance("Closet_0").id


def test_camera_pose_is_the_pitched_optical_frame(camera):
    position, quat = camera.camera_pose(1.0, 2.0, math.pi / 2)
    spec = PROFILE.camera
    assert position == pytest.approx((1.0, 2.0 + spec.forward, spec.height))
    rot = np.array(pb.getMatrixFromQuaternion(quat)).reshape(3, 3)
    pitch = math.radians(spec.pitch_deg)
    assert rot[:, 2] == pytest.approx([0.0, math.cos(pitch), -math.sin(pitch)], abs=1e-9)   # z forward
    assert rot[:, 0] == pytest.approx([1.0, 0.0, 0.0], abs=1e-9)                           # x right
    assert quaternion_from_matrix(LINK_TO_OPTICAL) == pytest.approx((-0.5, 0.5, -0.5, 0.5))
    assert camera.camera_info.frame_id == names.CAMERA_OPTICAL_FRAME


def test_instance_colours_use_the_footprint_mask_colours(camera, world, box_house):
    cap = camera.capture(6.8, 3.0, 0.0)
    colours = camera.instance_color(cap)
    rows = {r["id"]: tuple(r["mask_color"]) for r in make_footprint(box_house, world.state.settings())["instances"]}
    v, u = 240, 320
    assert tuple(colours[v, u]) == rows[int(cap.instance[v, u])]


# ----------------------------------------------------------------------------- laser

def _room_distance(x, y, angle, x0=0.0, y0=0.0, x1=6.0, y1=4.0):
    c, s = math.cos(angle), math.sin(angle)
    ts = [t for t in ((x1 - x) / c if c > 1e-12 else math.inf, (x0 - x) / c if c < -1e-12 else math.inf,
                      (y1 - y) / s if s > 1e-12 else math.inf, (y0 - y) / s if s < -1e-12 else math.inf)]
    return min(ts)


def test_laser_ranges_match_the_walls_within_a_centimetre(world):
    laser = Laser(world, PROFILE.laser)
    x, y, yaw = 2.0, 2.5, 0.3
    scan = laser.scan(x, y, yaw)
    checked = 0
    for i, r in enumerate(scan.ranges):
        angle = scan.angle_min + i * scan.angle_increment + yaw
        expected = _room_distance(x, y, angle)
        hit_y = y + expected * math.sin(angle)
        if abs(x + expected * math.cos(angle) - 6.0) < 1e-6 and DOOR_Y[0] - 0.05 <= hit_y <= DOOR_Y[1] + 0.05:
            continue                                   # through the doorway
        assert r == pytest.approx(expected, abs=0.01), i
        checked += 1
    assert checked > 340


def test_rep117_counting_and_infinities(world):
    full = Laser(world, PROFILE.laser)
    assert len(full.angles) == 360
    assert full.angle_min == pytest.approx(-math.pi)
    assert full.angle_max == pytest.approx(-math.pi + 359 * full.angle_increment)
    fan = Laser(world, replace(PROFILE.laser, fov_deg=270.0))
    scan = fan.scan(2.0, 2.5, 0.0)
    assert len(scan.ranges) == round((scan.angle_max - scan.angle_min) / scan.angle_increment) + 1 == 271
    assert (scan.angle_min, scan.angle_max) == pytest.approx((-3 * math.pi / 4, 3 * math.pi / 4))
    short = Laser(world, replace(PROFILE.laser, range_max=3.0)).scan(2.0, 2.5, 0.0)
    assert short.ranges[180] == np.inf                 # the east wall is 4 m ahead
    assert short.ranges[270] == pytest.approx(1.5, abs=0.01)
    near = Laser(world, replace(PROFILE.laser, range_min=2.2)).scan(2.0, 2.5, 0.0)
    assert near.ranges[0] == -np.inf                   # the west wall is 2 m behind
    assert near.ranges[180] == pytest.approx(4.0, abs=0.01)
    assert scan.frame_id == names.LASER_FRAME
    assert scan.scan_time == pytest.approx(1 / PROFILE.laser.rate)
    assert scan.time_increment == pytest.approx(scan.scan_time / 271)


def test_laser_sees_past_ignored_bodies(world):
    """A robot part in front of the laser (a bumper, a mast) must not shadow the scan when ignored.
    (Rays that start inside a convex body do not hit it, so a body around the laser never does.)"""
    laser = Laser(world, PROFILE.laser)
    clear = laser.scan(2.0, 2.5, 0.0)
    shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[0.05, 0.3, 0.5], physicsClientId=world.client)
    body = pb.createMultiBody(0, shape, -1, basePosition=[2.35, 2.5, 0.5], physicsClientId=world.client)
    try:
        blocked = laser.scan(2.0, 2.5, 0.0)
        ignored = laser.scan(2.0, 2.5, 0.0, ignore_bodies=[body])
    finally:
        pb.removeBody(body, physicsClientId=world.client)
    assert blocked.ranges[180] == pytest.approx(0.3, abs=0.01) and (blocked.hit_bodies == body).sum() > 40
    assert ignored.ranges == pytest.approx(clear.ranges, abs=1e-4)


def _drive_and_scan(world: World, rooms: int, every_steps: int = 24):
    """Drive the station's robot through the first ``rooms`` room goals with the path follower,
    scanning every ``every_steps`` physics steps as the sim node does; (pose, scan) per scan."""
    sim = Simulation(world)
    robot = next(iter(sim.robots.values()))
    laser, navigation = Laser(world, PROFILE.laser), Navigation(world.house, world.state, PROFILE)
    follower, scans = PathFollower(robot, navigation, PROFILE), []
    for room in world.house.rooms[:rooms]:
        try:
            follower.navigate_to(navigation.room_goal(room.id, robot.pose[:2]))
        except Unreachable:
            continue
        for _ in range(1200):                            # at most 120 s of sim time per room
            if follower.update(every_steps * sim.dt) in (Status.ARRIVED, Status.FAILED, Status.IDLE):
                break
            sim.step(every_steps)
            scans.append((robot.pose, laser.scan(*robot.pose, ignore_bodies=(robot.body,))))
    return robot, scans


@pytest.mark.parametrize("number", [15, 23])
def test_scans_of_a_drive_equal_a_replay_without_the_robot(houses, number):
    """The robot's own body never shortens or lengthens a beam: every scan of a drive through the
    house equals, beam for beam, a scan from the same pose in the same world with the robot gone.
    (Beams used to restart from the robot's base-link box at the map origin and pass walls.)"""
    with World(houses[number], resolve(load_settings(), houses[number])) as world:
        robot, scans = _drive_and_scan(world, rooms=3)
        pb.removeBody(robot.body, physicsClientId=world.client)
        replay = Laser(world, PROFILE.laser)
        assert len(scans) > 150
        for pose, scan in scans:
            again = replay.scan(*pose)
            assert np.array_equal(scan.ranges, again.ranges) and np.array_equal(scan.hit_bodies,
                                                                                again.hit_bodies), pose


def test_the_laser_sees_between_legs(houses):
    """At laser height a dining table or chair blocks with its modelled legs and frames, not its box:
    rays crossing each one's box (at 9 offsets along each axis) hit it exactly where an independent
    ray/triangle intersection with the drawn model says, and some pass between the legs."""
    house = houses[15]
    with World(house, resolve(load_settings(), house)) as world:
        checked, passed_between = 0, 0
        for obj in house.objects:
            box = obj.box(world.state.models[obj.id])
            if obj.type not in ("Table", "Chair") or box.size[2] < 0.6:     # no coffee tables
                continue
            z = house.room(obj.room).floor_z + PROFILE.laser.height
            c, s = math.cos(obj.yaw), math.sin(obj.yaw)

            def in_house(u: float, v: float) -> list[float]:
                return [box.position[0] + c * u - s * v, box.position[1] + s * u + c * v, z]  # noqa: B023 (used in this loop)

            starts, ends = [], []
            for t in np.linspace(-0.4, 0.4, 9):
                u, v = box.size[0] / 2 + 0.01, box.size[1] / 2 + 0.01
                starts += [in_house(-u, t * box.size[1]), in_house(t * box.size[0], -v)]
                ends += [in_house(u, t * box.size[1]), in_house(t * box.size[0], v)]
            hits = pb.rayTestBatch(starts, ends, physicsClientId=world.client)
            body = world.instance(obj.id).body
            drawn = drawn_hits(object_parts(house, obj, world.state.models[obj.id]), np.array(starts),
                               np.array(ends))
            for (hit_body, _, fraction, *_), expected in zip(hits, drawn):
                assert (hit_body == body) == np.isfinite(expected), obj.id
                if hit_body == body:
                    assert fraction == pytest.approx(expected, abs=0.002), obj.id
            passed_between += any(h[0] != body for h in hits) and any(h[0] == body for h in hits)
            checked += 1
    assert checked >= 3 and passed_between >= 1


def drawn_hits(placed, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Per ray, the fraction along it where it first meets the drawn triangles of a placed library
    model (Moller-Trumbore), inf where it misses them."""
    c, s = math.cos(placed.yaw), math.sin(placed.yaw)
    v = placed.model.vertices
    xyz = np.column_stack([placed.position[0] + c * v[:, 0] - s * v[:, 1],
                           placed.position[1] + s * v[:, 0] + c * v[:, 1], placed.position[2] + v[:, 2]])
    a, b, c_ = (xyz[placed.model.faces[:, k]] for k in range(3))
    e1, e2 = b - a, c_ - a
    out = np.full(len(starts), np.inf)
    for i, (p, q) in enumerate(zip(starts, ends)):
        d = q - p
        h = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, h)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        w = p - a
        u = np.einsum("ij,ij->i", w, h) * inv
        qv = np.cross(w, e1)
        vv = (qv @ d) * inv
        t = np.einsum("ij,ij->i", e2, qv) * inv
        hit = ok & (u >= 0) & (vv >= 0) & (u + vv <= 1) & (t >= 0) & (t <= 1)
        if hit.any():
            out[i] = t[hit].min()
    return out


def test_closing_a_door_changes_laser_and_depth_in_the_doorway(world, camera, appearance):
    laser = Laser(world, PROFILE.laser)
    pose = (3.0, 1.5, 0.0)
    open_scan, open_cap = laser.scan(*pose), camera.capture(*pose)
    appearance.set_door("Door_0", False)
    closed_scan, closed_cap = laser.scan(*pose), camera.capture(*pose)
    assert open_scan.ranges[180] == pytest.approx(6.0, abs=0.01)            # room B's far wall
    door = world.instance("Door_0").id
    assert (open_cap.instance == door).mean() < 0.01 < (closed_cap.instance == door).mean()
    position, _ = camera.optical_pose(*pose)
    along_x = math.cos(math.radians(PROFILE.camera.pitch_deg))       # optical axis: x per metre of depth
    leaf_x = position[0] + closed_cap.depth[240, 320] * along_x
    assert 6.1 - DOOR_LEAF_THICKNESS <= leaf_x <= 6.1 + DOOR_LEAF_THICKNESS   # on the leaf model
    assert closed_scan.ranges[180] == pytest.approx(leaf_x - pose[0], abs=0.003)  # the laser hits the leaf
    assert closed_cap.instance[240, 320] == door
    assert position[0] + open_cap.depth[240, 320] * along_x > 8.0            # into room B
    assert world.state.doors["Door_0"] is False


# ----------------------------------------------------------------------------- appearance and lighting

def _mean(img, mask=None):
    return float(img[mask].mean() if mask is not None else img.mean())


def test_day_is_brighter_than_sunset_is_brighter_than_night(camera, appearance):
    means = {}
    for preset in ("day", "sunset", "night"):
        appearance.set_knob("sun_angle", preset)
        means[preset] = _mean(camera.capture(3.0, 2.0, math.pi).rgb)
    # (the window shows the garden at sunset instead of clipping white, so the frame's lead over the
    # lamp-lit night is 1.45x, not the 1.5x a white window gave)
    assert means["day"] > 1.2 * means["sunset"] > 1.2 * 1.3 * means["night"]
    assert sun_light(180).gain[0] > sun_light(180).gain[2]          # sunset light is warm
    assert sun_light(200).gain[2] > sun_light(200).gain[0]          # night is blue


def test_the_robots_sensor_is_noisier_and_darker_at_night_and_the_ideal_camera_is_clean(world, appearance):
    """The Giraff's camera has a sensor model (exposure and gain within limits, shot and read noise):
    the frame-to-frame noise of a still view grows as light falls, a night room with every light off
    stays dark (past the longest exposure and the highest gain); the ideal camera (no sensor) gives
    the same image twice."""
    sensor = PROFILE.camera.sensor
    assert sensor is not None and load_profile("giraff_ideal").camera.sensor is None
    real = SmartCamera(world, PROFILE.camera, agent="real", sensor=sensor)
    ideal = SmartCamera(world, PROFILE.camera, agent="ideal")
    noise, level = {}, {}
    try:
        for preset, lights in (("day", "on"), ("night", "on"), ("night", "off")):
            appearance.set_knob("sun_angle", preset)
            appearance.set_lights("all", lights)
            a, b = (real.capture(3.0, 2.0, math.pi).rgb.astype(np.float32) for _ in range(2))
            noise[preset + lights] = float(np.std(a - b)) / math.sqrt(2)
            level[preset + lights] = float(a.mean())
            assert np.array_equal(ideal.capture(3.0, 2.0, math.pi).rgb, ideal.capture(3.0, 2.0, math.pi).rgb)
    finally:
        real.close()
        ideal.close()
    assert noise["dayon"] > 0.5 and noise["nighton"] > 1.5 * noise["dayon"]
    assert noise["nightoff"] > noise["nighton"] and level["nightoff"] < 0.75 * level["dayon"]


def test_lights_on_brighten_their_room_at_night_and_not_through_the_wall(world, appearance):
    """With the exposure fixed (a camera in manual mode), a lamp brightens its own room and leaves
    the far side of the wall, seen from the next room with the door shut, exactly as it was."""
    camera = SmartCamera(world, PROFILE.camera, CameraOptions(manual_exposure=4.0))
    appearance.set_knob("sun_angle", "night")
    appearance.set_lights("all", "off")
    appearance.set_door("Door_0", False)
    in_a, in_b = (3.0, 1.5, 0.0), (7.5, 3.3, math.pi)       # B looks west, at the wall it shares with A
    dark_a, dark_b = camera.capture(*in_a), camera.capture(*in_b)
    appearance.set_light("Light_0", True)
    lit_a, lit_b = camera.capture(*in_a), camera.capture(*in_b)
    room_a = np.isin(dark_a.instance, list({i.id for i in world.instances if i.room == "A"}))
    wall_b = dark_b.instance == world.instance("B/walls").id
    assert room_a.mean() > 0.5 and wall_b.mean() > 0.3
    assert _mean(lit_a.rgb, room_a) > 3 * _mean(dark_a.rgb, room_a)
    assert np.array_equal(lit_b.rgb, dark_b.rgb)                      # no light through the wall


def test_paint_changes_wall_pixel_colour(camera, world, appearance):
    walls = world.instance("A/walls").id
    appearance.set_paint("A", "walls", "terracotta")
    warm = camera.capture(2.0, 0.6, 0.0)
    appearance.set_paint("A", "walls", "sky")
    cool = camera.capture(2.0, 0.6, 0.0)
    w = warm.instance == walls
    assert w.mean() > 0.3
    r_warm, _, b_warm = warm.rgb[w].mean(axis=0)
    r_cool, _, b_cool = cool.rgb[w].mean(axis=0)
    assert r_warm > b_warm + 40 and b_cool > r_cool + 20
    assert world.state.paint["A"]["walls"] == "sky"
    with pytest.raises(UserError):
        appearance.set_paint("A", "walls", "plaid")


def test_swapping_an_object_model_changes_its_pixels(camera, world, appearance):
    closet = world.instance("Closet_0").id
    before = camera.capture(6.8, 3.0, 0.0)
    assert appearance.set_object_model("Closet_0", 1) == 1
    after = camera.capture(6.8, 3.0, 0.0)
    both = (before.instance == closet) & (after.instance == closet)
    diff = np.abs(before.rgb.astype(int) - after.rgb.astype(int)).sum(axis=2)
    assert both.mean() > 0.2 and (diff[both] > 20).mean() > 0.05
    assert world.state.models["Closet_0"] == 1
    assert make_footprint(world.house, world.state.settings())["settings"]["models"]["Closet_0"] == 1


def test_model_choices_random_and_inherit(world, appearance):
    picked = appearance.set_object_model("Closet_0", "random", seed=4)
    settings = load_settings()
    settings["models"]["set"] = {"Closet_0": "random"}
    assert picked == resolve(settings, world.house, 4).models["Closet_0"]
    appearance.set_object_model("Light_0", 2)
    assert appearance.set_object_model("Light_1", {"inherit": "Light_0"}) == 2
    with pytest.raises(UserError):
        appearance.set_object_model("Closet_0", 99)


def test_randomise_changes_settings_and_world_together(world, appearance):
    target = appearance.randomise(seed=3)
    again = resolve(load_settings(), world.house, 0)
    assert target == world.state.settings()
    assert target.paint != again.paint or target.models != again.models or target.lights != again.lights
    assert 0.0 <= target.sun_angle <= 240.0
    fp = make_footprint(world.house, world.state.settings())
    assert fp["settings"]["paint"] == target.paint


def test_window_is_an_opening_onto_the_outdoors(world, appearance):
    """The wall is cut where the window is: its glass (labelled with the window) shows a bright
    outdoors by day and a dark one at night, and depth stops at the glass."""
    camera = SmartCamera(world, PROFILE.camera, CameraOptions(manual_exposure=1.0))
    window = world.instance("Wall_0").id
    seen = {}
    for preset in ("day", "night"):
        appearance.set_knob("sun_angle", preset)
        cap = camera.capture(3.0, 2.0, math.pi)
        pane = cap.instance == window
        assert pane.mean() > 0.03
        assert np.isfinite(cap.depth[pane]).all()
        seen[preset] = _mean(cap.rgb, pane)
    assert seen["day"] > 90                                  # a bright outdoors by day
    assert seen["night"] < seen["day"] / 3


# ----------------------------------------------------------------------------- determinism, renderers

def test_same_seed_and_pose_give_identical_images_and_scans(box_house):
    options = CameraOptions(pixel_noise=3.0, depth_noise=0.002)
    laser_spec = replace(PROFILE.laser, noise_sigma=0.01)
    runs = []
    for seed in (5, 5, 6):
        with _world(box_house, seed) as w:
            cam, laser = SmartCamera(w, PROFILE.camera, options, backend="tiny"), Laser(w, laser_spec)
            runs.append([(cam.capture(2.0, 2.0, 0.3), laser.scan(2.0, 2.0, 0.3)) for _ in range(2)])
    (a1, s1), (a2, s2) = runs[0]
    (b1, t1), _ = runs[1]
    (c1, u1), _ = runs[2]
    assert np.array_equal(a1.rgb, b1.rgb) and np.array_equal(a1.depth, b1.depth, equal_nan=True)
    assert np.array_equal(s1.ranges, t1.ranges)
    assert not np.array_equal(a1.rgb, a2.rgb) and not np.array_equal(s1.ranges, s2.ranges)   # new frame
    assert not np.array_equal(a1.rgb, c1.rgb) and not np.array_equal(s1.ranges, u1.ranges)   # new seed


def test_each_agent_has_its_own_noise(box_house):
    """Same seed, pose and frame counter: one agent's sensors repeat exactly, two agents' differ."""
    options = CameraOptions(pixel_noise=3.0, depth_noise=0.002)
    laser_spec = replace(PROFILE.laser, noise_sigma=0.01)
    with _world(box_house, 5) as w:
        reads = [(SmartCamera(w, PROFILE.camera, options, agent, backend="tiny").capture(2.0, 2.0, 0.3),
                  Laser(w, laser_spec, agent).scan(2.0, 2.0, 0.3)) for agent in ("alpha", "beta", "alpha")]
    (a, sa), (b, sb), (a_again, sa_again) = reads
    assert a.index == b.index == a_again.index == 0 and sa.index == sb.index == 0
    assert np.array_equal(a.rgb, a_again.rgb) and np.array_equal(a.depth, a_again.depth, equal_nan=True)
    assert np.array_equal(sa.ranges, sa_again.ranges)
    assert not np.array_equal(a.rgb, b.rgb) and not np.array_equal(a.depth, b.depth, equal_nan=True)
    assert not np.array_equal(sa.ranges, sb.ranges)


def test_tiny_renderer_fallback_sees_the_same_geometry(box_house, camera):
    """The fallback looks plainer (no shadows, no materials) but sees the same scene from the same K."""
    pose = (3.0, 1.5, 0.3)
    gl = camera.capture(*pose)
    with _world(box_house) as w:
        tiny_camera = SmartCamera(w, PROFILE.camera, backend="tiny")
        assert tiny_camera.backend == "tiny"
        tiny = tiny_camera.capture(*pose)
    assert (gl.instance == tiny.instance).mean() > 0.99
    both = np.isfinite(gl.depth) & np.isfinite(tiny.depth)
    assert np.median(np.abs(gl.depth[both] - tiny.depth[both])) < 0.01
    assert tiny.rgb.std() > 10 and gl.rgb.std() > 10


# ----------------------------------------------------------------------------- optics

def test_distortion_moves_pixels_as_cv2_projects_them(world, camera):
    coefficients = (-0.25, 0.08, 0.001, -0.001, 0.0)
    bent = SmartCamera(world, PROFILE.camera, CameraOptions(distortion=coefficients))
    assert bent.camera_info.D == coefficients
    x, y, yaw = 2.0, 3.0, 0.0
    cap = bent.capture(x, y, yaw)
    position, rotation = bent.optical_pose(x, y, yaw)
    point = np.array([6.0, 3.3, 0.0])                 # floor meets the east wall
    cam_point = (point - position) @ rotation
    zero = np.zeros(3)
    projected, _ = cv2.projectPoints(cam_point[None], zero, zero, bent.K, np.array(coefficients))
    u, v = projected[0, 0]
    col = cap.instance[:, int(round(u))]
    walls, floors = world.instance("A/walls").id, world.instance("A/floor").id
    boundary = np.flatnonzero((col[:-1] == walls) & (col[1:] == floors))
    assert len(boundary) == 1 and abs(boundary[0] + 0.5 - v) <= 1.5
    straight = camera.capture(x, y, yaw)
    assert not np.array_equal(straight.instance, cap.instance)


def test_motion_blur_follows_turning_speed(world):
    blurry = SmartCamera(world, PROFILE.camera, CameraOptions(motion_blur=True, exposure=0.03))
    still = blurry.capture(3.0, 2.0, math.pi, velocity=(0.0, 0.0))
    turning = blurry.capture(3.0, 2.0, math.pi, velocity=(0.0, 1.0))     # ~16 px sweep

    def energy(img, axis):
        return float((np.diff(cv2.cvtColor(img, cv2.COLOR_RGB2GRAY).astype(float), axis=axis) ** 2).mean())
    assert energy(turning.rgb, 1) < 0.5 * energy(still.rgb, 1)            # sideways detail smeared
    assert energy(turning.rgb, 0) > 0.5 * energy(still.rgb, 0)            # vertical detail mostly kept


def test_jpeg_helpers(camera):
    rgb = camera.capture(3.0, 2.0, math.pi).rgb
    data = encode_jpeg(rgb, 80)
    assert data[:2] == b"\xff\xd8" and len(data) < rgb.nbytes / 5
    back = jpeg_roundtrip(rgb, 80)
    assert back.shape == rgb.shape and 0 < np.abs(back.astype(int) - rgb).mean() < 5


# ----------------------------------------------------------------------------- CLI

def test_render_command_writes_images_and_info(tmp_path, capsys):
    out = tmp_path / "view"
    assert main(["render", "15", "--pose", "8.41", "-4.75", "1.5708", "--sun", "night", "--lights", "on",
                 "--renderer", "tiny", "-o", str(out)]) == 0
    depth = cv2.imread(str(out / "depth.png"), cv2.IMREAD_UNCHANGED)
    assert depth.dtype == np.uint16 and depth.shape == (480, 640) and 300 < np.median(depth) < 20000
    mask = cv2.imread(str(out / "mask.png"))
    info = json.loads((out / "info.json").read_text())
    assert info["K"][0][0] == pytest.approx(548.571, abs=1e-3) and info["sun_angle"] == 200.0
    assert sum(i["pixels"] for i in info["instances"]) + info["pixels_without_instance"] == 640 * 480
    top = info["instances"][0]
    assert (mask[:, :, ::-1].reshape(-1, 3) == top["mask_color"]).all(axis=1).sum() == top["pixels"]
    assert main(["render", "15", "--pose", "0", "0", "0", "--sun", "noon", "-o", str(out)]) == 2
    assert "sun_angle: expected degrees in [0, 360] or one of day, sunset, night, random, got 'noon'" \
        in capsys.readouterr().err
