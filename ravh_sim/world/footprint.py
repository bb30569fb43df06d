"""The footprint: what is in the world, with ids, mask colours, poses and models, so a run can be reproduced.

The instance table (:mod:`ravh_sim.world.instances`: every room surface and labelled object) is followed
by the dressing objects the seed may place (:func:`dressing_instances`, ``kind: dressing``). The
footprint is that table with each instance's pose and model (dressing rows only for those the settings'
``dressing`` level places, marked ``dressing: true`` with their ``support``), plus the resolved settings;
:func:`load_footprint` gives back the house number and settings, from which the World rebuilds exactly
the same scene.
"""
from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ravh_sim.errors import FileFieldError
from ravh_sim.files import atomic_write
from ravh_sim.poses import quaternion_from_yaw
from ravh_sim.world.dressing import Dressed, dressing, slots
from ravh_sim.world.geometry import polygon_centroid
from ravh_sim.world.house import House
from ravh_sim.world.instances import STRUCTURE_KINDS, Instance, build_instances, mask_color
from ravh_sim.world.library import record
from ravh_sim.world.settings import Resolved
from ravh_sim.world.solids import object_parts

FOOTPRINT_FORMAT = "ravh_sim/footprint@1"
def dressing_instances(house: House, seed: int) -> list[Instance]:
    """Every dressing object that ``seed`` may place in ``house`` (:func:`ravh_sim.world.dressing.slots`),
    numbered after the house's instances: the same ids at every level and with every object model."""
    return [Instance(s.instance, s.id, "dressing", s.room, house.room(s.room).type, s.type, s.tags,
                     mask_color(s.instance)) for s in slots(house, seed)]


def dressing_pose(dressed: Dressed) -> dict[str, Any]:
    """A placed dressing object's footprint fields (:class:`ravh_sim.world.dressing.Dressed`)."""
    slot = dressed.slot
    return {"position": _r(dressed.position), "orientation": _r(quaternion_from_yaw(dressed.yaw)),
            "yaw": _r(dressed.yaw), "model": None, "size": _r(slot.size), "asset": slot.model_id,
            "dressing": True, "support": slot.support, "collides": slot.collides}


def instance_pose(house: House, models: Mapping[str, int], inst: Instance) -> dict[str, Any]:
    """Position, orientation and model of an instance when objects have ``models``; ``asset`` names
    the furniture-library model drawn (see furniture/ATTRIBUTION.md), None for procedural ones."""
    if inst.kind in STRUCTURE_KINDS:
        room = house.room(inst.room)
        cx, cy = polygon_centroid(room.floor)
        z = {"floor": room.floor_z, "ceiling": room.ceiling_z, "walls": (room.floor_z + room.ceiling_z) / 2}
        return {"position": _r([cx, cy, z[inst.kind]]), "orientation": [0.0, 0.0, 0.0, 1.0], "yaw": 0.0,
                "model": None, "size": None, "asset": None}
    obj = house.object(inst.name)
    model = models[obj.id]
    box = obj.box(model)
    fitted = object_parts(house, obj, model).model
    return {"position": _r(box.position), "orientation": _r(quaternion_from_yaw(obj.yaw)),
            "yaw": _r(obj.yaw), "model": model, "size": _r(box.size),
            "asset": record(fitted).id if fitted is not None else None}


def make_footprint(house: House, settings: Resolved) -> dict[str, Any]:
    """The footprint document (JSON-ready) of a world with ``settings``: for a running world, the
    record of its live state (``world.state.settings()``), so it describes what the sensors see."""
    rows = []
    for inst in build_instances(house):
        row = {"id": inst.id, "name": inst.name, "kind": inst.kind, "mask_color": list(inst.mask_color),
               "room": inst.room, "room_type": inst.room_type, "type": inst.type, "tags": list(inst.tags)}
        row.update(instance_pose(house, settings.models, inst))
        if inst.kind == "door":
            row["open"] = settings.doors[inst.name]
        if inst.name in settings.lights:
            row["on"] = settings.lights[inst.name]
        rows.append(row)
    for dressed in dressing(house, settings.models, settings.dressing, settings.seed):
        slot = dressed.slot
        rows.append({"id": slot.instance, "name": slot.id, "kind": "dressing",
                     "mask_color": list(mask_color(slot.instance)), "room": slot.room,
                     "room_type": house.room(slot.room).type, "type": slot.type, "tags": list(slot.tags),
                     **dressing_pose(dressed)})
    imported = ({"house_name": house.name, "attribution": house.attribution, "source": house.source}
                if house.name else {})
    return {"format": FOOTPRINT_FORMAT, "house": house.number, **imported,
            "settings": settings.model_dump(mode="json"), "instances": rows}


def dump_footprint(footprint: dict[str, Any]) -> str:
    """Stable text (sorted keys, one instance per line) so equal footprints are byte-identical."""
    head = {k: v for k, v in footprint.items() if k != "instances"}
    text = json.dumps(head, sort_keys=True, separators=(",", ":"))[:-1]
    rows = ",\n".join(json.dumps(r, sort_keys=True, separators=(",", ":")) for r in footprint["instances"])
    return f'{text},"instances":[\n{rows}\n]}}\n'


def write_footprint(footprint: dict[str, Any], path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, dump_footprint(footprint).encode())


def load_footprint(path: Path) -> tuple[int, Resolved]:
    """(house number, resolved settings) of a footprint file."""
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError) as e:
        raise FileFieldError(path, "-", f"cannot read footprint: {e}") from None
    if not isinstance(data, dict) or data.get("format") != FOOTPRINT_FORMAT:
        raise FileFieldError(path, "format", f"expected {FOOTPRINT_FORMAT!r}")
    try:
        return int(data["house"]), Resolved.model_validate(data["settings"])
    except (KeyError, TypeError, ValueError) as e:
        raise FileFieldError(path, f"settings ({e})", "missing or malformed") from None


def _r(values: Any) -> Any:
    """Round to 0.1 mm (a number or a sequence); + 0.0 turns -0.0 into 0.0 for stable text."""
    if isinstance(values, (int, float)):
        return round(float(values), 4) + 0.0
    return [round(float(v), 4) + 0.0 for v in values]

