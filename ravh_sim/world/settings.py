"""Environment Manager settings S = {L lights, D doors, M paints, O object models, A agents}.

A YAML file (``config/default.yaml`` documents every key) says what to do in general terms ("every
ceiling light on", "random paint", "door Door_2 closed"); :func:`resolve` turns that into a
:class:`Resolved` value with one explicit choice per light, door, room and object. Every random choice
comes from the single seed, drawn per item from a stream named after the item, so changing one item's
setting never reshuffles the others, and the same seed and file always give the same world.
The resolved settings go into the footprint, and a footprint rebuilds the world from them alone.
"""
from __future__ import annotations

import math
import random
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ravh_sim.errors import FileFieldError, UnknownNameError, UserError
from ravh_sim.paths import DEFAULT_CONFIG, ROBOTS_DIR
from ravh_sim.world import paints
from ravh_sim.world.furniture import variant_count
from ravh_sim.world.house import House

SUN_PRESETS = {"day": 100.0, "sunset": 180.0, "night": 200.0}
SWITCH = ("on", "off", "random")
DOOR_STATES = ("default", "open", "closed", "random")


@dataclass(frozen=True)
class AgentSpec:
    name: str
    profile: str
    pose: tuple[float, float, float]         # x, y, yaw in the house frame


@dataclass
class Resolved:
    """One explicit choice for every item: what the world is built from and what a footprint stores."""
    seed: int
    sun_angle: float
    lights: dict[str, bool]
    doors: dict[str, bool]                   # door id -> open
    paint: dict[str, dict[str, str]]         # room id -> {"walls": paint, "floor": paint}
    models: dict[str, int]                   # object id -> model variant
    agents: list[AgentSpec] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["agents"] = [{"name": a.name, "profile": a.profile, "pose": list(a.pose)} for a in self.agents]
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Resolved:
        agents = [AgentSpec(a["name"], a["profile"], tuple(a["pose"])) for a in d.get("agents", [])]
        return cls(seed=int(d["seed"]), sun_angle=float(d["sun_angle"]), lights=dict(d["lights"]),
                   doors=dict(d["doors"]), paint={k: dict(v) for k, v in d["paint"].items()},
                   models={k: int(v) for k, v in d["models"].items()}, agents=agents)


def load_settings(path: Path | str | None = None) -> dict[str, Any]:
    """Read a settings YAML over the defaults; unknown keys are errors that name file and key."""
    base = _read_yaml(DEFAULT_CONFIG)
    if path is None:
        return base
    user = _read_yaml(Path(path))
    _check_keys(user, base, str(path), "")
    return _merge(base, user)


def resolve(settings: dict[str, Any], house: House, seed: int | None = None,
            source: str = "settings") -> Resolved:
    """Turn general settings into explicit per-item choices for ``house``."""
    seed = int(settings.get("seed", 0) if seed is None else seed)
    pick = _Picker(seed)
    lights_cfg, doors_cfg = settings["lights"], settings["doors"]
    paint_cfg, models_cfg = settings["paint"], settings["models"]
    return Resolved(
        seed=seed,
        sun_angle=_sun_angle(lights_cfg.get("sun_angle", "day"), pick, source),
        lights=_resolve_lights(lights_cfg, house, pick, source),
        doors=_resolve_doors(doors_cfg, house, pick, source),
        paint=_resolve_paint(paint_cfg, house, pick, source),
        models=_resolve_models(models_cfg, house, pick, source),
        agents=_resolve_agents(settings.get("agents", []), house, source),
    )


class _Picker:
    """Random choices keyed by (seed, what, item): independent of the order of the questions."""

    def __init__(self, seed: int) -> None:
        self.seed = seed

    def rng(self, what: str, item: str) -> random.Random:
        return random.Random(f"{self.seed}/{what}/{item}")

    def coin(self, what: str, item: str) -> bool:
        return self.rng(what, item).random() < 0.5


def _sun_angle(value: Any, pick: _Picker, source: str) -> float:
    if isinstance(value, str) and value in SUN_PRESETS:
        return SUN_PRESETS[value]
    if value == "random":
        return pick.rng("sun", "angle").uniform(0.0, 240.0)
    if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) \
            and 0 <= value <= 360:
        return float(value)
    raise FileFieldError(source, "lights.sun_angle",
                         f"expected degrees in [0, 360], day, sunset, night or random; got {value!r}")


def _switch(value: Any, source: str, field_path: str) -> str:
    if value is True:                       # YAML 1.1 reads on/off as booleans
        return "on"
    if value is False:
        return "off"
    if value not in SWITCH:
        raise FileFieldError(source, field_path, f"expected on, off or random; got {value!r}")
    return value


def _resolve_lights(cfg: dict, house: House, pick: _Picker, source: str) -> dict[str, bool]:
    per_light = _per_item(cfg, "lights.set", house.light_by_id, "light", source)
    out = {}
    for light in house.lights:
        group = "ceiling" if light.kind == "ceiling" else "lamps"
        if light.id in per_light:
            state = _switch(per_light[light.id], source, f"lights.set.{light.id}")
        else:
            state = _switch(cfg.get(group, "on"), source, f"lights.{group}")
        out[light.id] = pick.coin("light", light.id) if state == "random" else state == "on"
    return out


def _resolve_doors(cfg: dict, house: House, pick: _Picker, source: str) -> dict[str, bool]:
    per_door = _per_item(cfg, "doors.set", house.door_by_id, "door", source)
    out = {}
    for door in house.doors:
        key = f"doors.set.{door.id}" if door.id in per_door else "doors.all"
        state = per_door.get(door.id, cfg.get("all", "default"))
        if state is True or state is False:
            state = "open" if state else "closed"
        if state not in DOOR_STATES:
            raise FileFieldError(source, key, f"expected one of {', '.join(DOOR_STATES)}; got {state!r}")
        out[door.id] = {"default": door.default_open, "open": True, "closed": False,
                        "random": pick.coin("door", door.id)}[state]
    return out


def _resolve_paint(cfg: dict, house: House, pick: _Picker, source: str) -> dict[str, dict[str, str]]:
    per_room = _per_item(cfg, "paint.rooms", house.room_by_id, "room", source)
    out = {}
    for room in house.rooms:
        surfaces = {}
        for surface, general in (("walls", "walls"), ("floor", "floors")):
            room_cfg = per_room.get(room.id) or {}
            if not isinstance(room_cfg, dict):
                raise FileFieldError(source, f"paint.rooms.{room.id}", "expected {walls: ..., floor: ...}")
            key = f"paint.rooms.{room.id}.{surface}" if surface in room_cfg else f"paint.{general}"
            value = room_cfg.get(surface, cfg.get(general, "default"))
            surfaces[surface] = _paint(value, room.type, surface, pick.rng("paint", f"{room.id}/{surface}"),
                                       source, key)
        out[room.id] = surfaces
    return out


def _paint(value: Any, room_type: str, surface: str, rng: random.Random, source: str, key: str) -> str:
    if value == "default":
        return paints.default_paint(room_type, surface)
    if value == "random":
        return rng.choice(paints.all_paints())
    if value == "random_plain":
        return rng.choice(list(paints.PLAIN_COLOURS))
    if value == "random_texture":
        return rng.choice(paints.TEXTURES)
    if isinstance(value, str) and paints.is_paint(value):
        return value
    raise FileFieldError(source, key, f"unknown paint {value!r}; use default, random, random_plain, "
                         f"random_texture, '#rrggbb' or one of: {', '.join(paints.all_paints())}")


def _resolve_models(cfg: dict, house: House, pick: _Picker, source: str) -> dict[str, int]:
    per_object = _per_item(cfg, "models.set", house.object_by_id, "object", source)
    explicit: dict[str, int] = {}
    inherit_from: dict[str, str] = {}
    for obj in house.objects:
        key = f"models.set.{obj.id}" if obj.id in per_object else "models.all"
        value = per_object.get(obj.id, cfg.get("all", "default"))
        count = variant_count(obj.type)
        if isinstance(value, dict) and set(value) == {"inherit"}:
            inherit_from[obj.id] = str(house.object(value["inherit"]).id)
            continue
        if obj.id not in per_object and cfg.get("inherit", True) and obj.inherits_model_from:
            inherit_from[obj.id] = obj.inherits_model_from
            continue
        if value == "default":
            explicit[obj.id] = obj.default_model
        elif value == "random":
            explicit[obj.id] = pick.rng("model", obj.id).randrange(count)
        elif isinstance(value, int) and not isinstance(value, bool):
            explicit[obj.id] = value % count if obj.id not in per_object else _index(value, count, source, key)
        else:
            raise FileFieldError(source, key, f"expected default, random, a model index or "
                                 f"{{inherit: OBJECT_ID}}; got {value!r}")
    return {obj.id: _follow(obj.id, explicit, inherit_from) for obj in house.objects}


def _index(value: int, count: int, source: str, key: str) -> int:
    if not 0 <= value < count:
        raise FileFieldError(source, key, f"model index must be in 0..{count - 1}, got {value}")
    return value


def _follow(obj_id: str, explicit: dict[str, int], inherit_from: dict[str, str]) -> int:
    """The model of ``obj_id``, following inheritance links (cycles fall back to model 0)."""
    seen = set()
    while obj_id in inherit_from and obj_id not in seen:
        seen.add(obj_id)
        obj_id = inherit_from[obj_id]
    return explicit.get(obj_id, 0)


def _resolve_agents(cfg: Any, house: House, source: str) -> list[AgentSpec]:
    if not isinstance(cfg, list):
        raise FileFieldError(source, "agents", "expected a list of agents")
    agents, names = [], set()
    for i, a in enumerate(cfg):
        if not isinstance(a, dict):
            raise FileFieldError(source, f"agents[{i}]", "expected {name, profile, start}")
        name = str(a.get("name", f"robot{i}"))
        if name in names:
            raise FileFieldError(source, f"agents[{i}].name", f"duplicate agent name {name!r}")
        names.add(name)
        profile = str(a.get("profile", "giraff"))
        if not (ROBOTS_DIR / f"{profile}.yaml").exists():
            valid = sorted(p.stem for p in ROBOTS_DIR.glob("*.yaml"))
            raise FileFieldError(source, f"agents[{i}].profile", str(UnknownNameError("robot profile",
                                                                                      profile, valid)))
        agents.append(AgentSpec(name, profile, _start_pose(a.get("start", "station"), house, source,
                                                           f"agents[{i}].start")))
    return agents


def _start_pose(value: Any, house: House, source: str, key: str) -> tuple[float, float, float]:
    if value == "station":
        return (house.station.position[0], house.station.position[1], house.station.yaw)
    if isinstance(value, list) and len(value) == 3 and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value):
        return (float(value[0]), float(value[1]), float(value[2]))
    raise FileFieldError(source, key, f"expected station or [x, y, yaw]; got {value!r}")


def _per_item(cfg: dict, key: str, known: dict, kind: str, source: str) -> dict:
    section = key.split(".")[1]
    items = cfg.get(section) or {}
    if not isinstance(items, dict):
        raise FileFieldError(source, key, f"expected a mapping of {kind} id to value")
    for item in items:
        if item not in known:
            raise FileFieldError(source, f"{key}.{item}", str(UnknownNameError(kind, item, list(known))))
    return items


def _read_yaml(path: Path) -> dict[str, Any]:
    try:
        data = yaml.safe_load(path.read_text())
    except OSError as e:
        raise UserError(f"{path}: cannot read settings: {e.strerror}") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f"line {mark.line + 1} column {mark.column + 1}" if mark else "-"
        raise FileFieldError(path, where, f"invalid YAML: {getattr(e, 'problem', e)}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise FileFieldError(path, "(top level)", "expected a mapping of settings")
    return data


def _check_keys(user: dict, base: dict, source: str, prefix: str) -> None:
    """Reject keys the defaults do not have (typos), except inside per-item maps."""
    for key, value in user.items():
        where = f"{prefix}{key}"
        if key not in base:
            raise FileFieldError(source, where, f"unknown key; valid: {', '.join(map(str, base))}")
        if isinstance(value, dict) and isinstance(base[key], dict) and key not in ("set", "rooms"):
            _check_keys(value, base[key], source, where + ".")


def _merge(base: dict, user: dict) -> dict:
    out = dict(base)
    for key, value in user.items():
        out[key] = _merge(base[key], value) if isinstance(value, dict) and isinstance(
            base.get(key), dict) and key not in ("set", "rooms") else value
    return out
