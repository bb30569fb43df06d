"""How rooms connect: through doors and through open passages (archways) that have no door.

The house files list doors with the rooms they join, but some rooms open onto each other without a
door (house 23's two living rooms share a 1.75 m archway). Both show up the same way on a raster:
two rooms' floors touching with no wall between them. Each such contact is one :class:`Link`,
attributed to the door standing in it when there is one.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

from ravh_sim.world.house import House

RESOLUTION = 0.05
MIN_OPENING_M = 0.4          # narrower contacts are drawing slivers, not passages
DOOR_MATCH_M = 0.6           # a contact this close to a door's centre is that door's doorway
WALL_BELOW_M = 1.0           # wall pieces starting lower than this (not lintels) block passage


@dataclass(frozen=True)
class Link:
    rooms: tuple[str, str]
    door: str | None          # None: an open passage
    position: tuple[float, float]
    width: float              # metres of contact


@lru_cache(maxsize=64)
def room_links(house: House) -> tuple[Link, ...]:
    """Every contact between two rooms, with the door in it (if any). Cached per house."""
    labels, origin = _room_raster(house)
    links = []
    for (a, b), cells in _contacts(labels).items():
        mask = np.zeros(labels.shape, np.uint8)
        mask[cells[:, 0], cells[:, 1]] = 1
        count, comp = cv2.connectedComponents(mask, connectivity=8)
        for k in range(1, count):
            rows, cols = np.nonzero(comp == k)
            width = float(max(np.ptp(rows), np.ptp(cols)) + 1) * RESOLUTION
            if width < MIN_OPENING_M:
                continue
            x = origin[0] + (float(cols.mean()) + 0.5) * RESOLUTION
            y = origin[1] + (float(rows.mean()) + 0.5) * RESOLUTION
            ids = (house.rooms[a].id, house.rooms[b].id)
            links.append(Link(ids, _door_at(house, ids, x, y), (round(x, 3), round(y, 3)), round(width, 2)))
    for door in house.doors:              # doors whose contact was too thin to see still join rooms
        if len(door.rooms) == 2 and not any(lk.door == door.id for lk in links):
            links.append(Link((door.rooms[0], door.rooms[1]), door.id, door.position[:2], door.width))
    return tuple(sorted(links, key=lambda lk: (lk.rooms, lk.door or "", lk.position)))


def room_index_raster(house: House, resolution: float = RESOLUTION) -> tuple[np.ndarray, tuple[float, float]]:
    """Room index + 1 per cell of the house's floor plan (0 outside every room); rows run along y.
    Returns the raster and the house-frame position of cell (0, 0)."""
    xmin, ymin, xmax, ymax = house.bounds
    origin = (xmin - 0.5, ymin - 0.5)
    shape = (int((ymax - ymin + 1) / resolution) + 1, int((xmax - xmin + 1) / resolution) + 1)
    labels = np.zeros(shape, np.int32)
    for i, room in enumerate(house.rooms):
        for poly in (room.floor, *room.extra_floors):
            cv2.fillPoly(labels, [_cells(poly, origin, resolution)], i + 1)
    return labels, origin


def _cells(points, origin: tuple[float, float], resolution: float) -> np.ndarray:
    return np.round((np.asarray(points, float) - origin) / resolution).astype(np.int32)


def _room_raster(house: House) -> tuple[np.ndarray, tuple[float, float]]:
    """Room index + 1 per cell (0 outside, -1 wall)."""
    labels, origin = room_index_raster(house)

    def px(points) -> np.ndarray:
        return _cells(points, origin, RESOLUTION)

    for wall in house.walls:
        if wall.z0 - house.room(wall.room).floor_z < WALL_BELOW_M:
            thickness = max(int(round(wall.thickness / RESOLUTION)), 1)
            cv2.line(labels, tuple(px(wall.a)), tuple(px(wall.b)), -1, thickness)
    return labels, origin


def _contacts(labels: np.ndarray) -> dict[tuple[int, int], np.ndarray]:
    """Cells where two different rooms touch (4-neighbourhood), grouped by room pair."""
    out: dict[tuple[int, int], list[tuple[np.intp, np.intp]]] = {}
    for da, db in (((slice(None), slice(0, -1)), (slice(None), slice(1, None))),
                   ((slice(0, -1), slice(None)), (slice(1, None), slice(None)))):
        a, b = labels[da], labels[db]
        touch = (a > 0) & (b > 0) & (a != b)
        rows, cols = np.nonzero(touch)
        for r, c in zip(rows, cols):
            pair = (min(a[r, c], b[r, c]) - 1, max(a[r, c], b[r, c]) - 1)
            out.setdefault(pair, []).append((r, c))
    return {pair: np.array(cells) for pair, cells in out.items()}


def _door_at(house: House, rooms: tuple[str, str], x: float, y: float) -> str | None:
    best, best_d = None, DOOR_MATCH_M
    for door in house.doors:
        d = float(np.hypot(door.position[0] - x, door.position[1] - y))
        if d < best_d and set(door.rooms) & set(rooms):
            best, best_d = door.id, d
    return best
