"""Where behaviours go: the Wanderer's light waypoints and the Grid's lattice nodes.

The paper's Wanderer visits every room through the floor projections of its ceiling lights (lights
hang over the open middle of a room); a projection that lands on furniture is moved to the nearest
free cell of the same room. The Grid behaviour visits lattice nodes every ``spacing`` metres, room
by room, in a back-and-forth sweep so consecutive nodes are neighbours. Two node rules:

- :func:`paper_grid_nodes` (the paper's presets): the original project walks a lattice every 0.5 m
  of the house frame and keeps every point Unity's ``NavMeshAgent.CalculatePath`` finds a path to on
  a walkable mesh baked for a 0.1 m agent, with its exact-route check off: points near but off the
  mesh are kept and the robot stops at the nearest spot it can reach. Here: a point is kept when it
  lies within ``near`` (0.1 m) of the area a 0.1 m disc reaches from the start; the robot, wider,
  stops at the nearest cell of its own free space reachable from the start. Over the 30 houses this
  gives 0.92-1.26x the paper's grid captures, median 1.07 (``ravh dataset build`` prints the ratio).
- :func:`grid_nodes` (``cover``): lattice cells on the robot's own free space, plus fill-ins so every
  reachable cell is within ``spacing`` of a node: fewer nodes (0.66x the paper's), none unreachable.
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
NODE_RULES = ("paper", "cover")      # the Grid's node rules (module docstring)


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
    return _room_tour(grid, by_room, start)


PAPER_AGENT_RADIUS = 0.1         # m: the radius the original's walkable mesh was baked for
PAPER_NEAR = 0.1                 # m: how far off that mesh a kept lattice point may lie


def paper_lattice(walkable: Grid, start: Point, spacing: float = 0.5, near: float = PAPER_NEAR) -> list[Point]:
    """The lattice points (multiples of ``spacing`` in the house frame) within ``near`` of the part of
    ``walkable`` (free space inflated by the paper's agent radius) connected to ``start``."""
    reach = reachable(walkable, start)
    off = cv2.distanceTransform((~reach).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * walkable.resolution
    (ox, oy), res = walkable.origin, walkable.resolution
    xs = np.arange(math.ceil(ox / spacing), math.floor((ox + walkable.shape[1] * res) / spacing) + 1) * spacing
    ys = np.arange(math.ceil(oy / spacing), math.floor((oy + walkable.shape[0] * res) / spacing) + 1) * spacing
    gx, gy = np.meshgrid(xs, ys)
    rows = np.floor((gy - oy) / res + 1e-9).astype(int)
    cols = np.floor((gx - ox) / res + 1e-9).astype(int)
    inside = (rows < walkable.shape[0]) & (cols < walkable.shape[1])
    keep = np.zeros(gx.shape, bool)
    keep[inside] = off[rows[inside], cols[inside]] <= near + 1e-6
    return list(zip(gx[keep].tolist(), gy[keep].tolist()))


def nearest_reachable_cells(grid: Grid, start: Point, points: list[Point]) -> list[tuple[int, int]]:
    """Per point, the cell of ``grid`` reachable from ``start`` nearest to it: where a robot sent
    there stops."""
    reach = reachable(grid, start)
    cells = np.argwhere(reach)
    if not len(cells):
        raise ValueError("no free cell reachable from the start")
    _, labels = cv2.distanceTransformWithLabels((~reach).astype(np.uint8), cv2.DIST_L2, 5,
                                                labelType=cv2.DIST_LABEL_PIXEL)
    # labels number the zero (reachable) pixels in row-major order, from 1
    out = []
    for x, y in points:
        r, c = grid.cell_of(x, y)
        r, c = min(max(r, 0), grid.shape[0] - 1), min(max(c, 0), grid.shape[1] - 1)
        cr, cc = cells[labels[r, c] - 1]
        out.append((int(cr), int(cc)))
    return out


def paper_grid_nodes(layout: Layout, walkable: Grid, grid: Grid, start: Point, spacing: float = 0.5,
                     near: float = PAPER_NEAR) -> list[Point]:
    """The paper's node rule (module docstring): one node per kept lattice point, at the spot of the
    robot's free space ``grid`` it stops at, toured room by room like :func:`grid_nodes`. Lattice
    points whose stop is the same cell stay separate nodes (the original captures at each)."""
    stops = nearest_reachable_cells(grid, start, paper_lattice(walkable, start, spacing, near))
    masks = room_masks(layout, grid)
    by_room: dict[str, list[tuple[int, int]]] = {}
    for r, c in stops:
        room = next((room_id for room_id, mask in masks.items() if mask[r, c]), "")
        by_room.setdefault(room, []).append((r, c))
    return _room_tour(grid, by_room, start)


def _room_tour(grid: Grid, by_room: dict[str, list[tuple[int, int]]], start: Point) -> list[Point]:
    """Rooms nearest first, each toured nearest node first."""
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
