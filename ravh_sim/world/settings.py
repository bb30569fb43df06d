"""Environment Manager settings S = {L lights, D doors, M paints, O object models, A agents}.

A YAML file (``config/default.yaml`` documents every key) says what to do in general terms ("every
ceiling light on", "random paint", "door Door_2 closed"); :func:`resolve` turns that into a
:class:`Resolved` value with one explicit choice per light, door, room and object. Every random choice
comes from the single seed, drawn per item from a stream named after the item, so changing one item's
setting never reshuffles the others, and the same seed and file always give the same world.
The resolved settings are the appearance model (:class:`ravh_msgs_py.appearance.Looks`, whose
global knobs, like the sun angle, this file's ``lights`` section sets) with the seed and the agents:
frozen, a World starts from them, and its live state (:mod:`ravh_sim.world.state`) is the current
:class:`Resolved` value, replaced on each change. That value goes into the footprint, and a footprint
rebuilds the world from it alone.
"""
from __future__ import annotations

import math
import random
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, Field, create_model

from ravh_msgs_py.appearance import DOOR, KNOBS, SEED_MAX, SWITCH, Looks, Seed
from ravh_msgs_py.names import DEFAULT_PROFILE
from ravh_sim.errors import FileFieldError, UnknownNameError, UserError
from ravh_sim.paths import DEFAULT_CONFIG, ROBOTS_DIR
from ravh_sim.schema import Strict, load_yaml, read_text, shown, validate
from ravh_sim.world import paints
from ravh_sim.world.house import House, HouseObject, Light, Room
from ravh_sim.world.solids import model_count

DOOR_STATES = ("default", *DOOR)          # a settings file may also keep a door as the house has it
AGENT_CLEARANCE = 0.5      # m between two agents' start positions (two Giraff radii)
MAX_AGENTS = 32            # each is a simulated robot with its own sensors
RESERVED_AGENT_NAMES = ("ravh",)   # a second agent's names are prefixed with its name: ravh/... is the sim's


# --------------------------------------------------------------------------- the file's schema
# Values that mix words and numbers get one validator each, so an error says what is allowed.

def _check_switch(v: Any) -> Any:
    if isinstance(v, bool) or v in SWITCH:  # YAML 1.1 reads on/off as booleans
        return v
    raise ValueError("expected on, off or random")


def _check_door(v: Any) -> Any:
    if isinstance(v, bool) or v in DOOR_STATES:
        return v
    raise ValueError(f"expected one of {', '.join(DOOR_STATES)}")


def _check_paint(v: Any) -> Any:
    if v in ("default", "random", "random_plain", "random_texture") or isinstance(v, str) and paints.is_paint(v):
        return v
    raise ValueError(f"unknown paint; use default, random, random_plain, random_texture, '#rrggbb' "
                     f"or one of: {', '.join(paints.all_paints())}")


def _check_model(v: Any) -> Any:
    if v in ("default", "random") or isinstance(v, int) and not isinstance(v, bool) and v >= 0 or (
            isinstance(v, dict) and set(v) == {"inherit"} and isinstance(v["inherit"], str)):
        return v
    raise ValueError("expected default, random, a model index >= 0 or {inherit: OBJECT_ID}")


def _check_start(v: Any) -> Any:
    if v == "station" or isinstance(v, list) and len(v) == 3 and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v):
        return v
    raise ValueError("expected station or [x, y, yaw] (finite numbers)")


def _checked(check) -> Any:
    return Annotated[Any, AfterValidator(check)]


class _Switches(Strict):
    ceiling: _checked(_check_switch)
    lamps: _checked(_check_switch)
    set: dict[str, _checked(_check_switch)]


# the lights section: the switches and every global knob of the appearance model (sun_angle, ...)
_KNOB_FIELDS: dict[str, Any] = {name: (_checked(knob.check), Looks.model_fields[name].default)
                                for name, knob in KNOBS.items()}
_Lights = create_model("_Lights", __base__=_Switches, **_KNOB_FIELDS)


class _Doors(Strict):
    all: _checked(_check_door)
    set: dict[str, _checked(_check_door)]


class _RoomPaint(Strict):
    walls: _checked(_check_paint) = None
    floor: _checked(_check_paint) = None


class _Paint(Strict):
    walls: _checked(_check_paint)
    floors: _checked(_check_paint)
    rooms: dict[str, _RoomPaint]


class _Models(Strict):
    all: _checked(_check_model)
    set: dict[str, _checked(_check_model)]
    inherit: bool


class _Agent(Strict):
    # no name: robot<i>; an explicit null is refused (the default is not validated, the value is)
    name: Annotated[str, Field(default=None, min_length=1, max_length=64, pattern=r"^[A-Za-z_][A-Za-z0-9_]*$")]
    profile: Annotated[str, Field(min_length=1, max_length=64)] = DEFAULT_PROFILE
    start: _checked(_check_start) = "station"


class SettingsFile(Strict):
    """Every key of a settings file after merging over the defaults (config/default.yaml)."""
    seed: Seed
    lights: _Lights
    doors: _Doors
    paint: _Paint
    models: _Models
    dressing: Literal["none", "tidy", "lived-in"]
    agents: Annotated[list[_Agent], Field(max_length=MAX_AGENTS)]


def check_seed(seed: Any) -> int:
    """A seed from a flag or a request, held to the settings file's rule."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= SEED_MAX:
        raise UserError(f"seed: expected an integer in 0..{SEED_MAX}, got {shown(seed)}")
    return seed


@dataclass(frozen=True)
class AgentSpec:
    name: str
    profile: str
    pose: tuple[float, float, float]         # x, y, yaw in the house frame


class Resolved(Looks):
    """One explicit choice for every item: what a world is built from and what a footprint stores
    (``model_dump(mode="json")``; ``model_validate`` reads it back). Frozen, mappings included: a value
    that was handed to a World or written into a footprint can never drift from what it recorded;
    :meth:`changed` derives another."""
    seed: Seed
    agents: tuple[AgentSpec, ...] = ()


def knob_value(name: str, choice: Any, seed: int) -> float:
    """The value of global knob ``name`` (ravh_msgs_py.appearance.KNOBS) that ``choice`` (a number or
    one of the knob's words) stands for; "random" draws from ``seed`` as a settings file does."""
    knob = KNOBS[name]
    try:
        return knob.value(knob.check(choice), _Picker(seed).stream)
    except ValueError as e:
        raise UserError(f"{name}: {e}, got {shown(choice)}") from None


def light_group(light: Light) -> str:
    """The group (ravh_msgs_py.appearance.LIGHT_GROUPS, besides "all") that switches ``light``."""
    return "ceiling" if light.kind == "ceiling" else "lamps"


def load_settings(path: Path | str | None = None) -> dict[str, Any]:
    """Read a settings YAML over the defaults and validate every key; errors name file and key."""
    base = _read_yaml(DEFAULT_CONFIG)
    if path is None:
        return base
    user = _read_yaml(Path(path))
    merged = _merge(base, user)
    validate(SettingsFile, merged, path)
    return merged


def resolve(settings: dict[str, Any], house: House, seed: int | None = None,
            source: str = "settings") -> Resolved:
    """Turn general settings into explicit per-item choices for ``house``."""
    validate(SettingsFile, settings, source)
    seed = settings["seed"] if seed is None else check_seed(seed)
    pick = _Picker(seed)
    lights_cfg, doors_cfg = settings["lights"], settings["doors"]
    paint_cfg, models_cfg = settings["paint"], settings["models"]
    return Resolved(
        seed=seed,
        **{name: knob.value(lights_cfg.get(name, Looks.model_fields[name].default), pick.stream)
           for name, knob in KNOBS.items()},
        lights=_resolve_lights(lights_cfg, house, pick, source),
        doors=_resolve_doors(doors_cfg, house, pick, source),
        paint=_resolve_paint(paint_cfg, house, pick, source),
        models=_resolve_models(models_cfg, house, pick, source),
        dressing=settings.get("dressing", "none"),
        agents=_resolve_agents(settings.get("agents", []), house, source),
    )


class _Picker:
    """Random choices keyed by (seed, what, item): independent of the order of the questions."""

    def __init__(self, seed: int) -> None:
        self.seed = seed

    def stream(self, name: str) -> random.Random:
        return random.Random(f"{self.seed}/{name}")

    def rng(self, what: str, item: str) -> random.Random:
        return self.stream(f"{what}/{item}")

    def coin(self, what: str, item: str) -> bool:
        return self.rng(what, item).random() < 0.5


def _switch(value: Any) -> str:
    if isinstance(value, bool):       # YAML 1.1 reads on/off as booleans
        return "on" if value else "off"
    return value


def _resolve_lights(cfg: dict, house: House, pick: _Picker, source: str) -> dict[str, bool]:
    per_light = _per_item(cfg, "lights.set", house.light_by_id, "light", source)
    out = {}
    for light in house.lights:
        if light.id in per_light:
            state = _switch(per_light[light.id])
        else:
            state = _switch(cfg[light_group(light)])
        out[light.id] = pick.coin("light", light.id) if state == "random" else state == "on"
    return out


def _resolve_doors(cfg: dict, house: House, pick: _Picker, source: str) -> dict[str, bool]:
    per_door = _per_item(cfg, "doors.set", house.door_by_id, "door", source)
    out = {}
    for door in house.doors:
        state = per_door.get(door.id, cfg["all"])
        if isinstance(state, bool):
            state = "open" if state else "closed"
        out[door.id] = {"default": door.default_open, "open": True, "closed": False,
                        "random": pick.coin("door", door.id)}[state]
    return out


def _resolve_paint(cfg: dict, house: House, pick: _Picker, source: str) -> dict[str, dict[str, str]]:
    per_room = _per_item(cfg, "paint.rooms", house.room_by_id, "room", source)
    out = {}
    for room in house.rooms:
        surfaces = {}
        for surface, general in (("walls", "walls"), ("floor", "floors")):
            value = (per_room.get(room.id) or {}).get(surface) or cfg[general]
            surfaces[surface] = _paint(value, room, surface, pick.rng("paint", f"{room.id}/{surface}"))
        out[room.id] = surfaces
    return out


def _paint(value: str, room: Room, surface: str, rng: random.Random) -> str:
    if value == "default":              # the room's own paint (an imported home's colours), else by its type
        return room.own_paint(surface) or paints.default_paint(room.type, surface)
    if value == "random":
        return rng.choice(paints.all_paints())
    if value == "random_plain":
        return rng.choice(list(paints.PLAIN_COLOURS))
    if value == "random_texture":
        return rng.choice(paints.TEXTURES)
    return value


def _resolve_models(cfg: dict, house: House, pick: _Picker, source: str) -> dict[str, int]:
    per_object = _per_item(cfg, "models.set", house.object_by_id, "object", source)
    if isinstance(cfg["all"], int) and house.objects:
        _index(cfg["all"], max(model_count(o) for o in house.objects), source, "models.all")
    explicit: dict[str, int] = {}
    inherit_from: dict[str, str] = {}
    for obj in house.objects:
        key = f"models.set.{obj.id}" if obj.id in per_object else "models.all"
        value = per_object.get(obj.id, cfg["all"])
        count = model_count(obj)
        if isinstance(value, dict) and set(value) == {"inherit"}:
            inherit_from[obj.id] = str(house.object(value["inherit"]).id)
            continue
        if obj.id not in per_object and cfg["inherit"] and obj.inherits_model_from:
            inherit_from[obj.id] = obj.inherits_model_from
            continue
        if value == "default":
            explicit[obj.id] = obj.default_model
        elif value == "random":
            explicit[obj.id] = pick.rng("model", obj.id).randrange(count)
        else:   # an index: per object it must exist; models.all wraps for objects with fewer models
            explicit[obj.id] = value % count if obj.id not in per_object else _index(value, count, source, key)
    return {obj.id: fit_model(_follow(obj.id, explicit, inherit_from), obj) for obj in house.objects}


def fit_model(index: int, obj: HouseObject) -> int:
    """A model index another object passed on (inheritance), made one that ``obj`` has: a sink
    inheriting from a counter with more models wraps round, as ``models.all`` does, instead of asking
    for a model it lacks."""
    return index % model_count(obj)


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


def _resolve_agents(cfg: list[dict], house: House, source: str) -> tuple[AgentSpec, ...]:
    agents: list[AgentSpec] = []
    names = set()
    for i, a in enumerate(cfg):
        name = a.get("name") or f"robot{i}"
        if name in names:
            raise FileFieldError(source, f"agents[{i}].name", f"duplicate agent name {name!r}")
        if name in RESERVED_AGENT_NAMES:
            raise FileFieldError(source, f"agents[{i}].name", f"{name!r} is reserved: the sim's own topics "
                                 f"and services are named {name}/...")
        names.add(name)
        profile = a.get("profile", DEFAULT_PROFILE)
        if not (ROBOTS_DIR / f"{profile}.yaml").exists():
            valid = sorted(p.stem for p in ROBOTS_DIR.glob("*.yaml"))
            raise FileFieldError(source, f"agents[{i}].profile", str(UnknownNameError("robot profile",
                                                                                      profile, valid)))
        pose = _start_pose(a.get("start", "station"), house, source, f"agents[{i}].start")
        for other in agents:
            if math.dist(pose[:2], other.pose[:2]) < AGENT_CLEARANCE:
                raise FileFieldError(source, f"agents[{i}].start", f"within {AGENT_CLEARANCE} m of agent "
                                     f"{other.name!r}'s start; give each agent its own start")
        agents.append(AgentSpec(name, profile, pose))
    return tuple(agents)


def _start_pose(value: Any, house: House, source: str, key: str) -> tuple[float, float, float]:
    if value == "station":
        return (house.station.position[0], house.station.position[1], house.station.yaw)
    x, y, yaw = (float(v) for v in value)
    try:
        house.room_at_or_raise(x, y)
    except UserError as e:
        raise FileFieldError(source, key, str(e)) from None
    return (x, y, yaw)


def _per_item(cfg: dict, key: str, known: dict, kind: str, source: str) -> dict:
    items = cfg[key.split(".")[1]]
    for item in items:
        if item not in known:
            raise FileFieldError(source, f"{key}.{item}", str(UnknownNameError(kind, item, list(known))))
    return items


def _read_yaml(path: Path) -> dict[str, Any]:
    data = load_yaml(read_text(path, "settings"), path)
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise FileFieldError(path, "(top level)", "expected a mapping of settings")
    return data


def _merge(base: dict, user: dict) -> dict:
    out = dict(base)
    for key, value in user.items():
        out[key] = _merge(base[key], value) if isinstance(value, dict) and isinstance(
            base.get(key), dict) and key not in ("set", "rooms") else value
    return out
