"""Where behaviours go: the Wanderer's light waypoints and the Grid's lattice nodes.

The paper's Wanderer visits every room through the floor projections of its ceiling lights (lights
hang over the open middle of a room); a projection that lands on furniture is moved to the nearest
free cell of the same room. The Grid behaviour visits lattice nodes every ``spacing`` metres over
the free area, room by room, in a back-and-forth sweep so consecutive nodes are neighbours.
"""
from __future__ import annotations

import math
import random
from dataclasses import dataclass

import cv2
import numpy as np

from ravh_sim.nav.grid import Grid, reachable
from ravh_sim.world.geometry import Polygon
from ravh_sim.world.house import House

Point = tuple[float, float]
ORDERS = ("cyclic", "once", "random")


def nearest_free_cell(grid: Grid, xy: Point, mask: np.ndarray) -> tuple[int, int]:
    rows, cols = np.nonzero(mask)
    if len(rows) == 0:
        raise ValueError("no free cell in the map")
    r0, c0 = grid.cell_of(*xy)
    k = int(np.argmin((rows - r0) ** 2 + (cols - c0) ** 2))
    return int(rows[k]), int(cols[k])


@dataclass(frozen=True)
class Layout:
    """What behaviours need of a house: room floors and ceiling-light positions. Built from a House
    here, or from ground-truth queries by the behaviour nodes (which only talk to the sim node)."""
    rooms: dict[str, tuple[Polygon, ...]]          # room id -> floor polygons, in house order
    ceiling_lights: tuple[tuple[str, Point], ...]  # (room id, (x, y))

    @classmethod
    def of(cls, house: House) -> Layout:
        return cls({r.id: (r.floor, *r.extra_floors) for r in house.rooms},
                   tuple((lt.room, lt.position[:2]) for lt in house.lights if lt.kind == "ceiling"))


def room_masks(layout: Layout, grid: Grid) -> dict[str, np.ndarray]:
    """Per room, the grid cells whose centres lie on its floor."""
    return {room_id: grid.polygons_mask(polygons) for room_id, polygons in layout.rooms.items()}


def light_waypoints(layout: Layout, grid: Grid, start: Point) -> dict[str, list[Point]]:
    """Per room (house order), waypoints under its ceiling lights snapped into reachable free space;
    a room without a reachable light gets its most open reachable point. Unreachable rooms are left out."""
    reach = reachable(grid, start)
    clearance = cv2.distanceTransform(reach.astype(np.uint8), cv2.DIST_L2, 5)
    out: dict[str, list[Point]] = {}
    for room_id, mask in room_masks(layout, grid).items():
        usable = mask & reach
        if not usable.any():
            continue
        points = []
        for light_room, xy in layout.ceiling_lights:
            if light_room == room_id:
                r, c = nearest_free_cell(grid, xy, usable)
                points.append(grid.center_of(r, c))
        if not points:
            row, col = np.unravel_index(int(np.argmax(np.where(usable, clearance, -1))), grid.shape)
            points.append(grid.center_of(int(row), int(col)))
        out[room_id] = _dedupe(points, grid.resolution * 4)
    return out


def room_order(rooms: list[str], mode: str, rng: random.Random) -> list[str]:
    """The order rooms are visited in one round: as listed (cyclic/once) or shuffled (random)."""
    if mode not in ORDERS:
        raise ValueError(f"order must be one of {ORDERS}, got {mode!r}")
    order = list(rooms)
    if mode == "random":
        rng.shuffle(order)
    return order


def grid_nodes(layout: Layout, grid: Grid, start: Point, spacing: float = 0.5) -> list[Point]:
    """Lattice nodes every ``spacing`` m on reachable free cells, room by room (nearest room next),
    each room toured nearest node first. Free strips the lattice misses (a narrow corridor between
    lattice rows) get extra nodes until every reachable cell is within ``spacing`` of a node of its room."""
    reach = reachable(grid, start)
    step = max(1, int(round(spacing / grid.resolution)))
    lattice = np.zeros(grid.shape, bool)
    lattice[step // 2::step, step // 2::step] = True
    by_room: dict[str, list[tuple[int, int]]] = {}
    for room_id, mask in room_masks(layout, grid).items():
        area = mask & reach
        if area.any():
            by_room[room_id] = _cover(area, lattice & area, step)
    nodes: list[Point] = []
    here = start
    remaining = dict(by_room)
    while remaining:
        room_id = min(remaining, key=lambda rid: _distance_to_cells(grid, here, remaining[rid]))
        pts = _tour([grid.center_of(r, c) for r, c in remaining.pop(room_id)], here)
        nodes += pts
        here = pts[-1]
    return nodes


def _cover(area: np.ndarray, seeds: np.ndarray, step: int) -> list[tuple[int, int]]:
    """``seeds`` plus farthest-point additions until every cell of ``area`` is within ``step`` cells."""
    nodes = seeds.copy()
    while True:
        if nodes.any():
            far = cv2.distanceTransform((~nodes).astype(np.uint8), cv2.DIST_L2, 5)
        else:
            far = np.full(area.shape, np.inf, np.float32)
        far[~area] = 0
        r, c = np.unravel_index(int(np.argmax(far)), far.shape)
        if far[r, c] <= step:
            break
        nodes[r, c] = True
    rows, cols = np.nonzero(nodes)
    return list(zip(rows.tolist(), cols.tolist()))


def _tour(points: list[Point], start: Point) -> list[Point]:
    """Greedy nearest-neighbour order from ``start``: on a lattice it walks neighbour to neighbour."""
    left = np.array(points)
    order: list[Point] = []
    here = np.array(start)
    while len(left):
        k = int(np.argmin(np.sum((left - here) ** 2, axis=1)))
        here = left[k]
        order.append((float(here[0]), float(here[1])))
        left = np.delete(left, k, axis=0)
    return order


def _distance_to_cells(grid: Grid, xy: Point, cells: list[tuple[int, int]]) -> float:
    return min(math.dist(xy, grid.center_of(r, c)) for r, c in cells)


def _dedupe(points: list[Point], min_gap: float) -> list[Point]:
    out: list[Point] = []
    for p in points:
        if all(math.dist(p, q) >= min_gap for q in out):
            out.append(p)
    return out
