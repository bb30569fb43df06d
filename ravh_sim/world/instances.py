"""The instance table: everything the camera can see, with the id instance images store and a mask colour.

A pure function of the house (no pybullet, no settings): one entry per room surface (floor, ceiling,
walls) and per labelled object, in a fixed order, numbered from 1 (0 means "nothing" in instance
images). Dressing objects follow, numbered after these (:mod:`ravh_sim.world.dressing`), and the
footprint (:mod:`ravh_sim.world.footprint`) adds each instance's pose and model.
"""
from __future__ import annotations

from dataclasses import dataclass

from ravh_sim.world.house import House

STRUCTURE_KINDS = ("floor", "ceiling", "walls")


@dataclass
class Instance:
    """Something the camera can see, with the id that instance images store."""
    id: int                        # >= 1
    name: str                      # object id, or '<room id>/floor|ceiling|walls'
    kind: str                      # object | door | window | floor | ceiling | walls | dressing
    room: str
    room_type: str
    type: str                      # object category (first tag) or the structure kind
    tags: tuple[str, ...]
    mask_color: tuple[int, int, int]
    body: int = -1                 # pybullet body, set by the World


def mask_color(instance_id: int) -> tuple[int, int, int]:
    """A unique colour per id: the id's bits spread over R, G, B from the top bit down, so that
    consecutive ids get very different colours (and the mapping is invertible)."""
    rgb = [0, 0, 0]
    for bit in range(24):
        if instance_id >> bit & 1:
            rgb[bit % 3] |= 1 << (7 - bit // 3)
    return (rgb[0], rgb[1], rgb[2])


def build_instances(house: House) -> list[Instance]:
    """Every instance of ``house`` in its fixed order."""
    specs: list[tuple[str, str, str, str, tuple[str, ...]]] = []
    rooms_with_walls = {w.room for w in house.walls}
    for room in house.rooms:
        for kind in STRUCTURE_KINDS:
            if kind != "walls" or room.id in rooms_with_walls:
                specs.append((f"{room.id}/{kind}", kind, room.id, kind, (kind,)))
    for obj in house.objects:
        kind = "door" if obj.id in house.door_by_id else "window" if obj.type == "Wall" else "object"
        specs.append((obj.id, kind, obj.room, obj.type, obj.tags))
    return [Instance(i, name, kind, room, house.room(room).type, type_, tags, mask_color(i))
            for i, (name, kind, room, type_, tags) in enumerate(specs, start=1)]
