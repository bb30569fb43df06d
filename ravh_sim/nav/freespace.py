"""The Navigation Manager's free-area map: where the robot's centre may go in a house.

The map is computed from the house model, not sensed, so navigation works from the first tick and
agrees with the pybullet world by construction. Three steps, each its own function:

1. :func:`obstacles` rasterises the house at one robot height: the union of the room floors (plus
   open doorways) is the known area, everything else is UNKNOWN; wall pieces as the world builds
   them (:func:`ravh_sim.world.structure.solid_walls`), columns, closed door
   leaves and the furniture parts that the robot's body would hit (legs, seats, a table top below
   the robot's height: :mod:`ravh_sim.world.solids`, the parts the world collides with) are
   OCCUPIED; the rest is FREE. A part is its box (``Placed.footprints``: a library model's largest
   pieces), so this map is conservative: it blocks the floor under a chair's seat, between its legs.
2. :func:`inflate` grows every non-free cell by the robot radius (a disc), so a FREE cell is a
   position where the whole robot disc fits: the planner can then treat the robot as a point.
3. :func:`free_space` chains the two; :func:`ravh_sim.nav.grid.distance_to_obstacle` gives the
   clearance the planner uses to keep paths away from walls where there is room.

Rasterisation uses cv2 polygon filling on sub-pixel coordinates: a few hundred shapes per house take
milliseconds. An obstacle covers the cells whose centre lies inside it (see :func:`fill_box`: house
coordinates sit on cell edges, and cv2's own rounding would narrow every 0.8 m corridor by a cell),
and a shape thinner than a cell still covers a line of cells, so no wall is lost at any resolution.

Why the union of floors: neighbouring floor polygons meet under each doorway (each reaches half
way through the threshold), so the known area is connected exactly where the walls have gaps;
open doors' frame boxes are added to the known area as well, so a doorway never depends on floor
outlines meeting to the last centimetre.

This is not /map: the obstacle map a ROS user's AMCL or SLAM sees (:mod:`ravh_sim.nav.obstaclemap`)
is the house cut at the laser's height, what the laser hits, on the same grid (:func:`floor_grid`).
"""
from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence

import cv2
import numpy as np

from ravh_sim.errors import UnknownNameError
from ravh_sim.nav.grid import FREE, OCCUPIED, UNKNOWN, Grid, distance_cells
from ravh_sim.world.dressing import Dressed
from ravh_sim.world.geometry import box_corners
from ravh_sim.world.house import Door, House, Wall
from ravh_sim.world.solids import Footprint, object_parts
from ravh_sim.world.structure import solid_walls

NON_OBSTACLE_TYPES = frozenset({"Door", "Wall", "Light", "Station"})
"""Object types that never block: doors (handled through ``house.doors``), windows (inside the
walls), ceiling lights and the robot's own charging station."""

MIN_OBSTACLE_TOP = 0.02
"""Parts whose top is at most this high above the floor (rugs, thresholds) do not block."""

MIN_DOOR_THICKNESS = 0.1
SHIFT = 8                                   # cv2 fixed-point fraction bits (see :func:`pixels`)
SCALE = 1 << SHIFT


def free_space(house: House, door_open: Mapping[str, bool], models: Mapping[str, int] | None = None,
               radius: float = 0.25, height: float = 1.6, resolution: float = 0.05,
               margin: float = 0.5, dressed: Sequence[Dressed] = ()) -> Grid:
    """Cells where a robot disc of ``radius`` and ``height`` fits: FREE, OCCUPIED or UNKNOWN.

    ``door_open`` maps door ids to open (True) or closed; doors it omits keep their default state.
    ``models`` maps object ids to the model variant shown in the world: pass the resolved settings'
    ``models`` (inheritance already followed) to match the world; objects it omits use their
    default model. ``dressed``: the dressing shown (:func:`ravh_sim.world.dressing.dressing`); those
    that collide block like furniture.
    """
    return inflate(obstacles(house, door_open, models, height, resolution, margin, dressed), radius)


def obstacles(house: House, door_open: Mapping[str, bool], models: Mapping[str, int] | None = None,
              height: float = 1.6, resolution: float = 0.05, margin: float = 0.5,
              dressed: Sequence[Dressed] = ()) -> Grid:
    """The uninflated map: known floor FREE, obstacles at robot height OCCUPIED, outside UNKNOWN.

    The grid covers ``house.bounds`` plus ``margin`` on every side, aligned to ``resolution``.
    """
    open_state, models, grid = map_start(house, door_open, models, resolution, margin, height=height)
    blocked = np.zeros(grid.shape, np.uint8)
    for box in _obstacle_boxes(house, open_state, models, height, resolution, dressed):
        fill_box(blocked, box, grid)
    grid.data[blocked > 0] = OCCUPIED
    return grid


def map_start(house: House, door_open: Mapping[str, bool], models: Mapping[str, int] | None, resolution: float,
              margin: float, **heights: float) -> tuple[dict[str, bool], Mapping[str, int], Grid]:
    """What every map of a house starts from: its arguments checked (``heights`` by name, each > 0), the
    doors' states, the models, and the known floor (:func:`floor_grid`)."""
    if resolution <= 0 or margin < 0 or any(h <= 0 for h in heights.values()):
        named = ", ".join(f"{k} > 0" for k in heights)
        raise ValueError(f"need resolution > 0, {named}, margin >= 0; got {resolution}, "
                         f"{', '.join(map(str, heights.values()))}, {margin}")
    open_state = door_states(house, door_open)
    return open_state, checked_models(house, models or {}), floor_grid(house, open_state, resolution, margin)


def floor_grid(house: House, open_state: Mapping[str, bool], resolution: float, margin: float) -> Grid:
    """The known floor FREE (the union of the room floors and of open doorways), the rest UNKNOWN, on a
    grid over ``house.bounds`` plus ``margin`` aligned to ``resolution``; ``open_state`` as
    :func:`door_states` gives it."""
    grid = _empty_grid(house, resolution, margin)
    known = np.zeros(grid.shape, np.uint8)
    for room in house.rooms:
        for poly in (room.floor, *room.extra_floors):
            _fill_polygon(known, poly, grid)
    for door in house.doors:
        if open_state[door.id]:
            fill_box(known, _door_box(door), grid)
    grid.data[known > 0] = FREE
    return grid


def inflate(grid: Grid, radius: float) -> Grid:
    """A copy of ``grid`` where FREE cells whose centre lies within ``radius`` of any non-FREE cell
    (OCCUPIED or UNKNOWN: the robot must not leave the house either) are OCCUPIED. Distances are
    taken to the obstacle cell's near edge (centre distance minus half a cell), so a robot centred on
    a free cell clears the obstacle's area, not just its centre."""
    if radius < 0:
        raise ValueError(f"radius must be >= 0, got {radius}")
    data = grid.data.copy()
    within = distance_cells(grid.data) - 0.5 <= radius / grid.resolution + 1e-6
    data[(data == FREE) & within] = OCCUPIED
    return Grid(data, grid.origin, grid.resolution)


# --------------------------------------------------------------------------- shapes

Box = Footprint
"""A yawed rectangle on the floor: centre (x, y), size (along yaw, across), yaw."""


def _obstacle_boxes(house: House, open_state: Mapping[str, bool], models: Mapping[str, int],
                    height: float, resolution: float = 0.0, dressed: Sequence[Dressed] = ()) -> Iterator[Box]:
    """Footprints of everything that blocks a robot of ``height``; object parts thinner than
    ``resolution`` grow to it inside their object (see ``Placed.footprints``)."""
    floor_z = {room.id: room.floor_z for room in house.rooms}
    for wall in (w for room in house.rooms for w in solid_walls(house, room.id)):
        base = floor_z[wall.room]
        if wall.z0 < base + height and wall.z1 > base:
            yield wall_box(wall)
    for door in house.doors:
        if not open_state[door.id]:
            yield _door_box(door)
    for obj in house.objects:
        if obj.type not in NON_OBSTACLE_TYPES:
            base = floor_z[obj.room]
            placed = object_parts(house, obj, models.get(obj.id))
            yield from placed.footprints(base + MIN_OBSTACLE_TOP, base + height, resolution)
    for item in dressed:
        if item.slot.collides:
            base = floor_z[item.slot.room]
            yield from item.placed().footprints(base + MIN_OBSTACLE_TOP, base + height, resolution)


def wall_box(wall: Wall) -> Box:
    (ax, ay), (bx, by) = wall.a, wall.b
    return ((ax + bx) / 2, (ay + by) / 2), (wall.length, wall.thickness), math.atan2(by - ay, bx - ax)


def _door_box(door: Door) -> Box:
    """The doorway rectangle: the frame's width along ``yaw``, at least the leaf's thickness deep."""
    return door.position[:2], (door.width, max(door.leaf[1], MIN_DOOR_THICKNESS)), door.yaw


# --------------------------------------------------------------------------- raster

def _empty_grid(house: House, resolution: float, margin: float) -> Grid:
    xmin, ymin, xmax, ymax = house.bounds
    ox = math.floor((xmin - margin) / resolution) * resolution
    oy = math.floor((ymin - margin) / resolution) * resolution
    cols = math.ceil((xmax + margin - ox) / resolution)
    rows = math.ceil((ymax + margin - oy) / resolution)
    return Grid(np.full((rows, cols), UNKNOWN, np.int8), (ox, oy), resolution)


def _fill_polygon(mask: np.ndarray, outline: Sequence[tuple[float, float]], grid: Grid) -> None:
    """Set to 1 every cell of ``mask`` that the polygon ``outline`` (metres) touches."""
    cv2.fillPoly(mask, [pixels(np.asarray(outline), grid)], 1, lineType=cv2.LINE_8, shift=SHIFT)


def fill_box(mask: np.ndarray, box: Box, grid: Grid) -> None:
    """Set to 1 the cells of ``mask`` whose centre lies in ``box``; a box thinner than a cell is
    drawn as a line one cell wide, so no wall is ever lost between cell centres.

    cv2 fills from the cell nearest one edge to the cell nearest the other, which makes a shape half
    a cell wider on each side than the set of cell centres inside it; shrinking the box by half a
    cell per side first removes that bias (which would otherwise narrow every passage by a cell).
    """
    center, (length, width), yaw = box
    shrunk = (max(length - grid.resolution, 0.0), max(width - grid.resolution, 0.0))
    corners = box_corners(center, shrunk, yaw)
    cv2.fillConvexPoly(mask, pixels(corners, grid), 1, lineType=cv2.LINE_8, shift=SHIFT)


def pixels(points: np.ndarray, grid: Grid) -> np.ndarray:
    """cv2 fixed-point pixel coordinates of (n, 2) points in metres: cell centres on integers."""
    at = (points - np.asarray(grid.origin)) / grid.resolution - 0.5
    return np.round(at * SCALE).astype(np.int32)


# --------------------------------------------------------------------------- arguments

def door_states(house: House, door_open: Mapping[str, bool]) -> dict[str, bool]:
    unknown = [d for d in door_open if d not in house.door_by_id]
    if unknown:
        raise UnknownNameError("door", unknown[0], list(house.door_by_id))
    return {d.id: bool(door_open.get(d.id, d.default_open)) for d in house.doors}


def checked_models(house: House, models: Mapping[str, int]) -> Mapping[str, int]:
    unknown = [o for o in models if o not in house.object_by_id]
    if unknown:
        raise UnknownNameError("object", unknown[0], list(house.object_by_id))
    return models
