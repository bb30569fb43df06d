"""What each object is made of where it stands: its model's parts, placed in the house.

Why one place: the pybullet world draws an object as its parts merged and collides with each part
(so the laser sees between table legs and hits a door leaf where the camera sees it), and the
free-space map blocks the floor under the parts that a robot's body would hit (a table top blocks
a tall robot; the empty corner of an L-shaped sofa does not). Physics, sensors and navigation then
agree on every surface because they read the same parts.

A :class:`Placed` object holds its parts in its body frame (box centre at the origin, unrotated)
and the body's pose; the world turns it by ``yaw`` about z and moves it to ``position``.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from ravh_sim.world.facing import choose_facing
from ravh_sim.world.furniture import build_parts, front_axis
from ravh_sim.world.house import Door, House, HouseObject
from ravh_sim.world.mesh import Mesh

DOOR_LEAF_THICKNESS = 0.05
"""m: the door leaf model's thickness (the doorway's frame is part of the walls)."""

Footprint = tuple[tuple[float, float], tuple[float, float], float]
"""A yawed rectangle on the floor: centre (x, y), size (along yaw, across), yaw."""


@dataclass(frozen=True)
class Placed:
    """An object's model parts in its body frame and the body's pose in the house."""
    parts: tuple[Mesh, ...]
    position: tuple[float, float, float]
    yaw: float

    def mesh(self) -> Mesh:
        """The parts merged: what the camera draws."""
        return Mesh.merged(self.parts)

    def footprints(self, z_low: float, z_high: float, min_size: float = 0.0) -> Iterator[Footprint]:
        """Floor rectangles (in the body's yawed frame) of the parts that reach into the height
        band (z_low, z_high) of the house frame: a part's rectangle is its extent along the body's
        axes, exact for the boxes most parts are and a little larger for round or slanted ones.

        A rectangle narrower than ``min_size`` grows to it towards the middle of the object, so a
        raster that draws thin shapes as lines one cell wide never draws beyond the object.
        """
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        x, y, z = self.position
        whole_lo, whole_hi = Mesh.merged(self.parts).bounds()
        for part in self.parts:
            lo, hi = part.bounds()
            if hi[2] + z <= z_low or lo[2] + z >= z_high:
                continue
            half = np.maximum((hi - lo)[:2], min_size) / 2
            middle = np.clip((lo + hi)[:2] / 2, np.minimum(whole_lo[:2] + half, 0.0),
                             np.maximum(whole_hi[:2] - half, 0.0))
            yield (x + c * middle[0] - s * middle[1], y + s * middle[0] + c * middle[1]), tuple(2 * half), self.yaw


def object_parts(house: House, obj: HouseObject, model: int | None) -> Placed:
    """``obj`` as model variant ``model`` shows it (doors: the leaf, closed, see :func:`door_parts`)."""
    if obj.id in house.door_by_id:
        return door_parts(house, house.door_by_id[obj.id], model)
    box = obj.box(model)
    walls = [(w.a, w.b) for w in house.walls if w.room == obj.room and w.kind != "lintel"]
    facing = choose_facing(box.position[:2], obj.yaw, box.size, walls, front=front_axis(obj.type))
    variant = obj.default_model if model is None else model
    parts = _parts(obj.type, tuple(box.size), variant, facing, obj.prefab)
    return Placed(parts, tuple(box.position), obj.yaw)


def door_parts(house: House, door: Door, model: int | None) -> Placed:
    """The closed door leaf (see :func:`door_pose`)."""
    width, _, height = door.leaf
    variant = house.object(door.id).default_model if model is None else model
    parts = _parts("Door", (DOOR_LEAF_THICKNESS, width, height), variant, 0, "")
    return Placed(parts, *door_pose(house, door))


def door_pose(house: House, door: Door) -> tuple[tuple[float, float, float], float]:
    """Where a closed door's leaf stands: across the doorway on the lower of its rooms' floors,
    its thickness along the doorway's depth (body position, yaw)."""
    floor = min(house.room(r).floor_z for r in door.rooms)
    return (door.position[0], door.position[1], floor + door.leaf[2] / 2), door.yaw - math.pi / 2


@functools.lru_cache(maxsize=8192)
def _parts(object_type: str, size: tuple[float, float, float], variant: int, facing: int,
           prefab: str) -> tuple[Mesh, ...]:
    """Cached: the world, every free-space map and every door or model change ask again."""
    return tuple(build_parts(object_type, np.asarray(size), variant, facing, prefab))
