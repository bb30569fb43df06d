"""The house model: rooms, walls, doors, windows, lights, labelled objects and the station.

A house file (``houses/houseNN.json``, schema in ``houses/README.md``) is read once into these frozen
dataclasses; everything downstream (the pybullet world, the plan picture, navigation, ground truth)
reads the same model. Loading validates every field and reports the file and field path of the first
problem, so a hand-edited house never fails later with an obscure error.

Frame: REP 103, metres, z up, one frame per house (``map``).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any, Iterator

from ravh_sim.errors import FileFieldError, UnknownNameError
from ravh_sim.paths import HOUSES_DIR
from ravh_sim.world.geometry import Polygon, point_in_polygon, polygon_area

HOUSE_FORMAT = "ravh_sim/house@1"
LIGHT_KINDS = ("ceiling", "lamp", "wall")
WALL_KINDS = ("wall", "lintel", "column")

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Room:
    id: str
    type: str
    name: str
    floor: Polygon                 # counter-clockwise outline, not closed
    extra_floors: tuple[Polygon, ...]
    floor_z: float
    ceiling_z: float

    @property
    def area(self) -> float:
        return polygon_area(self.floor) + sum(polygon_area(p) for p in self.extra_floors)

    def contains(self, x: float, y: float) -> bool:
        return point_in_polygon(x, y, self.floor) or any(
            point_in_polygon(x, y, p) for p in self.extra_floors)


@dataclass(frozen=True)
class Wall:
    a: Vec2
    b: Vec2
    thickness: float
    z0: float
    z1: float
    room: str
    kind: str                      # wall | lintel | column

    @property
    def length(self) -> float:
        return math.dist(self.a, self.b)


@dataclass(frozen=True)
class Door:
    id: str                        # also the id of its labelled object
    position: Vec3                 # frame box centre
    yaw: float                     # direction of the door's width
    width: float
    height: float
    thickness: float
    leaf: Vec3                     # leaf width, thickness, height
    rooms: tuple[str, ...]         # one or two rooms (one: the entrance door)
    default_open: bool


@dataclass(frozen=True)
class Window:
    id: str
    position: Vec3
    yaw: float
    width: float
    height: float
    thickness: float
    room: str


@dataclass(frozen=True)
class Light:
    id: str                        # also the id of its labelled object
    kind: str                      # ceiling | lamp | wall
    position: Vec3
    intensity: float
    range: float
    color: Vec3
    room: str


@dataclass(frozen=True)
class ModelBox:
    """The box of one model variant of an object (same yaw as the object)."""
    position: Vec3
    size: Vec3


@dataclass(frozen=True)
class HouseObject:
    id: str                        # <first tag>_<n>, unique in the house
    type: str                      # first tag: the object category
    tags: tuple[str, ...]
    room: str
    prefab: str
    position: Vec3                 # box centre of the default model
    yaw: float
    size: Vec3
    size_estimated: bool           # upstream had no geometry; size is a per-type default
    models: tuple[ModelBox, ...]   # one per upstream model variant
    default_model: int
    inherits_model_from: str | None

    def box(self, model: int | None) -> ModelBox:
        """The box of model variant ``model`` (variants beyond upstream's use the default box)."""
        if model is None or model >= len(self.models):
            return self.models[self.default_model]
        return self.models[model]


@dataclass(frozen=True)
class Station:
    position: Vec3
    yaw: float                     # the robot's start heading
    object_id: str


@dataclass(frozen=True)
class House:
    number: int
    rooms: tuple[Room, ...]
    walls: tuple[Wall, ...]
    doors: tuple[Door, ...]
    windows: tuple[Window, ...]
    lights: tuple[Light, ...]
    objects: tuple[HouseObject, ...]
    station: Station
    source: dict[str, Any] = field(default_factory=dict, compare=False)

    @cached_property
    def room_by_id(self) -> dict[str, Room]:
        return {r.id: r for r in self.rooms}

    @cached_property
    def object_by_id(self) -> dict[str, HouseObject]:
        return {o.id: o for o in self.objects}

    @cached_property
    def door_by_id(self) -> dict[str, Door]:
        return {d.id: d for d in self.doors}

    @cached_property
    def light_by_id(self) -> dict[str, Light]:
        return {lt.id: lt for lt in self.lights}

    def room(self, room_id: str) -> Room:
        try:
            return self.room_by_id[room_id]
        except KeyError:
            raise UnknownNameError("room", room_id, list(self.room_by_id)) from None

    def object(self, object_id: str) -> HouseObject:
        try:
            return self.object_by_id[object_id]
        except KeyError:
            raise UnknownNameError("object", object_id, list(self.object_by_id)) from None

    def room_at(self, x: float, y: float) -> Room | None:
        """The room whose floor contains (x, y); None outside every room."""
        for room in self.rooms:
            if room.contains(x, y):
                return room
        return None

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of every floor and wall."""
        xs = [p[0] for r in self.rooms for poly in (r.floor, *r.extra_floors) for p in poly]
        ys = [p[1] for r in self.rooms for poly in (r.floor, *r.extra_floors) for p in poly]
        for w in self.walls:
            xs += [w.a[0], w.b[0]]
            ys += [w.a[1], w.b[1]]
        return min(xs), min(ys), max(xs), max(ys)

    def objects_in_room(self, room_id: str) -> Iterator[HouseObject]:
        self.room(room_id)
        return (o for o in self.objects if o.room == room_id)


# --------------------------------------------------------------------------- loading

def house_path(number: int, houses_dir: Path = HOUSES_DIR) -> Path:
    return houses_dir / f"house{number:02d}.json"


def available_houses(houses_dir: Path = HOUSES_DIR) -> list[int]:
    return sorted(int(p.stem[5:]) for p in houses_dir.glob("house[0-9][0-9].json"))


def load_house(house: int | str | Path, houses_dir: Path = HOUSES_DIR) -> House:
    """Load a house by number (1..30) or by file path; errors name the file and field."""
    if isinstance(house, Path) or (isinstance(house, str) and not house.isdigit()):
        path = Path(house)
    else:
        number = int(house)
        path = house_path(number, houses_dir)
        if not path.exists():
            raise UnknownNameError("house", number, available_houses(houses_dir))
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise FileFieldError(path, f"line {e.lineno} column {e.colno}", f"invalid JSON: {e.msg}") from None
    except OSError as e:
        raise FileFieldError(path, "-", f"cannot read: {e.strerror}") from None
    return house_from_dict(data, str(path))


def house_from_dict(data: Any, source: str) -> House:
    """Build a :class:`House` from its JSON form, validating every field."""
    root = _Fields(data, source, "")
    fmt = root.str("format")
    if fmt != HOUSE_FORMAT:
        root.fail("format", f"expected {HOUSE_FORMAT!r}, got {fmt!r}")
    rooms = tuple(_room(f) for f in root.items("rooms"))
    room_ids = [r.id for r in rooms]
    _unique(root, "rooms", room_ids)
    walls = tuple(_wall(f, room_ids) for f in root.items("walls"))
    objects = tuple(_object(f, room_ids) for f in root.items("objects"))
    object_ids = [o.id for o in objects]
    _unique(root, "objects", object_ids)
    for i, obj in enumerate(objects):
        if obj.inherits_model_from is not None and obj.inherits_model_from not in object_ids:
            root.fail(f"objects[{i}].inherits_model_from", f"unknown object {obj.inherits_model_from!r}")
    doors = tuple(_door(f, room_ids, object_ids) for f in root.items("doors"))
    windows = tuple(_window(f, room_ids, object_ids) for f in root.items("windows"))
    lights = tuple(_light(f, room_ids, object_ids) for f in root.items("lights"))
    st = root.sub("station")
    station = Station(st.vec("position", 3), st.num("yaw"), st.ref("object_id", object_ids))
    return House(number=root.int("house"), rooms=rooms, walls=walls, doors=doors, windows=windows,
                 lights=lights, objects=objects, station=station,
                 source=root.get("source", {}))


def _room(f: _Fields) -> Room:
    return Room(id=f.str("id"), type=f.str("type"), name=f.str("name"), floor=f.polygon("floor"),
                extra_floors=tuple(f.polygon(f"extra_floors[{i}]", v)
                                   for i, v in enumerate(f.list("extra_floors", []))),
                floor_z=f.num("floor_z"), ceiling_z=f.num("ceiling_z"))


def _wall(f: _Fields, rooms: list[str]) -> Wall:
    return Wall(a=f.vec("a", 2), b=f.vec("b", 2), thickness=f.positive("thickness"),
                z0=f.num("z0"), z1=f.num("z1"), room=f.ref("room", rooms),
                kind=f.choice("kind", WALL_KINDS))


def _door(f: _Fields, rooms: list[str], objects: list[str]) -> Door:
    door_rooms = tuple(f.ref(f"rooms[{i}]", rooms, v) for i, v in enumerate(f.list("rooms")))
    if not 1 <= len(door_rooms) <= 2:
        f.fail("rooms", f"a door joins one or two rooms, got {len(door_rooms)}")
    return Door(id=f.ref("id", objects), position=f.vec("position", 3), yaw=f.num("yaw"),
                width=f.positive("width"), height=f.positive("height"),
                thickness=f.positive("thickness"), leaf=f.vec("leaf", 3, positive=True),
                rooms=door_rooms, default_open=f.bool("default_open"))


def _window(f: _Fields, rooms: list[str], objects: list[str]) -> Window:
    return Window(id=f.ref("id", objects), position=f.vec("position", 3), yaw=f.num("yaw"),
                  width=f.positive("width"), height=f.positive("height"),
                  thickness=f.positive("thickness"), room=f.ref("room", rooms))


def _light(f: _Fields, rooms: list[str], objects: list[str]) -> Light:
    return Light(id=f.ref("id", objects), kind=f.choice("kind", LIGHT_KINDS),
                 position=f.vec("position", 3), intensity=f.nonnegative("intensity"),
                 range=f.positive("range"), color=f.vec("color", 3), room=f.ref("room", rooms))


def _object(f: _Fields, rooms: list[str]) -> HouseObject:
    tags = tuple(f.str(f"tags[{i}]", v) for i, v in enumerate(f.list("tags")))
    if not tags:
        f.fail("tags", "an object needs at least one tag")
    models = tuple(ModelBox(m.vec("position", 3), m.vec("size", 3, positive=True))
                   for m in f.items("models"))
    if not models:
        f.fail("models", "an object needs at least one model box")
    default = f.int("default_model")
    if not 0 <= default < len(models):
        f.fail("default_model", f"must index models (0..{len(models) - 1}), got {default}")
    obj_type = f.str("type")
    if obj_type != tags[0]:
        f.fail("type", f"must equal the first tag {tags[0]!r}, got {obj_type!r}")
    inherits = f.get("inherits_model_from")
    return HouseObject(id=f.str("id"), type=obj_type, tags=tags, room=f.ref("room", rooms),
                       prefab=f.str("prefab"), position=models[default].position, yaw=f.num("yaw"),
                       size=models[default].size, size_estimated=f.bool("size_estimated"),
                       models=models, default_model=default,
                       inherits_model_from=None if inherits is None else f.str("inherits_model_from"))


def _unique(root: _Fields, name: str, ids: list[str]) -> None:
    seen: set[str] = set()
    for i, x in enumerate(ids):
        if x in seen:
            root.fail(f"{name}[{i}].id", f"duplicate id {x!r}")
        seen.add(x)


class _Fields:
    """Typed access to one JSON object that reports bad fields as ``file: path.to.field: problem``."""

    def __init__(self, data: Any, source: str, path: str) -> None:
        self.source, self.path = source, path
        if not isinstance(data, dict):
            raise FileFieldError(source, path or "(top level)", f"expected an object, got {_kind(data)}")
        self.data = data

    def fail(self, key: str, problem: str) -> None:
        raise FileFieldError(self.source, self._at(key), problem)

    def _at(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def get(self, key: str, default: Any = None) -> Any:
        return self.data.get(key, default)

    def _need(self, key: str) -> Any:
        if key not in self.data:
            self.fail(key, "missing")
        return self.data[key]

    def sub(self, key: str) -> _Fields:
        return _Fields(self._need(key), self.source, self._at(key))

    def list(self, key: str, default: list | None = None) -> list:
        value = self.data.get(key, default) if default is not None else self._need(key)
        if not isinstance(value, list):
            self.fail(key, f"expected a list, got {_kind(value)}")
        return value

    def items(self, key: str) -> Iterator[_Fields]:
        for i, v in enumerate(self.list(key)):
            yield _Fields(v, self.source, self._at(f"{key}[{i}]"))

    def str(self, key: str, value: Any = None) -> str:
        value = self._need(key) if value is None else value
        if not isinstance(value, str) or not value:
            self.fail(key, f"expected a non-empty string, got {_kind(value)}")
        return value

    def bool(self, key: str) -> bool:
        value = self._need(key)
        if not isinstance(value, bool):
            self.fail(key, f"expected true or false, got {_kind(value)}")
        return value

    def int(self, key: str) -> int:
        value = self._need(key)
        if not isinstance(value, int) or isinstance(value, bool):
            self.fail(key, f"expected an integer, got {_kind(value)}")
        return value

    def num(self, key: str, value: Any = None) -> float:
        value = self._need(key) if value is None else value
        if not _is_number(value):
            self.fail(key, f"expected a finite number, got {_kind(value)}")
        return float(value)

    def positive(self, key: str) -> float:
        value = self.num(key)
        if value <= 0:
            self.fail(key, f"must be > 0, got {value}")
        return value

    def nonnegative(self, key: str) -> float:
        value = self.num(key)
        if value < 0:
            self.fail(key, f"must be >= 0, got {value}")
        return value

    def choice(self, key: str, options: tuple[str, ...]) -> str:
        value = self.str(key)
        if value not in options:
            self.fail(key, f"must be one of {', '.join(options)}, got {value!r}")
        return value

    def ref(self, key: str, valid: list[str], value: Any = None) -> str:
        value = self.str(key, value)
        if value not in valid:
            self.fail(key, f"unknown id {value!r}")
        return value

    def vec(self, key: str, n: int, value: Any = None, positive: bool = False) -> tuple:
        value = self._need(key) if value is None else value
        if not (isinstance(value, list) and len(value) == n and all(_is_number(v) for v in value)):
            self.fail(key, f"expected {n} finite numbers, got {_kind(value)}")
        if positive and min(value) <= 0:
            self.fail(key, f"every component must be > 0, got {value}")
        return tuple(float(v) for v in value)

    def polygon(self, key: str, value: Any = None) -> Polygon:
        value = self._need(key) if value is None else value
        if not isinstance(value, list) or len(value) < 3:
            self.fail(key, f"expected a polygon of at least 3 points, got {_kind(value)}")
        return tuple(self.vec(f"{key}[{i}]", 2, p) for i, p in enumerate(value))


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _kind(v: Any) -> str:
    text = json.dumps(v) if not isinstance(v, float) or math.isfinite(v) else str(v)
    return text if len(text) <= 40 else text[:37] + "..."
