"""Import the upstream Robot@VirtualHome house facts into our own house format.

``ravh import-houses SRC_DIR`` reads ``houseNN.json`` as extracted from the MIT-licensed Unity project
(schema in that folder's README) and writes ``houses/houseNN.json`` in the format documented in
``houses/README.md``. The importer keeps every room and labelled object (counts stay equal to the
source), drops Unity-specific fields (pivots, root quaternions, mesh names), and gives a per-type size
to the few objects that have no geometry upstream (ceiling lights, stations, keyboards), marked
``size_estimated`` so nobody mistakes it for measured data.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ravh_sim.errors import FileFieldError, UserError
from ravh_sim.world.house import HOUSE_FORMAT, house_from_dict

ATTRIBUTION = ("Layouts and object placements derived from Robot@VirtualHome by David Fernández "
               "Chaves et al., MIT License (github.com/DavidFernandezChaves/RobotAtVirtualHome).")

# Sizes (x, y, z) for objects with no geometry upstream, and where their box sits.
ESTIMATED_SIZE = {"Light": (0.36, 0.36, 0.08), "Station": (0.5, 0.5, 0.02), "Keyboard": (0.44, 0.14, 0.03)}
FALLBACK_SIZE = (0.1, 0.1, 0.1)

_DIGITS = 4


def import_houses(src_dir: Path, out_dir: Path) -> list[Path]:
    """Convert every ``houseNN.json`` of ``src_dir``; returns the files written."""
    sources = sorted(Path(src_dir).glob("house[0-9][0-9].json"))
    if not sources:
        raise UserError(f"{src_dir}: no houseNN.json files to import")
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for src in sources:
        house = convert_house(json.loads(src.read_text()), str(src))
        house_from_dict(house, str(src))          # what we write must load
        dst = out_dir / src.name
        dst.write_text(dump_house(house))
        written.append(dst)
    return written


def dump_house(house: dict[str, Any]) -> str:
    """Stable, diff-friendly JSON: one record per line inside each top-level list."""
    lines = ["{"]
    keys = list(house)
    for k, key in enumerate(keys):
        comma = "," if k < len(keys) - 1 else ""
        value = house[key]
        if isinstance(value, list) and value:
            lines.append(f"  {json.dumps(key)}: [")
            rows = [json.dumps(item, ensure_ascii=False) for item in value]
            lines += [f"    {row}," for row in rows[:-1]] + [f"    {rows[-1]}", f"  ]{comma}"]
        else:
            lines.append(f"  {json.dumps(key)}: {json.dumps(value, ensure_ascii=False)}{comma}")
    lines.append("}")
    return "\n".join(lines) + "\n"


def convert_house(src: dict[str, Any], source: str) -> dict[str, Any]:
    try:
        ceiling = {r["id"]: r["ceiling_z"] for r in src["rooms"]}
        return {
            "format": HOUSE_FORMAT,
            "house": src["house"],
            "attribution": ATTRIBUTION,
            "source": {k: src["source"][k] for k in ("repo", "commit", "prefab", "license")},
            "station": {"position": _r(src["station"]["position"]), "yaw": _r(src["station"]["yaw"]),
                        "object_id": src["station"]["object_id"]},
            "rooms": [_room(r) for r in src["rooms"]],
            "walls": [{"room": w["room"], "kind": w["kind"], "a": _r(w["a"]), "b": _r(w["b"]),
                       "thickness": _r(w["thickness"]), "z0": _r(w["z0"]), "z1": _r(w["z1"])}
                      for w in src["walls"]],
            "doors": [_door(d) for d in src["doors"]],
            "windows": [{"id": w["id"], "room": w["room"], "position": _r(w["position"]),
                         "yaw": _r(w["yaw"]), "width": _r(w["width"]), "height": _r(w["height"]),
                         "thickness": _r(w["thickness"])} for w in src["windows"]],
            "lights": [{"id": lt["id"], "kind": lt["kind"], "room": lt["room"],
                        "position": _r(lt["position"]), "intensity": _r(lt["intensity"]),
                        "range": _r(lt["range"]), "color": _r(lt["color_rgb"])} for lt in src["lights"]],
            "objects": [_object(o, ceiling[o["room"]]) for o in src["objects"]],
        }
    except (KeyError, TypeError, IndexError) as e:
        raise FileFieldError(source, str(e), "missing or malformed in the upstream file") from None


def _room(r: dict[str, Any]) -> dict[str, Any]:
    room = {"id": r["id"], "type": r["type"], "name": r["name"], "floor_z": _r(r["floor_z"]),
            "ceiling_z": _r(r["ceiling_z"]), "floor": _r(r["floor_polygon"])}
    if r.get("extra_floor_polygons"):
        room["extra_floors"] = _r(r["extra_floor_polygons"])
    return room


def _door(d: dict[str, Any]) -> dict[str, Any]:
    return {"id": d["id"], "rooms": d["rooms"], "position": _r(d["position"]), "yaw": _r(d["yaw"]),
            "width": _r(d["width"]), "height": _r(d["height"]), "thickness": _r(d["thickness"]),
            "leaf": _r(d["leaf_size"]), "default_open": d["default_open"]}


def _object(o: dict[str, Any], ceiling_z: float) -> dict[str, Any]:
    obj_type = o["tags"][0]
    estimated = o["size"] is None
    models = o["models"] or [{"default": True, "position": None, "size": None}]
    boxes = [_model_box(m, o, obj_type, ceiling_z) for m in models]
    default = next((i for i, m in enumerate(models) if m.get("default")), 0)
    return {"id": o["id"], "type": obj_type, "tags": o["tags"], "room": o["room"], "prefab": o["prefab"],
            "yaw": _r(o["yaw"]), "size_estimated": estimated, "default_model": default, "models": boxes,
            "inherits_model_from": o["inherits_model_from"]}


def _model_box(model: dict[str, Any], obj: dict[str, Any], obj_type: str,
               ceiling_z: float) -> dict[str, Any]:
    if model.get("size"):
        return {"position": _r(model["position"]), "size": _r(model["size"])}
    if obj.get("size"):                                   # a variant missing upstream: default box
        return {"position": _r(obj["position"]), "size": _r(obj["size"])}
    size = ESTIMATED_SIZE.get(obj_type, FALLBACK_SIZE)
    x, y, z = obj["position"]
    if obj_type == "Light":                               # a fixture hanging from the ceiling
        z = ceiling_z - size[2] / 2
    else:                                                 # resting on whatever the origin stands on
        z = z + size[2] / 2
    return {"position": _r([x, y, z]), "size": _r(list(size))}


def _r(value: Any) -> Any:
    """Round nested numbers to 0.1 mm so files stay small and stable."""
    if isinstance(value, (list, tuple)):
        return [_r(v) for v in value]
    return round(float(value), _DIGITS) if isinstance(value, (int, float)) else value
