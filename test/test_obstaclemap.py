"""The obstacle map (/map): uninflated, at laser height, where the laser really ends."""
from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from conftest import resolved

from ravh_sim.nav.grid import FREE, OCCUPIED, UNKNOWN
from ravh_sim.nav.navigation import Navigation
from ravh_sim.nav.obstaclemap import LASER_PLANE_MARGIN
from ravh_sim.robot.profile import load_profile
from ravh_sim.world.state import WorldState


def shoelace(polygon) -> float:
    return abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(polygon, [*polygon[1:], polygon[0]]))) / 2


def blocking_area(house, settings, laser_top: float) -> float:
    """Footprint area (box size products, overlaps counted twice) of what reaches up to the laser plane,
    and of the walls: computed from the house model, not from any raster."""
    area = sum(w.length * w.thickness for w in house.walls)
    for obj in house.objects:
        if obj.type in ("Door", "Wall", "Light", "Station"):
            continue
        box, floor_z = obj.box(settings.models.get(obj.id)), house.room(obj.room).floor_z
        bottom, top = box.position[2] - box.size[2] / 2, box.position[2] + box.size[2] / 2
        if top > floor_z + 0.02 and bottom < floor_z + laser_top:
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
    assert free >= 0.8 * (floor - blocking_area(house, settings, profile.laser.height + LASER_PLANE_MARGIN))
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


def test_laser_endpoints_land_on_occupied_cells(houses):
    """>= 90 % of the endpoints of real ray casts lie within one cell of an occupied cell."""
    from ravh_sim.runtime import SimRuntime
    rt = SimRuntime(15, None, 0, renderer="tiny")
    try:
        grid = rt.navigation.obstacle_map()
        near = cv2.dilate((grid.data == OCCUPIED).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
        free = np.argwhere(rt.navigation.map().data == FREE)
        agent = rt.agents[0]
        hits, total = 0, 0
        for r, c in free[np.random.default_rng(0).choice(len(free), 8, replace=False)]:
            x, y = rt.navigation.map().center_of(int(r), int(c))
            agent.robot.teleport(x, y, 0.0)
            scan = rt.scan(agent)
            for i, d in enumerate(scan.ranges):
                if math.isfinite(d):
                    angle = scan.angle_min + i * scan.angle_increment
                    hits += near[grid.cell_of(x + d * math.cos(angle), y + d * math.sin(angle))]
                    total += 1
        assert total > 1000 and hits / total >= 0.9
    finally:
        rt.close()

