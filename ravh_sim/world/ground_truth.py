"""The Environment Manager's ground truth: answers the query language of ``ravh_msgs_py.query``.

Answers come from the house model, a world's state (door states, chosen models: the live
:class:`~ravh_sim.world.state.WorldState` of a running world, or ``WorldState(resolved)`` without one)
and the instance table, so the same engine serves ``ravh query``, the Python API and the ROS service.
:meth:`GroundTruth.answer` never raises: every failure, including a bug, becomes a structured error
reply.

Dressing objects (:mod:`ravh_sim.world.dressing`, those the state's ``dressing`` level places) answer
like objects, marked ``"dressing": true`` with their ``support``: ``object``, ``objects_in_room``,
``objects_with_tag`` (their tags are their type and ``dressing``) and ``room`` list them; ``counts``
keeps ``objects`` and ``objects_by_type`` to the house's own objects (the paper's list) and counts
dressing apart (``dressing``, ``dressing_by_type``); ``tags`` counts both.
"""
from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from typing import Any

from ravh_msgs_py import query as q
from ravh_sim.world.dressing import Dressed, dressing
from ravh_sim.world.footprint import build_instances, dressing_instances, dressing_pose, instance_pose
from ravh_sim.world.geometry import polygon_centroid
from ravh_sim.world.house import House, HouseObject, Room
from ravh_sim.world.state import WorldState
from ravh_sim.world.topology import room_links


class GroundTruth:
    def __init__(self, house: House, state: WorldState) -> None:
        self.house = house
        self.state = state
        self.instances = {inst.name: inst for inst in build_instances(house)}
        self.instances.update({inst.name: inst for inst in dressing_instances(house, state.seed)})
        self._handlers: dict[str, Callable[..., Any]] = {
            "help": lambda: q.describe(),
            "rooms": self._rooms, "room": self._room, "objects_in_room": self._objects_in_room,
            "objects_with_tag": self._objects_with_tag, "object": self._object, "room_at": self._room_at,
            "door": self._door, "connectivity": self._connectivity, "counts": self._counts,
            "tags": self._tags,
        }

    def answer(self, text: str | bytes | dict) -> dict[str, Any]:
        """Reply to one request (JSON text or an already-decoded dict)."""
        try:
            name, args = q.parse_request(text)
            return q.ok_reply(self._handlers[name](**args))
        except q.QueryError as e:
            return e.reply()
        except Exception as e:  # the engine must never take a caller down
            return q.error_reply(q.INTERNAL, f"{type(e).__name__}: {e}")

    # ------------------------------------------------------------------ lookups with clear errors
    def _room_or_error(self, room_id: str) -> Room:
        if room_id not in self.house.room_by_id:
            raise q.QueryError(q.UNKNOWN_ID, f"unknown room {room_id!r}", list(self.house.room_by_id))
        return self.house.room_by_id[room_id]

    def _object_or_error(self, object_id: str) -> HouseObject:
        if object_id not in self.house.object_by_id:
            known = [*self.house.object_by_id, *(d.id for d in self._dressed())]
            raise q.QueryError(q.UNKNOWN_ID, f"unknown object {object_id!r}", known)
        return self.house.object_by_id[object_id]

    def _dressed(self) -> list[Dressed]:
        """The dressing objects the state shows now."""
        return list(dressing(self.house, self.state.models, self.state.dressing, self.state.seed))

    def _all_tags(self) -> list[str]:
        return [t for o in self.house.objects for t in o.tags] + [t for d in self._dressed() for t in d.slot.tags]

    def _check_tag(self, tag: str) -> None:
        tags = sorted(set(self._all_tags()))
        if tag not in tags:
            raise q.QueryError(q.UNKNOWN_ID, f"unknown tag {tag!r}", tags)

    # ------------------------------------------------------------------ summaries
    def _room_summary(self, room: Room) -> dict[str, Any]:
        cx, cy = polygon_centroid(room.floor)
        return {"id": room.id, "type": room.type, "area": round(room.area, 3),
                "centroid": [round(cx, 3), round(cy, 3)], "floor_z": room.floor_z, "ceiling_z": room.ceiling_z}

    def _object_summary(self, obj: HouseObject) -> dict[str, Any]:
        inst = self.instances[obj.id]
        pose = instance_pose(self.house, self.state.models, inst)
        return {"id": obj.id, "type": obj.type, "tags": list(obj.tags), "room": obj.room,
                "room_type": inst.room_type, "instance_id": inst.id, "mask_color": list(inst.mask_color),
                **pose}

    def _dressing_summary(self, dressed: Dressed) -> dict[str, Any]:
        slot = dressed.slot
        inst = self.instances[slot.id]
        return {"id": slot.id, "type": slot.type, "tags": list(slot.tags), "room": slot.room,
                "room_type": inst.room_type, "instance_id": inst.id, "mask_color": list(inst.mask_color),
                **dressing_pose(dressed)}

    # ------------------------------------------------------------------ queries
    def _rooms(self, type: str | None = None) -> list[dict[str, Any]]:
        types = sorted({r.type for r in self.house.rooms})
        if type is not None and type not in types:
            raise q.QueryError(q.UNKNOWN_ID, f"no room of type {type!r} in house {self.house.number}", types)
        return [self._room_summary(r) for r in self.house.rooms if type is None or r.type == type]

    def _room(self, id: str) -> dict[str, Any]:
        room = self._room_or_error(id)
        return {**self._room_summary(room), "floor": [list(p) for p in room.floor],
                "doors": [d.id for d in self.house.doors if room.id in d.rooms],
                "objects": [o.id for o in self.house.objects if o.room == room.id]
                + [d.id for d in self._dressed() if d.slot.room == room.id]}

    def _objects_in_room(self, room: str, tag: str | None = None) -> list[dict[str, Any]]:
        self._room_or_error(room)
        if tag is not None:
            self._check_tag(tag)
        return [self._object_summary(o) for o in self.house.objects
                if o.room == room and (tag is None or tag in o.tags)] + [
            self._dressing_summary(d) for d in self._dressed()
            if d.slot.room == room and (tag is None or tag in d.slot.tags)]

    def _objects_with_tag(self, tag: str) -> list[dict[str, Any]]:
        self._check_tag(tag)
        return [self._object_summary(o) for o in self.house.objects if tag in o.tags] + [
            self._dressing_summary(d) for d in self._dressed() if tag in d.slot.tags]

    def _object(self, id: str) -> dict[str, Any]:
        for d in self._dressed() if id not in self.house.object_by_id else ():
            if d.id == id:
                return self._dressing_summary(d)
        return self._object_summary(self._object_or_error(id))

    def _room_at(self, x: float, y: float) -> dict[str, Any] | None:
        room = self.house.room_at(float(x), float(y))
        return None if room is None else self._room_summary(room)

    def _door(self, id: str) -> dict[str, Any]:
        if id not in self.house.door_by_id:
            raise q.QueryError(q.UNKNOWN_ID, f"unknown door {id!r}", list(self.house.door_by_id))
        door = self.house.door_by_id[id]
        return {"id": door.id, "rooms": list(door.rooms), "open": self.state.doors[door.id],
                "position": list(door.position), "yaw": door.yaw, "width": door.width,
                "to_outside": len(door.rooms) == 1}

    def _connectivity(self, open_only: bool = False) -> dict[str, Any]:
        """Rooms joined by doors and by open passages (archways without a door)."""
        edges: list[dict[str, Any]] = []
        for link in room_links(self.house):
            is_open = True if link.door is None else self.state.doors[link.door]
            if is_open or not open_only:
                edges.append({"rooms": list(link.rooms), "door": link.door, "open": is_open,
                              "position": list(link.position), "width": link.width})
        neighbours: dict[str, set[str]] = {r.id: set() for r in self.house.rooms}
        for e in edges:
            a, b = e["rooms"]
            neighbours[a].add(b)
            neighbours[b].add(a)
        return {"rooms": [r.id for r in self.house.rooms], "edges": edges,
                "neighbours": {k: sorted(v) for k, v in neighbours.items()},
                "components": _components(neighbours)}

    def _counts(self, room: str | None = None) -> dict[str, Any]:
        if room is not None:
            self._room_or_error(room)
        objects = [o for o in self.house.objects if room is None or o.room == room]
        rooms = [r for r in self.house.rooms if room is None or r.id == room]
        dressed = [d for d in self._dressed() if room is None or d.slot.room == room]
        return {"objects": len(objects), "rooms": len(rooms),
                "objects_by_type": dict(sorted(Counter(o.type for o in objects).items())),
                "rooms_by_type": dict(sorted(Counter(r.type for r in rooms).items())),
                "dressing": len(dressed),
                "dressing_by_type": dict(sorted(Counter(d.slot.type for d in dressed).items()))}

    def _tags(self) -> dict[str, int]:
        return dict(sorted(Counter(self._all_tags()).items()))


def _components(neighbours: dict[str, set[str]]) -> list[list[str]]:
    seen: set[str] = set()
    components = []
    for start in neighbours:
        if start in seen:
            continue
        stack, comp = [start], []
        seen.add(start)
        while stack:
            node = stack.pop()
            comp.append(node)
            for nb in sorted(neighbours[node]):
                if nb not in seen:
                    seen.add(nb)
                    stack.append(nb)
        components.append(sorted(comp))
    return components
