"""The obstacle map (/map): uninflated, the house cut at the laser's height, where the laser really ends."""
from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from conftest import resolved

from ravh_msgs_py import names
from ravh_sim.nav.grid import FREE, OCCUPIED, UNKNOWN, Grid
from ravh_sim.nav.navigation import Navigation
from ravh_sim.nav.obstaclemap import UNSEEN_TYPES, _draw_section, obstacle_map
from ravh_sim.robot.profile import load_profile
from ravh_sim.world.solids import _convex_hull, object_parts
from ravh_sim.world.state import WorldState


def shoelace(polygon) -> float:
    return abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(polygon, [*polygon[1:], polygon[0]]))) / 2


def blocking_area(house, settings, laser_z: float) -> float:
    """Footprint area (box size products, overlaps counted twice) of what the laser plane cuts, and of
    the walls: computed from the house model, not from any raster."""
    area = sum(w.length * w.thickness for w in house.walls)
    for obj in house.objects:
        if obj.type in ("Door", "Wall", "Light", "Station"):
            continue
        box, floor_z = obj.box(settings.models.get(obj.id)), house.room(obj.room).floor_z
        bottom, top = box.position[2] - box.size[2] / 2, box.position[2] + box.size[2] / 2
        if bottom <= floor_z + laser_z <= top:
            area += box.size[0] * box.size[1]
    return area


@pytest.mark.parametrize("number", [15, 20, 23])
def test_free_area_is_the_floor_less_what_stands_on_it(houses, number):
    house = houses[number]
    settings = resolved(house)
    profile = load_profile("giraff")
    nav = Navigation(house, WorldState(settings), profile)
    grid = nav.obstacle_map()
    cell = grid.resolution ** 2
    free = (grid.data == FREE).sum() * cell
    floor = sum(shoelace(room.floor) + sum(shoelace(p) for p in room.extra_floors) for room in house.rooms)
    assert set(np.unique(grid.data)) == {FREE, OCCUPIED, UNKNOWN}
    assert free <= floor + 1.0
    assert free >= 0.8 * (floor - blocking_area(house, settings, profile.laser.height))
    assert free > 1.5 * (nav.map().data == FREE).sum() * cell          # the inflated free space is far smaller


def test_obstacle_map_is_not_inflated(houses):
    """Right next to a wall the obstacle map is free; the robot's free space keeps its radius off it."""
    house = houses[20]
    nav = Navigation(house, WorldState(resolved(house)), load_profile("giraff"))
    obstacles, free_space = nav.obstacle_map(), nav.map()
    occupied = (obstacles.data == OCCUPIED).astype(np.uint8)
    ring = (cv2.dilate(occupied, np.ones((3, 3), np.uint8)) > 0) & (obstacles.data == FREE)
    assert ring.sum() > 100
    assert (free_space.data[ring] == OCCUPIED).all()


def scan_endpoints(rt, agent) -> tuple[np.ndarray, np.ndarray]:
    """(n, 2) map-frame points of the finite ranges of a scan taken now, and the body each one hit: each
    range along its beam in laser_link, then laser_link -> base_link -> odom -> map as /tf has them
    (``SimRuntime.to_map``: the mounts published on /tf_static, odometry, the ground-truth map -> odom)."""
    scan = rt.scan(agent)
    origin = np.array(rt.to_map(names.LASER_FRAME, 0.0, 0.0))
    x_axis = np.array(rt.to_map(names.LASER_FRAME, 1.0, 0.0)) - origin       # the laser frame is level
    y_axis = np.array(rt.to_map(names.LASER_FRAME, 0.0, 1.0)) - origin
    ranges = np.asarray(scan.ranges, np.float64)
    angles = scan.angle_min + scan.angle_increment * np.arange(len(ranges))
    ok = np.isfinite(ranges)
    return (origin + np.outer(ranges[ok] * np.cos(angles[ok]), x_axis)
            + np.outer(ranges[ok] * np.sin(angles[ok]), y_axis)), scan.hit_bodies[ok]


def segment_distance(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Distance of each of (n, 2) points to the nearest of (m, 2, 2) segments."""
    a, b = segments[None, :, 0], segments[None, :, 1]
    ab, ap = b - a, points[:, None] - a
    t = np.clip((ap * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-18), 0.0, 1.0)
    return np.linalg.norm(ap - t[..., None] * ab, axis=-1).min(axis=1)


@pytest.mark.parametrize("number", [15, 20])
def test_laser_endpoints_land_on_the_map_edges(number):
    """What a SLAM builds from the sim's own scans: from 120 random free poses (random headings), >= 95 %
    of the finite endpoints, put in map through the transforms /tf publishes, lie on an occupied cell or
    next to one, and < 1 % lie deep inside an occupied area (no free or unknown cell around them): the
    map draws what the laser hits (legs, slats), not boxes around it (those held 4-9 % of endpoints).
    Each endpoint on a piece of furniture or a door lies on that object's cut at laser height."""
    from ravh_sim.runtime import SimRuntime
    rt = SimRuntime(number, None, 0, renderer="tiny")
    try:
        grid, agent = rt.navigation.obstacle_map(), rt.agents[0]
        occupied = (grid.data == OCCUPIED).astype(np.uint8)
        near = cv2.dilate(occupied, np.ones((3, 3), np.uint8)) > 0
        deep = cv2.erode(occupied, np.ones((3, 3), np.uint8), borderValue=0) > 0
        objects = {inst.body: inst.name for inst in rt.world.instances if inst.kind in ("object", "door", "window")}
        free = np.argwhere(rt.navigation.map().data == FREE)
        rng = np.random.default_rng(number)
        found, off_cut, cuts = [], [], {}
        for r, c in free[rng.choice(len(free), 120, replace=False)]:
            agent.robot.teleport(*rt.navigation.map().center_of(int(r), int(c)), float(rng.uniform(-math.pi, math.pi)))
            points, bodies = scan_endpoints(rt, agent)
            cells = np.floor((points - np.asarray(grid.origin)) / grid.resolution).astype(int)
            found.append(np.column_stack([near[cells[:, 1], cells[:, 0]], deep[cells[:, 1], cells[:, 0]]]))
            for body in set(bodies.tolist()) & set(objects):
                obj = rt.house.object(objects[body])
                if obj.id not in cuts:
                    cuts[obj.id] = object_parts(rt.house, obj, rt.world.state.models[obj.id]).section(
                        rt.house.room(obj.room).floor_z + agent.profile.laser.height)
                off_cut.append(segment_distance(points[bodies == body], cuts[obj.id]))
        on = np.concatenate(found)
        assert len(on) > 30000
        assert on[:, 0].mean() >= 0.95, f"{on[:, 0].mean():.3f} of the endpoints within one cell of an occupied one"
        assert on[:, 1].mean() < 0.01, f"{on[:, 1].mean():.3f} of the endpoints deep inside occupied cells"
        off = np.concatenate(off_cut)
        assert len(off) > 3000 and off.max() < 0.005         # pybullet's collision margin: ~2 mm on convex parts
    finally:
        rt.close()


def test_the_map_is_the_cut_at_laser_height(houses):
    """Objects wholly below the laser plane are free on /map but blocked in the robot's free space; an
    object the plane cuts is on /map only where its parts are (between a chair's legs is free). Houses 15
    (its chairs) and 7 (a pouf 20 cm high)."""
    below = cut = 0
    for number in (15, 7):
        house = houses[number]
        settings = resolved(house)
        nav = Navigation(house, WorldState(settings), load_profile("giraff"))
        grid, free_space, height = nav.obstacle_map(), nav.map(), nav.profile.laser.height
        for obj in house.objects:
            if obj.type in ("Door", "Wall", "Light", "Station"):
                continue
            placed = object_parts(house, obj, settings.models.get(obj.id))
            (x, y), floor = placed.position[:2], house.room(obj.room).floor_z
            top = placed.position[2] + placed.extent()[1][2]
            if top < floor + height - 0.01:
                assert grid.data[grid.cell_of(x, y)] == FREE
                assert free_space.data[free_space.cell_of(x, y)] == OCCUPIED
                below += 1
            elif obj.type == "Chair" and number == 15:     # house 7's stand under a table that covers them
                mask = np.zeros(grid.shape, np.uint8)
                _draw_section(mask, placed.section(floor + height), grid)
                r, c = grid.cell_of(x, y)
                if not mask[r, c]:
                    assert grid.data[r, c] == FREE          # the middle of a chair, between its legs
                    cut += 1
    assert below >= 1 and cut >= 1


def test_a_closed_cut_is_solid_an_open_one_is_not():
    """A cabinet's outline encloses occupied cells; a U-shaped shelf open at the front stays open."""
    grid = Grid(np.zeros((40, 40), np.int8), (0.0, 0.0), 0.05)
    square = np.array([[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]])
    closed = np.stack([square, np.roll(square, -1, axis=0)], axis=1)
    mask = np.zeros(grid.shape, np.uint8)
    _draw_section(mask, closed, grid)
    assert mask[grid.cell_of(1.0, 1.0)] and mask[15:25, 15:25].all() and not mask[grid.cell_of(1.7, 1.0)]
    mask[:] = 0
    _draw_section(mask, closed[:3], grid)                  # no side from (0.5, 1.5) to (0.5, 0.5)
    assert not mask[grid.cell_of(1.0, 1.0)] and mask[grid.cell_of(1.5, 1.0)]


def test_a_convex_part_is_cut_to_its_outline(houses):
    """A procedural part's cut is its convex hull's cross-section: a box gives its rectangle."""
    hull = _convex_hull(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5], [0.5, 0.0]]))
    assert sorted(map(tuple, hull.tolist())) == [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)]
    house = houses[20]
    door = house.doors[0]
    placed = object_parts(house, house.object(door.id), None)
    cut = placed.section(placed.position[2])                # the closed leaf and its jambs, at mid height
    assert len(cut) >= 4
    ends = cut.reshape(-1, 2)
    assert np.max(np.linalg.norm(ends - np.asarray(door.position[:2]), axis=1)) <= math.hypot(door.width, 0.2)
    assert not len(placed.section(placed.position[2] + 10.0))


def test_unseen_types_are_what_the_world_does_not_collide_with():
    from ravh_sim.world.scene import NON_SOLID_TYPES
    assert UNSEEN_TYPES == NON_SOLID_TYPES


def test_an_open_door_leaves_the_map(houses):
    house = houses[20]
    settings = resolved(house)
    door = house.doors[0]
    args = (settings.models, load_profile("giraff").laser.height, 0.05)
    closed = obstacle_map(house, {door.id: False}, *args)
    opened = obstacle_map(house, {door.id: True}, *args)
    assert closed.data[closed.cell_of(*door.position[:2])] == OCCUPIED
    assert opened.data[opened.cell_of(*door.position[:2])] == FREE
