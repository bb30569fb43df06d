"""``ravh import-home FILE.sh3d``: a Sweet Home 3D home as a house of ours.

Why: people draw their own flat or lab in Sweet Home 3D; this turns the drawing into a house file (the
schema of ``houses/README.md``, validated by :func:`ravh_sim.world.house.house_from_dict`) that every
command takes by name, number or path, with the home's own models beside it.

What the drawing says, kept (lengths cm -> m; Sweet Home 3D's plan has y pointing down, ours is REP 103,
so y = -y and angles turn the other way):

- walls: centre line, thickness, height (the wall's, else the level's, else the home's; a sloping wall
  takes its higher end; an arc becomes straight pieces), split at every door into the pieces beside it
  and a lintel above; each piece belongs to the room on its left side (else its right, else the nearest);
- rooms: their polygons and names; the type from the name in any of Sweet Home 3D's languages, else
  from the furniture in it (:mod:`ravh_sim.importers.room_types`); floor colour and the colour of the
  wall sides facing the room become the room's own paint;
- doors and windows (``doorOrWindow``): a door where the name says door or the opening reaches the
  floor and is walkable (at most :data:`DOOR_SILL` above it, at least :data:`DOOR_HEIGHT` tall), else a
  window (the wall gets a real opening there; the home's model fills it). Doors get our leaf, open by
  default except the entrance (one room), so the appearance service opens and closes them;
- furniture: our type from the name with the furniture importer's rules (:data:`NAME_RULES`, then
  :data:`ravh_sim.importers.furniture.RULES`), else the generic type :data:`GENERIC` labelled with its
  name, never dropped; the home's own model, colours, textures and mirroring as model variant 0
  (:mod:`ravh_sim.importers.home_models`); furniture groups are flattened;
- lights: ceiling lights (reaching within :data:`CEILING_GAP` of the ceiling), wall lights (above
  :data:`WALL_LIGHT_Z`) or lamps, intensity from ``power``, colour from the light source;
- levels: one per import (default the lowest with rooms), its floor at z = 0; all are listed;
- attribution: author, copyright and licence (Home.xml properties) in ``attribution`` and ``source``;
- the robot's start (a Station object): the free spot furthest from furniture and walls in the largest
  living area (or the largest room).

Pieces the plan cannot hold (outside the floor plan by more than the house schema allows) and hidden
pieces are left out and counted in the summary.
"""
from __future__ import annotations

import math
import re
import time
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any
from xml.etree.ElementTree import Element

import numpy as np
import shapely
from shapely.geometry import Point
from shapely.geometry import Polygon as ShapelyPolygon
from shapely.ops import nearest_points

from ravh_sim.errors import FileFieldError, UnknownNameError, UserError
from ravh_sim.importers.furniture import RULES
from ravh_sim.importers.home_models import Described, Look, model_id, write_model
from ravh_sim.importers.houses import dump_house
from ravh_sim.importers.room_types import room_type
from ravh_sim.importers.sh3d_archive import Sh3dArchive
from ravh_sim.world.house import HOUSE_FORMAT, MAX_ITEMS, MAX_OUTLINE, PLAN_MARGIN, house_from_dict
from ravh_sim.world.library import kind_of

GENERIC = "Furniture"
DOOR_SILL = 0.15            # m
DOOR_HEIGHT = 1.8           # m
CEILING_GAP = 0.35          # m
WALL_LIGHT_Z = 1.2          # m: a light whose bottom is this high and not at the ceiling hangs on a wall
MIN_SIZE = 0.005            # m: a piece's smallest extent (a rug drawn 0 cm tall)
MAX_CM = 1e6                # |coordinate| or size in cm: 10 km
ARC_STEP = math.pi / 12     # rad of an arc wall per straight piece
ROBOT_CLEARANCE = 0.45      # m from furniture and walls the start should keep
LIVING_TYPES = ("LivingRoom", "KitchenLivingRoom")
VIEW_NUDGE = 0.5            # m: a stored view this close outside every room is moved into the nearest
FIRST_NUMBER = 31           # imported homes are numbered after the 30 shipped houses
DOOR_WORDS = re.compile(r"door|porte|puerta|t[uü]r\b|tür|porta|deur|drzwi|dveř", re.IGNORECASE)
_CLASS_WORDS = {"office": "office", "small": "small", "tv": "tv", "vase": "vase", "corner_upper": "corner up",
                "corner": "corner", "upper": "up", "sink": "sink", "stove": "oven"}
NAME_RULES: tuple[tuple[str, str], ...] = (
    ("Bed", r"single bed|bunk bed|^bed\b|double bed"),
    ("WashingMachine", r"clothes washer|washing machine|lave-linge|waschmaschine|lavadora"),
    ("Refrigerator", r"fridge|refrigerator|r[ée]frig[ée]rateur|k[uü]hlschrank|nevera|frigor"),
    ("KitchenFurniture/stove", r"^cooker|^stove|cuisini[eè]re|^herd\b"),
    ("Decoration/vase", r"flowers|vase"),
    ("Drying", r"radiator|radiateur|heizk[oö]rper"),
)
"""Names the catalogue rules (which also filter by catalogue category, unknown in a home) miss."""


@dataclass
class Imported:
    """What one import wrote and found."""
    path: Path
    name: str
    number: int
    level: str
    levels: list[str]
    counts: dict[str, int]
    left_out: dict[str, int]
    views: list[tuple[str, float, float, float]]       # stored cameras: name, x, y, yaw (our frame)
    seconds: float = 0.0


@dataclass
class _Piece:
    element: Element
    where: str
    name: str
    x: float
    y: float                  # ours (north up)
    z0: float                 # bottom above the level's floor
    front: float              # heading of the piece's front (our yaw)
    width: float
    depth: float
    height: float


@dataclass
class _Segment:
    a: tuple[float, float]
    b: tuple[float, float]
    thickness: float
    z1: float
    left_colour: str | None
    right_colour: str | None
    cuts: list[tuple[float, float, float]] = field(default_factory=list)   # door (t0, t1, top)


def import_home(source: Path, out_dir: Path, name: str | None = None, level: str | None = None) -> Imported:
    """Import ``source`` into ``out_dir/<name>.json`` and its models into ``out_dir/<name>.models/``."""
    start = time.monotonic()
    source = Path(source)
    with Sh3dArchive(source) as archive:
        reader = _HomeReader(archive, name, level)
        house, models = reader.house(out_dir)
        out_dir.mkdir(parents=True, exist_ok=True)
        folder = out_dir / f"{reader.name}.models"
        folder.mkdir(exist_ok=True)
        written: dict[Look, str] = {}
        failed: Counter[str] = Counter()
        for obj, (look, size, described, where) in zip(house["objects"], models):
            if look is None:
                continue
            if look not in written:
                try:
                    written[look] = write_model(archive, look, size, described, folder,
                                                model_id(look, described.name), where)
                except (ValueError, IndexError, KeyError, UnicodeDecodeError) as e:
                    failed[f"{where}: model {look.entry!r} unreadable ({type(e).__name__}: {str(e)[:80]})"] += 1
                    written[look] = ""
            if written[look]:
                obj["model_file"] = f"{folder.name}/{written[look]}"
        house["house"] = _number(out_dir, reader.name)
        path = out_dir / f"{reader.name}.json"
        text = dump_house(house)
        house_from_dict(house, str(path))                       # what we write must load
        path.write_text(text)
    reader.left_out.update({k: v for k, v in failed.items()})
    return Imported(path, reader.name, house["house"], reader.level_name, reader.level_names,
                    dict(Counter(o["type"] for o in house["objects"])) | {
                        "rooms": len(house["rooms"]), "walls": len(house["walls"]), "doors": len(house["doors"]),
                        "windows": len(house["windows"]), "lights": len(house["lights"]),
                        "own models": len([v for v in written.values() if v])},
                    reader.left_out, reader.views(), time.monotonic() - start)


def _number(out_dir: Path, name: str) -> int:
    """The home's number: the one it had when imported before under this name, else the lowest free
    one from FIRST_NUMBER among the homes of ``out_dir``."""
    import json
    taken: dict[int, str] = {}
    for path in out_dir.glob("*.json"):
        try:
            number = json.loads(path.read_text()).get("house")
        except (OSError, ValueError, AttributeError):
            continue
        if isinstance(number, int):
            taken[number] = path.stem
    for number, stem in taken.items():
        if stem == name:
            return number
    free = next((n for n in range(FIRST_NUMBER, 100) if n not in taken), None)
    if free is None:
        raise UserError(f"{out_dir}: every house number {FIRST_NUMBER}..99 is taken; import into another --out")
    return free


def home_name(text: str) -> str:
    """A house name from free text: lower case letters, digits, '-' and '_', not all digits."""
    slug = re.sub(r"[^a-z0-9_-]+", "-", text.lower()).strip("-_")[:60]
    if not slug or slug.isdigit():
        slug = f"home-{slug}".strip("-")
    return slug


# ----------------------------------------------------------------------------------------- reading

class _HomeReader:
    """Home.xml of one level turned into the house file's records."""

    def __init__(self, archive: Sh3dArchive, name: str | None, level: str | None) -> None:
        self.archive, self.file = archive, archive.path
        self.root = archive.home()
        self.properties = {p.get("name", ""): p.get("value", "") for p in self.root.findall("property")}
        self.left_out: dict[str, int] = {}
        self._choose_level(level)
        base = name or (self.file.stem if level is None else f"{self.file.stem}-{self.level_name}")
        self.name = home_name(base)
        if name is not None and self.name != name:
            raise UserError(f"--name {name!r}: use lower case letters, digits, '-' and '_' (e.g. {self.name!r})")

    # -- levels
    def _choose_level(self, wanted: str | None) -> None:
        levels = [(e.get("id", ""), e.get("name", e.get("id", "")), self._num(e, "elevation", 0.0),
                   self._num(e, "height", 0.0), self._num(e, "elevationIndex", 0.0))
                  for e in self.root.findall("level")]
        levels.sort(key=lambda lv: (lv[2], lv[4]))
        self.level_names = [lv[1] for lv in levels]
        self.level_id: str | None = None
        self.level_name = ""
        self.level_span: tuple[float, float] | None = None      # cm above the ground (None: a single level)
        self.level_height = self._num(self.root, "wallHeight", 250.0) / 100
        if not levels:
            if wanted is not None:
                raise UserError(f"{self.file}: --level {wanted!r}: the home has a single level")
            return
        with_rooms = {r.get("level") for r in self.root.findall("room")}
        if wanted is None:
            chosen = next((lv for lv in levels if lv[0] in with_rooms), levels[0])
        else:
            matches = [lv for i, lv in enumerate(levels)
                       if wanted.lower() in (lv[0].lower(), lv[1].lower(), str(i))]
            if not matches:
                raise UnknownNameError("level", wanted, [lv[1] for lv in levels])
            chosen = matches[0]
        self.level_id, self.level_name = chosen[0], chosen[1]
        above = [lv[2] for lv in levels if lv[2] > chosen[2]]           # the next level up starts the next span
        self.level_span = (chosen[2], min(above) if above else math.inf)
        if chosen[3] > 0:
            self.level_height = chosen[3] / 100
        if chosen[0] not in with_rooms:
            raise UserError(f"{self.file}: level {chosen[1]!r} has no room; levels with rooms: "
                            + ", ".join(lv[1] for lv in levels if lv[0] in with_rooms))

    def _on_level(self, element: Element) -> bool:
        return self.level_id is None or element.get("level") == self.level_id

    # -- numbers
    def _where(self, element: Element) -> str:
        ident = element.get("id") or element.get("name") or ""
        return f"Home.xml <{element.tag}{f' id={ident!r}' if ident else ''}>"

    def _num(self, element: Element, attr: str, default: float | None = None) -> float:
        text = element.get(attr)
        if text is None:
            if default is None:
                raise FileFieldError(self.file, self._where(element), f"missing attribute {attr}")
            return default
        try:
            value = float(text)
        except ValueError:
            raise FileFieldError(self.file, self._where(element), f"{attr}={text[:40]!r} is not a number") from None
        if not math.isfinite(value) or abs(value) > MAX_CM:
            raise FileFieldError(self.file, self._where(element), f"{attr}={text[:40]!r} is out of range")
        return value

    def _bounded(self, elements: list[Element], limit: int, what: str) -> list[Element]:
        if len(elements) > limit:
            raise FileFieldError(self.file, f"Home.xml <{elements[0].tag}>", f"{len(elements)} {what}, over the "
                                 f"limit of {limit}")
        return elements

    # -- the house
    def house(self, out_dir: Path) -> tuple[dict[str, Any], list]:
        """The house record (number still 0) and, per object, what its own model needs."""
        walls = self._walls()
        rooms = self._rooms()
        if not rooms:
            raise FileFieldError(self.file, "Home.xml <room>", f"no room on level {self.level_name or '(only)'}: "
                                 "draw rooms (double-click inside walls in Sweet Home 3D)")
        pieces = list(self._pieces())
        self.room_polygons = [(r["id"], ShapelyPolygon(r["floor"])) for r in rooms]
        doors, door_objects, windows, window_objects = self._openings(pieces, walls)
        furniture, models, lights = self._furniture(pieces, rooms)
        objects = door_objects + window_objects + furniture
        all_models = [(None, None, None, "")] * (len(door_objects)) + self._window_models(pieces) + models
        self._type_rooms(rooms, objects)
        for door in doors:
            door["rooms"] = [self.room_ids[r] for r in door["rooms"]]
        for item in (*windows, *lights):
            item["room"] = self.room_ids[item["room"]]
        wall_records = self._wall_records(walls, rooms)
        station, station_object = self._station(rooms, objects)
        objects.append(station_object)
        all_models.append((None, None, None, ""))
        props = self.properties
        author = props.get("Author", "")
        house = {
            "format": HOUSE_FORMAT, "house": 0, "name": self.name,
            "attribution": (f"{self.file.name} drawn in Sweet Home 3D by {author or 'an unnamed author'}"
                            + (f" ({props['Copyright']})" if props.get("Copyright") else "")
                            + f"; licence: {props.get('License') or 'not stated'}. Imported by ravh import-home."),
            "source": {"file": self.file.name, "author": author, "copyright": props.get("Copyright", ""),
                       "license": props.get("License", ""), "level": self.level_name,
                       "levels": " | ".join(self.level_names), "importer": "ravh import-home"},
            "station": station, "rooms": rooms, "walls": wall_records, "doors": doors, "windows": windows,
            "lights": lights, "objects": objects}
        return house, all_models

    # -- walls
    def _walls(self) -> list[_Segment]:
        elements = self._bounded([w for w in self.root.findall("wall") if self._on_level(w)], MAX_ITEMS["walls"],
                                 "walls")
        segments: list[_Segment] = []
        for w in elements:
            a = (self._num(w, "xStart") / 100, -self._num(w, "yStart") / 100)
            b = (self._num(w, "xEnd") / 100, -self._num(w, "yEnd") / 100)
            thickness = max(self._num(w, "thickness") / 100, 0.01)
            height = self._num(w, "height", self.level_height * 100) / 100
            height = max(height, self._num(w, "heightAtEnd", height * 100) / 100, 0.05)
            colours = (_hex(w.get("leftSideColor")), _hex(w.get("rightSideColor")))
            arc = self._num(w, "arcExtent", 0.0)
            points = _arc_points(a, b, -arc) if abs(arc) > 1e-3 else [a, b]
            for p, q in zip(points[:-1], points[1:]):
                if math.dist(p, q) > 1e-3:
                    segments.append(_Segment(p, q, thickness, height, *colours))
        return segments

    def _wall_records(self, walls: list[_Segment], rooms: list[dict]) -> list[dict]:
        records = []
        for w in walls:
            length = math.dist(w.a, w.b)
            for t0, t1, z0, z1, kind in _pieces_of(w, length):
                a, b = _along(w, t0), _along(w, t1)
                if math.dist(a, b) < 1e-3 or z1 - z0 < 1e-3:
                    continue
                room = self.room_ids[self._room_beside(w, (t0 + t1) / 2)]
                records.append({"room": room, "kind": kind, "a": _r(a), "b": _r(b), "thickness": _r(w.thickness),
                                "z0": _r(z0), "z1": _r(z1)})
        if not records:
            raise FileFieldError(self.file, "Home.xml <wall>", f"no wall on level {self.level_name or '(only)'}")
        self._paint_walls(walls, rooms)
        return records

    def _side_rooms(self, w: _Segment, t: float) -> tuple[str | None, str | None]:
        """The rooms just off the wall's left and right sides (ours: left of a -> b) at ``t`` along it."""
        (ax, ay), (bx, by) = w.a, w.b
        length = max(math.dist(w.a, w.b), 1e-9)
        nx, ny = -(by - ay) / length, (bx - ax) / length
        px, py = _along(w, t)
        off = w.thickness / 2 + 0.05
        return self._room_at(px + nx * off, py + ny * off), self._room_at(px - nx * off, py - ny * off)

    def _room_beside(self, w: _Segment, t: float) -> str:
        left, right = self._side_rooms(w, t)
        return left or right or self._nearest_room(*_along(w, t))

    def _paint_walls(self, walls: list[_Segment], rooms: list[dict]) -> None:
        """Each room's wall paint: the colour most of the wall length facing it shows (uncoloured sides
        vote for our default paint). Sweet Home 3D's left side is the left on its y-down plan, our right."""
        votes: dict[str, dict[str | None, float]] = {}
        for w in walls:
            ours_left, ours_right = self._side_rooms(w, math.dist(w.a, w.b) / 2)
            for side_room, colour in ((ours_left, w.right_colour), (ours_right, w.left_colour)):
                if side_room:
                    tally = votes.setdefault(side_room, {})
                    tally[colour] = tally.get(colour, 0.0) + math.dist(w.a, w.b)
        for i, room in enumerate(rooms):
            tally = votes.get(f"#{i}", {})
            winner = max(tally, key=lambda c: tally[c]) if tally else None
            if winner:
                room.setdefault("paint", {})["walls"] = winner

    # -- rooms
    def _rooms(self) -> list[dict]:
        elements = self._bounded([r for r in self.root.findall("room") if self._on_level(r)], MAX_ITEMS["rooms"],
                                 "rooms")
        rooms: list[dict] = []
        outlines: set[frozenset] = set()
        for r in elements:
            points = [(self._num(p, "x") / 100, -self._num(p, "y") / 100) for p in r.findall("point")]
            polygon = _clean_polygon(points)
            if polygon is None:
                self.left_out[f"{self._where(r)}: no area"] = 1
                continue
            key = frozenset((round(x, 3), round(y, 3)) for x, y in polygon)
            if key in outlines:
                self.left_out[f"{self._where(r)}: the same outline as another room"] = 1
                continue
            outlines.add(key)
            room: dict[str, Any] = {"id": "", "type": "", "name": (r.get("name") or "").strip()[:100],
                                    "floor_z": 0.0, "ceiling_z": _r(self.level_height), "floor": _r(polygon)}
            floor = _hex(r.get("floorColor"))
            if floor:
                room["paint"] = {"floor": floor}
            rooms.append(room)
        return rooms

    def _type_rooms(self, rooms: list[dict], objects: list[dict]) -> None:
        """Types (:func:`room_type`) and ids ``<Type>_<n>``; objects, walls and doors still hold room
        indices as ``#<i>`` and are renamed here."""
        counts: Counter[str] = Counter()
        ids = {}
        for i, room in enumerate(rooms):
            inside = [o["type"] for o in objects if o["room"] == f"#{i}"]
            xs, ys = zip(*room["floor"])
            room["type"] = room_type(room["name"], inside, min(max(xs) - min(xs), max(ys) - min(ys)))
            counts[room["type"]] += 1
            room["id"] = ids[f"#{i}"] = f"{room['type']}_{counts[room['type']]}"
            room["name"] = room["name"] or f"({room['type']}, unnamed)"
        self.room_ids = ids
        for o in objects:
            o["room"] = ids[o["room"]]

    def _room_at(self, x: float, y: float) -> str | None:
        point = Point(x, y)
        return next((f"#{i}" for i, (_, poly) in enumerate(self.room_polygons) if poly.covers(point)), None)

    def _nearest_room(self, x: float, y: float) -> str:
        point = Point(x, y)
        distances = [poly.distance(point) for _, poly in self.room_polygons]
        return f"#{int(np.argmin(distances))}"

    # -- furniture
    def _pieces(self) -> Iterator[_Piece]:
        """Every visible piece of the level, groups flattened."""
        tags = ("pieceOfFurniture", "doorOrWindow", "light", "furnitureGroup")
        count = 0

        def walk(parent: Element, level_ok: bool) -> Iterator[_Piece]:
            nonlocal count
            for e in parent:
                if e.tag not in tags:
                    continue
                on_level = self._on_level(e) if e.get("level") is not None else level_ok
                if e.tag == "furnitureGroup":
                    yield from walk(e, on_level)
                    continue
                count += 1
                if count > MAX_ITEMS["objects"]:
                    raise FileFieldError(self.file, "Home.xml <pieceOfFurniture>", "more pieces than the limit of "
                                         f"{MAX_ITEMS['objects']}")
                if not on_level:
                    continue
                if e.get("visible") == "false":
                    self.left_out["hidden pieces"] = self.left_out.get("hidden pieces", 0) + 1
                    continue
                angle = self._num(e, "angle", 0.0)
                yield _Piece(e, self._where(e), (e.get("name") or e.tag).strip()[:100],
                             self._num(e, "x") / 100, -self._num(e, "y") / 100, self._num(e, "elevation", 0.0) / 100,
                             _wrap(-angle - math.pi / 2), max(self._num(e, "width") / 100, MIN_SIZE),
                             max(self._num(e, "depth") / 100, MIN_SIZE), max(self._num(e, "height") / 100, MIN_SIZE))

        yield from walk(self.root, self.level_id is None)

    def _is_door(self, p: _Piece) -> bool:
        return p.element.tag == "doorOrWindow" and (
            bool(DOOR_WORDS.search(p.name)) or (p.z0 <= DOOR_SILL and p.height >= DOOR_HEIGHT))

    def _openings(self, pieces: list[_Piece], walls: list[_Segment]) -> tuple[list, list, list, list]:
        doors: list[dict] = []
        door_objects: list[dict] = []
        windows: list[dict] = []
        window_objects: list[dict] = []
        for p in pieces:
            if p.element.tag != "doorOrWindow":
                continue
            width_dir = _wrap(p.front + math.pi / 2)
            wall, t = _host_wall(walls, p, width_dir)
            x, y, thickness = p.x, p.y, p.depth
            if wall is not None:
                x, y = _along(wall, t)
                thickness = wall.thickness
            if self._is_door(p):
                ident = f"Door_{len(doors)}"
                rooms = self._door_rooms(x, y, width_dir, thickness)
                if wall is not None:
                    wall.cuts.append((t - p.width / 2, t + p.width / 2, p.z0 + p.height))
                frame = min(0.07, 0.1 * p.width)
                doors.append({"id": ident, "rooms": rooms, "position": _r([x, y, p.z0 + p.height / 2]),
                              "yaw": _r(width_dir), "width": _r(p.width), "height": _r(p.height),
                              "thickness": _r(thickness),
                              "leaf": _r([p.width - 2 * frame, 0.04, max(p.height - frame, MIN_SIZE)]),
                              "default_open": len(rooms) > 1})
                door_objects.append(_object(ident, "Door", p.name, rooms[0], _wrap(width_dir - math.pi / 2),
                                            [x, y, p.z0 + p.height / 2], [thickness, p.width, p.height]))
            else:
                ident = f"Wall_{len(windows)}"
                room = self._room_beside(wall, t) if wall is not None else (
                    self._room_at(x, y) or self._nearest_room(x, y))
                windows.append({"id": ident, "room": room, "position": _r([x, y, p.z0 + p.height / 2]),
                                "yaw": _r(width_dir), "width": _r(p.width), "height": _r(p.height),
                                "thickness": _r(thickness)})
                window_objects.append(_object(ident, "Wall", p.name, room, p.front, [x, y, p.z0 + p.height / 2],
                                              [max(thickness, p.depth), p.width, p.height]))
        return doors, door_objects, windows, window_objects

    def _door_rooms(self, x: float, y: float, width_dir: float, thickness: float) -> list[str]:
        nx, ny = -math.sin(width_dir), math.cos(width_dir)
        off = thickness / 2 + 0.25
        found = [self._room_at(x + s * nx * off, y + s * ny * off) for s in (1.0, -1.0)]
        rooms = list(dict.fromkeys(r for r in found if r))
        return rooms or [self._nearest_room(x, y)]

    def _window_models(self, pieces: list[_Piece]) -> list:
        """The windows' models, marked so that their panes come out as clear glass."""
        models = [self._model_of(p) for p in pieces if p.element.tag == "doorOrWindow" and not self._is_door(p)]
        return [(replace(look, window=True) if look else None, *rest) for look, *rest in models]

    def _furniture(self, pieces: list[_Piece], rooms: list[dict]) -> tuple[list, list, list]:
        objects, models, lights = [], [], []
        counts: Counter[str] = Counter()
        xs = [x for r in rooms for x, _ in r["floor"]]
        ys = [y for r in rooms for _, y in r["floor"]]
        lo, hi = (min(xs) - PLAN_MARGIN + 0.05, min(ys) - PLAN_MARGIN + 0.05), \
            (max(xs) + PLAN_MARGIN - 0.05, max(ys) + PLAN_MARGIN - 0.05)
        for p in pieces:
            if p.element.tag == "doorOrWindow":
                continue
            c, s = abs(math.cos(p.front)), abs(math.sin(p.front))
            half = ((c * p.depth + s * p.width) / 2, (s * p.depth + c * p.width) / 2)
            if p.x - half[0] < lo[0] or p.x + half[0] > hi[0] or p.y - half[1] < lo[1] or p.y + half[1] > hi[1]:
                self.left_out["pieces outside the floor plan"] = self.left_out.get("pieces outside the floor plan",
                                                                                   0) + 1
                continue
            kind, light_kind = self._kind(p)
            object_type = kind.split("/")[0]
            ident = f"{object_type}_{counts[object_type]}"
            counts[object_type] += 1
            room = self._room_at(p.x, p.y) or self._nearest_room(p.x, p.y)
            prefab = p.name if "/" not in kind else f"{p.name} {_CLASS_WORDS[kind.split('/')[1]]}"
            if kind_of(object_type, prefab) != kind:
                prefab = _CLASS_WORDS.get(kind.split("/")[-1], p.name) if "/" in kind else object_type
            objects.append(_object(ident, object_type, p.name, room, p.front,
                                   [p.x, p.y, p.z0 + p.height / 2], [p.depth, p.width, p.height], prefab))
            models.append(self._model_of(p))
            if light_kind:
                lights.append(self._light(p, ident, light_kind, room))
        return objects, models, lights

    def _kind(self, p: _Piece) -> tuple[str, str | None]:
        """The library kind of a piece and, for a light, its light kind."""
        if p.element.tag == "light":
            top = p.z0 + p.height
            if top >= self.level_height - CEILING_GAP:
                return "Light", "ceiling"
            return ("Lighter", "wall") if p.z0 >= WALL_LIGHT_Z else ("Lamp", "lamp")
        lowered = p.name.lower()
        for kind, pattern in NAME_RULES:
            if re.search(pattern, lowered):
                return kind, None
        for kind, rule in RULES.items():
            if kind not in ("Lamp", "Light") and re.search(rule.name, lowered) and not re.search(rule.exclude,
                                                                                                 lowered):
                return kind, None
        return GENERIC, None

    def _light(self, p: _Piece, ident: str, kind: str, room: str) -> dict:
        power = min(max(self._num(p.element, "power", 0.5), 0.0), 1.0)
        source = p.element.find("lightSource")
        z = p.z0 + p.height * (self._num(source, "z", 0.5) if source is not None else 0.5)
        colour = _rgb(source.get("color") if source is not None else None) or (1.0, 1.0, 0.9)
        return {"id": ident, "kind": kind, "room": room, "position": _r([p.x, p.y, min(z, self.level_height - 0.01)]),
                "intensity": _r(min(100.0, (2.0 if kind == "ceiling" else 0.6) * power)), "range": 10.0,
                "color": _r(list(colour))}

    def _model_of(self, p: _Piece) -> tuple[Look | None, np.ndarray | None, Described | None, str]:
        e = p.element
        entry = e.get("model")
        if not entry:
            return None, None, None, p.where
        rotation = tuple(float(v) for v in (e.get("modelRotation") or "").split()) or None
        overrides = tuple((m.get("name", ""), _rgb(m.get("color")), _texture_entry(m))
                          for m in e.findall("material")[:256])
        look = Look(entry, rotation if rotation and len(rotation) == 9 else None, e.get("modelMirrored") == "true",
                    _rgb(e.get("color")), overrides, _texture_entry(e))
        props = self.properties
        described = Described(p.name, self.file.name, e.get("catalogId", ""), e.get("creator", ""),
                              props.get("License", ""))
        return look, np.array([p.depth, p.width, p.height]), described, p.where

    def views(self) -> list[tuple[str, float, float, float]]:
        """The views the author stored on the imported level (call after :meth:`house`): the eye's
        elevation within the level's span, the point in a room; one just outside every room (an
        author's camera backed against a wall) is moved into the nearest room, further ones are
        left out (a view of the garden)."""
        low, high = self.level_span or (-math.inf, math.inf)
        views = []
        for name, x, y, yaw, z in _views(self.root):
            if not low <= z < high:
                continue
            point = Point(x, y)
            polygon = min((polygon for _, polygon in self.room_polygons), key=point.distance)
            if polygon.distance(point) == 0.0:
                views.append((name, x, y, yaw))
            elif polygon.distance(point) <= VIEW_NUDGE:
                inner = polygon.buffer(-VIEW_NUDGE / 2)
                _, inside = nearest_points(point, polygon if inner.is_empty else inner)
                views.append((name, round(inside.x, 3), round(inside.y, 3), yaw))
        return views

    # -- the start
    def _station(self, rooms: list[dict], objects: list[dict]) -> tuple[dict, dict]:
        """The Station (the robot's start) in the largest living area's most open spot."""
        living = [r for r in rooms if r["type"] in LIVING_TYPES] or rooms
        room = max(living, key=lambda r: ShapelyPolygon(r["floor"]).area)
        floor = ShapelyPolygon(room["floor"])
        blocked = [_footprint(o) for o in objects if o["models"][0]["position"][2]
                   - o["models"][0]["size"][2] / 2 < 1.5 and o["type"] not in ("Door",)]
        obstacles = shapely.union_all(blocked) if blocked else shapely.Polygon()
        minx, miny, maxx, maxy = floor.bounds
        best: tuple[float, float, float, float] | None = None
        centroid = floor.centroid
        for x in np.arange(minx + 0.05, maxx, 0.1):
            for y in np.arange(miny + 0.05, maxy, 0.1):
                point = Point(x, y)
                if not floor.contains(point) or obstacles.contains(point):
                    continue
                clearance = min(floor.exterior.distance(point), obstacles.distance(point) if blocked else 9.0,
                                1.0)
                score = (clearance, -point.distance(centroid))
                if best is None or score > (best[2], best[3]):
                    best = (float(x), float(y), score[0], score[1])
        x, y = (best[0], best[1]) if best else (centroid.x, centroid.y)
        yaw = math.atan2(centroid.y - y, centroid.x - x) if math.dist((x, y), (centroid.x, centroid.y)) > 0.2 else 0.0
        station = {"position": _r([x, y, 0.0]), "yaw": _r(yaw), "object_id": "Station_0"}
        obj = _object("Station_0", "Station", "Station", room["id"], yaw, [x, y, 0.01], [0.5, 0.5, 0.02], "Station")
        obj["size_estimated"] = True
        return station, obj


# ----------------------------------------------------------------------------------------- geometry

def _object(ident: str, object_type: str, label: str, room: str, yaw: float, position: list[float],
            size: list[float], prefab: str | None = None) -> dict:
    tags = [object_type] + ([label] if label and label != object_type else [])
    return {"id": ident, "type": object_type, "tags": tags, "room": room, "prefab": prefab or label or object_type,
            "yaw": _r(_wrap(yaw)), "size_estimated": False, "default_model": 0,
            "models": [{"position": _r(position), "size": _r([max(v, MIN_SIZE) for v in size])}],
            "inherits_model_from": None}


def _footprint(o: dict) -> shapely.Polygon:
    (x, y, _), (sx, sy, _) = o["models"][0]["position"], o["models"][0]["size"]
    c, s = math.cos(o["yaw"]), math.sin(o["yaw"])
    corners = [(x + c * u - s * v, y + s * u + c * v) for u, v in
               ((-sx / 2, -sy / 2), (sx / 2, -sy / 2), (sx / 2, sy / 2), (-sx / 2, sy / 2))]
    return ShapelyPolygon(corners).buffer(ROBOT_CLEARANCE)


def _host_wall(walls: list[_Segment], p: _Piece, width_dir: float) -> tuple[_Segment | None, float]:
    """The wall a door or window sits in (its centre within the wall's thickness, its width along it)
    and how far along it."""
    best: tuple[_Segment | None, float, float] = (None, 0.0, math.inf)
    for w in walls:
        length = math.dist(w.a, w.b)
        dx, dy = (w.b[0] - w.a[0]) / length, (w.b[1] - w.a[1]) / length
        px, py = p.x - w.a[0], p.y - w.a[1]
        along, across = px * dx + py * dy, abs(-px * dy + py * dx)
        parallel = abs(math.cos(width_dir) * dy - math.sin(width_dir) * dx) < 0.2
        if parallel and -0.01 <= along <= length + 0.01 and across <= max(w.thickness, p.depth) / 2 + 0.1 \
                and across < best[2]:
            best = (w, along, across)
    return best[0], best[1]


def _pieces_of(w: _Segment, length: float) -> list[tuple[float, float, float, float, str]]:
    """(t0, t1, z0, z1, kind) of a wall cut by its doors: full-height pieces between doorways and a
    lintel above each doorway that is lower than the wall."""
    pieces, t = [], 0.0
    for t0, t1, top in sorted(w.cuts):
        t0, t1 = max(t0, 0.0), min(t1, length)
        if t0 > t:
            pieces.append((t, t0, 0.0, w.z1, "wall"))
        if top < w.z1 - 1e-3 and t1 > t0:
            pieces.append((t0, t1, top, w.z1, "lintel"))
        t = max(t, t1)
    if length > t:
        pieces.append((t, length, 0.0, w.z1, "wall"))
    return pieces


def _along(w: _Segment, t: float) -> tuple[float, float]:
    length = max(math.dist(w.a, w.b), 1e-9)
    return (w.a[0] + (w.b[0] - w.a[0]) * t / length, w.a[1] + (w.b[1] - w.a[1]) * t / length)


def _arc_points(a: tuple[float, float], b: tuple[float, float], extent: float) -> list[tuple[float, float]]:
    """Points along a circular arc from ``a`` to ``b`` turning by ``extent`` (our frame, counter-clockwise
    positive)."""
    chord = math.dist(a, b)
    if chord < 1e-6:
        return [a, b]
    mx, my = (a[0] + b[0]) / 2, (a[1] + b[1]) / 2
    nx, ny = -(b[1] - a[1]) / chord, (b[0] - a[0]) / chord
    offset = chord / 2 / math.tan(extent / 2)
    cx, cy = mx + nx * offset, my + ny * offset
    radius = math.dist((cx, cy), a)
    start = math.atan2(a[1] - cy, a[0] - cx)
    steps = max(2, math.ceil(abs(extent) / ARC_STEP))
    points = [(cx + radius * math.cos(start + extent * k / steps), cy + radius * math.sin(start + extent * k / steps))
              for k in range(steps + 1)]
    if math.dist(points[-1], b) > 1e-3 * max(chord, 1.0):        # a degenerate arc: keep the chord
        return [a, b]
    points[-1] = b
    return points


def _clean_polygon(points: list[tuple[float, float]]) -> list[tuple[float, float]] | None:
    """A simple counter-clockwise outline of at most MAX_OUTLINE vertices, or None where nothing is left."""
    if len(points) < 3:
        return None
    polygon = shapely.make_valid(ShapelyPolygon(points))
    if not isinstance(polygon, ShapelyPolygon):
        parts = [g for g in getattr(polygon, "geoms", []) if isinstance(g, ShapelyPolygon)]
        if not parts:
            return None
        polygon = max(parts, key=lambda g: g.area)
    polygon = ShapelyPolygon(polygon.exterior).simplify(0.002)
    tolerance = 0.01
    while len(polygon.exterior.coords) - 1 > MAX_OUTLINE and tolerance < 1.0:
        polygon = polygon.simplify(tolerance)
        tolerance *= 2
    if not isinstance(polygon, ShapelyPolygon) or polygon.area < 0.05 or len(polygon.exterior.coords) - 1 > MAX_OUTLINE:
        return None
    polygon = shapely.geometry.polygon.orient(polygon, 1.0)
    return [(float(x), float(y)) for x, y in polygon.exterior.coords[:-1]]


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def _hex(argb: str | None) -> str | None:
    """A Sweet Home 3D colour (``AARRGGBB`` hex) as our paint ``#rrggbb``."""
    if not argb or not re.fullmatch(r"[0-9A-Fa-f]{6,8}", argb):
        return None
    return "#" + argb[-6:].lower()


def _rgb(argb: str | None) -> tuple[float, float, float] | None:
    paint = _hex(argb)
    return None if paint is None else tuple(int(paint[i:i + 2], 16) / 255 for i in (1, 3, 5))  # type: ignore[return-value]


def _texture_entry(element: Element) -> str | None:
    texture = element.find("texture")
    return texture.get("image") if texture is not None else None


def _r(value: Any) -> Any:
    """Round to 0.1 mm so files stay small and stable."""
    if isinstance(value, (list, tuple)):
        return [_r(v) for v in value]
    return round(float(value), 4) + 0.0


def stored_views(archive: Sh3dArchive) -> list[tuple[str, float, float, float]]:
    """The cameras the home's author stored (``observerCamera``): name, x, y, yaw in our frame, on
    every level (``Imported.views`` has those of the imported level)."""
    return [view[:4] for view in _views(archive.home())]


def _views(root: Element) -> list[tuple[str, float, float, float, float]]:
    """Every ``observerCamera``: name, x, y (m, our frame), yaw (rad) and the eye's elevation (cm)."""
    views = []
    for camera in root.findall("observerCamera"):
        try:
            x, y, yaw, z = (float(camera.get(k, "nan")) for k in ("x", "y", "yaw", "z"))
        except ValueError:
            continue
        if all(map(math.isfinite, (x, y, yaw, z))):
            name = camera.get("name") or camera.get("attribute") or "observer"
            views.append((name, round(x / 100, 3), round(-y / 100, 3), round(_wrap(-yaw - math.pi / 2), 4), z))
    return views

