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
import os
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, Field, model_validator

from ravh_sim.errors import FileFieldError, UnknownNameError, UserError
from ravh_sim.paths import HOUSES_DIR, user_houses_dir
from ravh_sim.schema import Strict, number, read_text, shown, validate, vector
from ravh_sim.world.geometry import Polygon, distance_to_polygon, point_in_polygon, polygon_area, self_intersection
from ravh_sim.world.paints import is_paint

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
    paint: tuple[tuple[str, str], ...] = ()    # the room's own paint by surface (an imported home's colours)

    def own_paint(self, surface: str) -> str | None:
        """The paint the house file gives this room's ``surface`` (walls, floor), or None."""
        return dict(self.paint).get(surface)

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
    own_model: Path | None = None  # the house's own model (variant 0), an npz beside the house file

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
    name: str = ""                 # an imported home's name (``ravh import-home``); "" for the shipped houses
    attribution: str = field(default="", compare=False)

    @property
    def title(self) -> str:
        """How messages name the house: ``house 15``, or an imported home's name."""
        return self.name or f"house {self.number}"

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

    def room_at_or_raise(self, x: float, y: float) -> Room:
        """The room at (x, y); outside every room a UserError names the nearest one."""
        if not (math.isfinite(x) and math.isfinite(y)):
            raise UserError(f"({x}, {y}) is not a finite position")
        room = self.room_at(x, y)
        if room is None:
            raise UserError(f"({x:.3g}, {y:.3g}) is outside every room of house {self.number}; "
                            f"nearest room: {self.nearest_room(x, y).id}")
        return room

    def nearest_room(self, x: float, y: float) -> Room:
        """The room whose floor outline is closest to (x, y) (for errors about points outside)."""
        return min(self.rooms, key=lambda r: min(distance_to_polygon(x, y, p)
                                                 for p in (r.floor, *r.extra_floors)))

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


def imported_houses() -> dict[str, Path]:
    """The homes ``ravh import-home`` wrote into the user's folder, by name."""
    folder = user_houses_dir()
    return {p.stem: p for p in sorted(folder.glob("*.json"))} if folder.is_dir() else {}


def resolve_house(house: int | str | Path, houses_dir: Path = HOUSES_DIR) -> Path:
    """The house file a HOUSE argument names: a number (a shipped house, else an imported home of that
    number), an imported home's name, or the path of a house file. Every command resolves here."""
    if isinstance(house, Path):
        return house
    text = str(house).strip()
    if text.isdigit():
        path = house_path(int(text), houses_dir)
        if path.exists():
            return path
        numbered = {_number_of(p): p for p in imported_houses().values()}
        if int(text) in numbered:
            return numbered[int(text)]
    elif "/" in text or os.sep in text or text.endswith(".json"):
        return Path(text).expanduser()
    elif text in imported_houses():
        return imported_houses()[text]
    raise UnknownNameError("house", int(text) if text.isdigit() else text,
                           [*available_houses(houses_dir), *imported_houses()])


def _number_of(path: Path) -> int | None:
    """The ``house`` number of a house file, without validating the rest (None: unreadable)."""
    try:
        number = json.loads(read_text(path, "house file", MAX_HOUSE_BYTES)).get("house")
    except (UserError, ValueError, AttributeError, RecursionError):
        return None
    return number if isinstance(number, int) else None


def load_house(house: int | str | Path, houses_dir: Path = HOUSES_DIR) -> House:
    """Load a house by number, imported home's name or file path (:func:`resolve_house`); errors name
    the file and field."""
    path = resolve_house(house, houses_dir)
    text = read_text(path, "house file", MAX_HOUSE_BYTES)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise FileFieldError(path, f"line {e.lineno} column {e.colno}", f"invalid JSON: {e.msg}") from None
    except RecursionError:
        raise FileFieldError(path, "(top level)", "nested too deeply") from None
    loaded = house_from_dict(data, str(path))
    named = re.fullmatch(r"house(\d\d)\.json", path.name)
    if named and int(named[1]) != loaded.number:
        raise FileFieldError(path, "house", f"{loaded.number} disagrees with the file name {path.name}")
    return loaded


def house_number(house: int | str | Path, houses_dir: Path = HOUSES_DIR) -> int:
    """The number of the house a HOUSE argument names, for what keys houses by number (a dataset
    build's folders and seeds, the evaluations, the benches). The file is loaded (a bad one fails
    here), and a house file outside both folders is refused: its number would not find it again."""
    loaded = load_house(house, houses_dir)
    try:
        found = resolve_house(loaded.number, houses_dir)
    except UnknownNameError:
        found = None
    if found is None or found.resolve() != resolve_house(house, houses_dir).resolve():
        raise UserError(f"{house}: this command takes a house by number or by an imported home's name; "
                        f"import a home with 'ravh import-home' first")
    return loaded.number


def house_numbers(houses_dir: Path = HOUSES_DIR) -> list[int]:
    """The numbers of every house: the shipped ones and the imported homes'."""
    imported = (_number_of(p) for p in imported_houses().values())
    return sorted({*available_houses(houses_dir), *(n for n in imported if n is not None)})


# bounds that no real house comes near, so a unit or typing slip (1e12, 1e30) is refused at load
EXTENT = 1000.0            # m, |coordinate|
SIZE = 100.0               # m, any object, door or window dimension
Coord = number(ge=-EXTENT, le=EXTENT)
Size = number(gt=0.0, le=SIZE)
Yaw = number(ge=-4 * math.pi, le=4 * math.pi)
# no control characters: ids end up in logs, terminals, topic names and file names
Id = Annotated[str, Field(min_length=1, max_length=200, pattern=r"^[^\x00-\x1f\x7f]+$")]
# what the geometry may cost: the shipped houses have at most 42 floor vertices, 158 objects, 14 rooms,
# 27 lights and 3 m rooms; a 10,000-vertex floor or 80,000 objects took minutes to build
MAX_HOUSE_BYTES = 4 << 20
MAX_OUTLINE = 256          # vertices of one floor outline
MAX_ROOM_HEIGHT = 10.0     # m, ceiling above floor
MAX_ITEMS = {"rooms": 200, "walls": 5000, "doors": 500, "windows": 500, "lights": 1000, "objects": 2000}
PLAN_MARGIN = 1.0          # m: objects, doors, windows, lights and walls stay this close to the floor plan
P2 = vector(Coord, 2)
P3 = vector(Coord, 3)


def _not_a_number(name: str) -> str:
    if name.isdigit():
        raise ValueError("a name must not be all digits (digits name a house by number)")
    return name


def _inside(path: str) -> str:
    if ".." in path.split("/"):
        raise ValueError("must stay in the house file's folder (no '..')")
    return path


# an imported home's name: lower case, not all digits
HouseName = Annotated[str, Field(min_length=1, max_length=60, pattern=r"^[a-z0-9][a-z0-9_-]*$"),
                      AfterValidator(_not_a_number)]
# an object's own model: an npz in a folder beside the house file (relative, no '..')
ModelFile = Annotated[str, Field(max_length=200, pattern=r"^[A-Za-z0-9_-][A-Za-z0-9_./-]*\.npz$"),
                      AfterValidator(_inside)]


MIN_FLOOR_AREA = 1e-4      # m^2


def _simple_polygon(points: list) -> list:
    if polygon_area(tuple(points)) < MIN_FLOOR_AREA:
        raise ValueError(f"zero-area floor (below {MIN_FLOOR_AREA} m^2)")
    crossing = self_intersection(tuple(points))
    if crossing:
        raise ValueError(f"self-intersecting outline (edges {crossing[0]} and {crossing[1]} meet)")
    return points


FloorOutline = Annotated[list[P2], Field(min_length=3, max_length=MAX_OUTLINE), AfterValidator(_simple_polygon)]


def _paint(value: str) -> str:
    if not is_paint(value):
        raise ValueError(f"not a paint (a name of ravh_sim/world/paints.py or #rrggbb): {shown(value)}")
    return value


class _RoomPaint(Strict):
    walls: Annotated[str, AfterValidator(_paint)] | None = None
    floor: Annotated[str, AfterValidator(_paint)] | None = None


class _Room(Strict):
    id: Id
    type: Id
    name: Id
    floor: FloorOutline
    extra_floors: Annotated[list[FloorOutline], Field(max_length=16)] = []
    floor_z: Coord
    ceiling_z: Coord
    paint: _RoomPaint | None = None

    @model_validator(mode="after")
    def _ceiling_above_floor(self) -> _Room:
        if float(self.ceiling_z) <= float(self.floor_z):      # float(): mypy cannot read Coord as a type
            raise ValueError(f"ceiling_z {self.ceiling_z} must be above floor_z {self.floor_z}")
        if float(self.ceiling_z) - float(self.floor_z) > MAX_ROOM_HEIGHT:
            raise ValueError(f"ceiling_z {self.ceiling_z} is more than {MAX_ROOM_HEIGHT:g} m above "
                             f"floor_z {self.floor_z}")
        return self


class _Wall(Strict):
    room: Id
    kind: Literal[WALL_KINDS]
    a: P2
    b: P2
    thickness: Size
    z0: Coord
    z1: Coord

    @model_validator(mode="after")
    def _proper(self) -> _Wall:
        if math.dist(self.a, self.b) < 1e-6:
            raise ValueError("zero-length wall (a == b)")
        if float(self.z1) <= float(self.z0):
            raise ValueError(f"z1 {self.z1} must be above z0 {self.z0}")
        return self


class _Door(Strict):
    id: Id
    rooms: Annotated[list[Id], Field(min_length=1, max_length=2)]
    position: P3
    yaw: Yaw
    width: Size
    height: Size
    thickness: Size
    leaf: vector(Size, 3)
    default_open: bool


class _Window(Strict):
    id: Id
    room: Id
    position: P3
    yaw: Yaw
    width: Size
    height: Size
    thickness: Size


Channel = number(ge=0.0, le=1.0)


class _Light(Strict):
    id: Id
    kind: Literal[LIGHT_KINDS]
    room: Id
    position: P3
    intensity: number(ge=0.0, le=100.0)
    range: number(gt=0.0, le=EXTENT)
    color: vector(Channel, 3)


class _ModelBox(Strict):
    position: P3
    size: vector(Size, 3)


class _Object(Strict):
    id: Id
    type: Id
    tags: Annotated[list[Id], Field(min_length=1, max_length=32)]
    room: Id
    prefab: Id
    yaw: Yaw
    size_estimated: bool
    default_model: Annotated[int, Field(ge=0)]
    models: Annotated[list[_ModelBox], Field(min_length=1, max_length=16)]
    inherits_model_from: Id | None = None
    model_file: ModelFile | None = None

    @model_validator(mode="after")
    def _consistent(self) -> _Object:
        if self.default_model >= len(self.models):
            raise ValueError(f"default_model must index models (0..{len(self.models) - 1}), "
                             f"got {self.default_model}")
        if self.type != self.tags[0]:
            raise ValueError(f"type must equal the first tag {self.tags[0]!r}, got {self.type!r}")
        return self


class _Station(Strict):
    position: P3
    yaw: Yaw
    object_id: Id


class HouseFile(Strict):
    """The schema of a house file (houses/README.md); cross-references are checked after it."""
    format: Literal[HOUSE_FORMAT]
    house: Annotated[int, Field(ge=1, le=99)]
    name: HouseName | None = None
    attribution: str = ""
    source: dict[str, str] = {}
    station: _Station
    rooms: Annotated[list[_Room], Field(min_length=1, max_length=MAX_ITEMS["rooms"])]
    walls: Annotated[list[_Wall], Field(min_length=1, max_length=MAX_ITEMS["walls"])]
    doors: Annotated[list[_Door], Field(max_length=MAX_ITEMS["doors"])]
    windows: Annotated[list[_Window], Field(max_length=MAX_ITEMS["windows"])]
    lights: Annotated[list[_Light], Field(max_length=MAX_ITEMS["lights"])]
    objects: Annotated[list[_Object], Field(max_length=MAX_ITEMS["objects"])]


def house_from_dict(data: Any, source: str) -> House:
    """Build a :class:`House` from its JSON form: the schema checks every field, then the ids."""
    f = validate(HouseFile, data, source)
    room_ids = _unique(source, "rooms", [r.id for r in f.rooms])
    object_ids = _unique(source, "objects", [o.id for o in f.objects])
    for kind in ("doors", "windows", "lights"):
        _unique(source, kind, [item.id for item in getattr(f, kind)])
    _distinct_floors(source, f.rooms)
    _on_the_plan(source, f)
    refs = _References(source, room_ids, object_ids)
    for i, w in enumerate(f.walls):
        refs.room(f"walls[{i}].room", w.room)
    for i, o in enumerate(f.objects):
        refs.room(f"objects[{i}].room", o.room)
        if o.inherits_model_from is not None:
            refs.object(f"objects[{i}].inherits_model_from", o.inherits_model_from)
    for i, d in enumerate(f.doors):
        refs.object(f"doors[{i}].id", d.id)
        for j, r in enumerate(d.rooms):
            refs.room(f"doors[{i}].rooms[{j}]", r)
    placed: dict[str, Sequence[_Window | _Light]] = {"windows": f.windows, "lights": f.lights}
    for kind, items in placed.items():
        for i, item in enumerate(items):
            refs.object(f"{kind}[{i}].id", item.id)
            refs.room(f"{kind}[{i}].room", item.room)
    refs.object("station.object_id", f.station.object_id)
    rooms = tuple(Room(r.id, r.type, r.name, _poly(r.floor), tuple(_poly(p) for p in r.extra_floors),
                       r.floor_z, r.ceiling_z,
                       tuple((k, v) for k, v in (r.paint.model_dump() if r.paint else {}).items() if v))
                  for r in f.rooms)
    folder = Path(source).parent
    house = House(
        number=f.house, rooms=rooms,
        walls=tuple(Wall(w.a, w.b, w.thickness, w.z0, w.z1, w.room, w.kind) for w in f.walls),
        doors=tuple(Door(d.id, d.position, d.yaw, d.width, d.height, d.thickness, d.leaf, tuple(d.rooms),
                         d.default_open) for d in f.doors),
        windows=tuple(Window(w.id, w.position, w.yaw, w.width, w.height, w.thickness, w.room)
                      for w in f.windows),
        lights=tuple(Light(lt.id, lt.kind, lt.position, lt.intensity, lt.range, lt.color, lt.room)
                     for lt in f.lights),
        objects=tuple(_object(o, source, i, folder) for i, o in enumerate(f.objects)),
        station=Station(f.station.position, f.station.yaw, f.station.object_id),
        source=dict(f.source), name=f.name or "", attribution=f.attribution)
    x, y, _ = house.station.position
    if house.room_at(x, y) is None:
        raise FileFieldError(source, "station.position", "outside every room")
    return house


def _distinct_floors(source: str, rooms: Sequence[_Room]) -> None:
    """Two rooms on one floor outline are a copy-paste slip (room_at could answer either)."""
    seen: dict[frozenset, str] = {}
    for i, r in enumerate(rooms):
        key = frozenset((round(x, 3), round(y, 3)) for x, y in map(_xy, r.floor))
        if key in seen:
            raise FileFieldError(source, f"rooms[{i}].floor", f"the same outline as room {seen[key]!r}")
        seen[key] = r.id


def _on_the_plan(source: str, f: HouseFile) -> None:
    """Objects (every model box), doors, windows, lights and walls lie on the floor plan's bounding box
    grown by PLAN_MARGIN: something hundreds of metres away, or a box covering the house, is a slip."""
    points = [p for r in f.rooms for outline in (r.floor, *r.extra_floors) for p in outline]
    lo = (min(p[0] for p in points) - PLAN_MARGIN, min(p[1] for p in points) - PLAN_MARGIN)
    hi = (max(p[0] for p in points) + PLAN_MARGIN, max(p[1] for p in points) + PLAN_MARGIN)

    def check(field_path: str, x: float, y: float, half_x: float = 0.0, half_y: float = 0.0) -> None:
        if x - half_x < lo[0] or x + half_x > hi[0] or y - half_y < lo[1] or y + half_y > hi[1]:
            raise FileFieldError(source, field_path, f"outside the house: beyond its floor plan "
                                 f"({lo[0]:.1f}..{hi[0]:.1f}, {lo[1]:.1f}..{hi[1]:.1f} m with the margin)")
    for i, o in enumerate(f.objects):
        c, s = abs(math.cos(o.yaw)), abs(math.sin(o.yaw))
        for j, m in enumerate(o.models):
            (x, y), (sx, sy) = _xy(m.position), _xy(m.size)
            check(f"objects[{i}].models[{j}]", x, y, (c * sx + s * sy) / 2, (s * sx + c * sy) / 2)
    placed: dict[str, Sequence[_Door | _Window | _Light]] = {"doors": f.doors, "windows": f.windows,
                                                              "lights": f.lights}
    for kind, items in placed.items():
        for i, item in enumerate(items):
            check(f"{kind}[{i}].position", *_xy(item.position))
    for i, w in enumerate(f.walls):
        check(f"walls[{i}].a", *_xy(w.a))
        check(f"walls[{i}].b", *_xy(w.b))


def _xy(point: Any) -> tuple[float, float]:
    """x, y of a validated point or size (the schema's tuple types are built at run time)."""
    return float(point[0]), float(point[1])


def _poly(points: list) -> Polygon:
    return tuple(tuple(p) for p in points)


def _object(o: _Object, source: str, index: int, folder: Path) -> HouseObject:
    models = tuple(ModelBox(m.position, m.size) for m in o.models)
    default = models[o.default_model]
    own = None
    if o.model_file is not None:
        own = folder / o.model_file
        if not own.is_file():
            raise FileFieldError(source, f"objects[{index}].model_file", f"no such file: {own}")
    return HouseObject(id=o.id, type=o.type, tags=tuple(o.tags), room=o.room, prefab=o.prefab,
                       position=default.position, yaw=o.yaw, size=default.size,
                       size_estimated=o.size_estimated, models=models, default_model=o.default_model,
                       inherits_model_from=o.inherits_model_from, own_model=own)


def _unique(source: str, name: str, ids: list[str]) -> set[str]:
    seen: set[str] = set()
    for i, x in enumerate(ids):
        if x in seen:
            raise FileFieldError(source, f"{name}[{i}].id", f"duplicate id {x!r}")
        seen.add(x)
    return seen


class _References:
    """Checks that room and object ids used across the file exist."""

    def __init__(self, source: str, rooms: set[str], objects: set[str]) -> None:
        self.source, self.rooms, self.objects = source, rooms, objects

    def room(self, field_path: str, value: str) -> None:
        if value not in self.rooms:
            raise FileFieldError(self.source, field_path, f"unknown room id {shown(value)}")

    def object(self, field_path: str, value: str) -> None:
        if value not in self.objects:
            raise FileFieldError(self.source, field_path, f"unknown object id {shown(value)}")
