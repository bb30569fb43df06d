"""Dressing: the things people put in a home, placed where people put them.

The appearance knob ``dressing`` (:class:`ravh_msgs_py.appearance.Looks`: ``none``, ``tidy`` or
``lived-in``) adds catalogue objects to a house: plates, bowls, cups, a fruit bowl and a vase on
tables; pans, a kettle, bottles and a dish rack (one a kitchen, by its sink) on worktops; rows of
books, boxes and plants on the boards of bookcases (racks) and shelves, stacks of books on desks;
pillows and a duvet on beds, cushions and a throw on sofas; towels in bathrooms; rugs by sofas and
beds; curtains or blinds at windows; plants in corners; more pictures on the walls.

How a layout is made (:func:`layout`), in plain Python, with no pybullet:

- **Slots** come from the house and the seed alone (:func:`slots`): per support (a table, a worktop,
  a shelf, a bed, a sofa, a window, a room's corners and walls) the things it may hold, each with its
  library model (drawn from the seed's ``dressing/<slot>`` stream), its size and whether the ``tidy``
  level keeps it (``tidy`` is a subset of ``lived-in``). A slot's id (``Plate_0``; numbered after the
  house's own objects of that type, so ``Cup_3`` follows the house's ``Cup_0..2``) and its instance id
  (after every instance of the house) never depend on the level or on the object models.
- **Poses** depend on the supports' models (a table's model decides where its top is; a bookcase's, which
  boards it has, :func:`_boards`): each slot tries seeded candidate positions on its support (on a
  bookcase, at each of its boards) and takes the first that (a) rests on the support's
  real geometry, the fitted model's triangles, not its box (vertical lines through the object's
  footprint cross the support's triangles: the highest crossing under it is its bottom, nothing of
  the support lies inside it, and enough of its footprint touches), and (b) keeps clear of every other
  object's pieces (:attr:`Placed.bounds`; on a bookcase, of its own sides, back and dividers too), the
  walls and every dressing object placed before it.
  Things on the floor keep clear of doorways, passages and the robot's station; a rug lies under
  nothing that stands on the floor but feet (a bed's, a nightstand's legs: a pile takes them), never
  under a base. A slot with no room on its support is left out.

A dressing object collides as its own triangles (the laser sees what the camera draws) unless it is a
rug (flat on the floor: the robot drives over it). Dressing objects are ``kind: dressing`` instances
(footprint rows also carry ``dressing: true`` and their ``support``): the paper's evaluations read
``kind: object`` only, so they keep the paper's object list, and so does the COCO export
(:mod:`ravh_sim.dataset.coco`), whose semantic images give them their own class ids.
"""
from __future__ import annotations

import functools
import math
import random
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import trimesh
from shapely.geometry import Point, Polygon

from ravh_sim.world import library, made_art, made_objects, soft_furnishings
from ravh_sim.world.house import House, HouseObject, Room
from ravh_sim.world.instances import build_instances
from ravh_sim.world.solids import Placed, _fitted, _piece_bounds, object_parts
from ravh_sim.world.structure import solid_walls
from ravh_sim.world.topology import room_links

LEVELS = ("none", "tidy", "lived-in")
DRESSING_TAG = "dressing"
REST_TOLERANCE = 0.0015       # m: a support's triangle this close above an object's bottom is its surface
FLOOR_CLEARANCE = 0.9         # m: a floor object's centre from a doorway's or passage's centre, the station
CANDIDATES = 24               # positions tried per slot
FOOT_SIZE = 0.12              # m: furniture touches a rug's band with feet this small (legs, castors) or
                              # with a base; a rug goes under feet, as a pile takes them, never a base
REST_SAMPLES = 9              # vertical lines per side of a footprint that find its support (odd: the
                              # coarse lattice is every other line; 5 missed a mattress rising 2 mm
REST_INSET = 0.003            # between them), this far inside its edges


@dataclass(frozen=True)
class Spec:
    """A thing a support may hold: its type, the library kinds that model it (first with models wins),
    the box it is scaled into (front, across, up; uniformly, unless ``stretch``), how many a support
    holds at each level and how it stands."""
    type: str
    kinds: tuple[str, ...]
    box: tuple[float, float, float]
    tidy: int
    lived_in: int
    flat: float = 0.005                # m: how far below its bottom a footprint point may find its support
    touching: float = 0.6              # share of the footprint that must rest on the support
    stretch: bool = False
    collides: bool = True
    facing: str = "random"             # random | support (the support's front) | out (into the room)
    unlike: tuple[str, ...] = ()       # words in the ids of the kinds' models that are not this thing


def _s(type_: str, kinds: str, box: tuple[float, float, float], tidy: int, lived_in: int, **kw) -> Spec:
    return Spec(type_, tuple(kinds.split()), box, tidy, lived_in, **kw)


# what each support holds; the kinds are the furniture library's (Dressing/... first, older kinds after)
STACK = (0.26, 0.2, 0.1)       # a few books lying on a table or a desk (made_objects: box under ROW_HEIGHT)
TABLE = (_s("FruitBowl", "Dressing/fruit_bowl", (0.32, 0.32, 0.16), 1, 1),
         _s("Vase", "Dressing/vase Decoration/vase", (0.18, 0.18, 0.32), 1, 1),
         _s("Plate", "Dressing/plate", (0.26, 0.26, 0.04), 0, 4),
         _s("Cup", "Dressing/cup Cup", (0.12, 0.12, 0.11), 0, 3),
         _s("Bowl", "Dressing/bowl", (0.17, 0.17, 0.08), 0, 1),
         _s("Book", "Dressing/book", STACK, 0, 1, stretch=True))
SMALL_TABLE = (_s("Vase", "Dressing/vase Decoration/vase", (0.16, 0.16, 0.28), 1, 1),
               _s("Book", "Dressing/book", STACK, 0, 2, stretch=True),
               _s("Cup", "Dressing/cup Cup", (0.12, 0.12, 0.11), 0, 1),
               _s("Plant", "Dressing/plant Decoration", (0.2, 0.2, 0.25), 0, 1))
DESK = (_s("Book", "Dressing/book", STACK, 1, 3, stretch=True),
        _s("Cup", "Dressing/cup Cup", (0.12, 0.12, 0.11), 0, 1),
        _s("Plant", "Dressing/plant Decoration", (0.2, 0.2, 0.25), 0, 1),
        _s("Box", "Dressing/box", (0.3, 0.25, 0.15), 0, 1))
WORKTOP = (_s("DishRack", "Dressing/dish_rack", (0.42, 0.36, 0.24), 1, 1, stretch=True, facing="support"),
           _s("Kettle", "Dressing/kettle", (0.22, 0.2, 0.26), 1, 1),
           _s("Pan", "Dressing/pan", (0.45, 0.28, 0.1), 0, 1),
           _s("Bottle", "Dressing/bottle", (0.07, 0.07, 0.26), 0, 2),
           _s("Bowl", "Dressing/bowl", (0.17, 0.17, 0.08), 0, 1),
           _s("Cup", "Dressing/cup Cup", (0.12, 0.12, 0.11), 0, 2))
# on a bookcase's or a shelf's boards (a row's width and height are made to measure: _box), wholly on
# a board (touching), spines and box fronts to the room
SHELF = (_s("Book", "Dressing/book", (0.2, 0.45, 0.22), 2, 6, stretch=True, touching=0.97, facing="support"),
         _s("Box", "Dressing/box", (0.26, 0.3, 0.18), 1, 2, touching=0.97, facing="support"),
         _s("Plant", "Dressing/plant Decoration", (0.2, 0.2, 0.2), 1, 2, touching=0.9),
         _s("Vase", "Dressing/vase Decoration/vase", (0.14, 0.14, 0.2), 0, 1, touching=0.9))
BED = (_s("Duvet", "Dressing/duvet", (1.4, 1.6, 0.12), 1, 1, stretch=True, flat=0.08, touching=0.3,
          facing="support"),
       _s("Pillow", "Dressing/pillow", (0.45, 0.7, 0.14), 1, 2, flat=0.05, touching=0.7, facing="support"))
SOFA = (_s("Cushion", "Dressing/cushion", (0.2, 0.45, 0.45), 1, 3, flat=0.04, touching=0.4, facing="support"),
        _s("Throw", "Dressing/throw", (0.6, 1.0, 0.07), 0, 1, stretch=True, flat=0.05, touching=0.4,
           facing="support"))
RUG = _s("Rug", "Dressing/rug", (1.6, 2.2, 0.02), 1, 1, stretch=True, collides=False, facing="support",
         unlike=("bathmat", "doormat"))         # a living room's or a bedroom's rug, not a mat made large
CURTAIN = _s("Curtain", "Dressing/curtain", (0.2, 1.6, 2.4), 0, 1, stretch=True, facing="out")   # a pair, drawn open
BLIND = _s("Blind", "Dressing/blind", (0.06, 1.2, 0.6), 0, 1, stretch=True, facing="out")
FLOOR_PLANT = _s("Plant", "Dressing/floor_plant Decoration", (0.6, 0.6, 1.1), 0, 1)
WALL_ART = _s("Picture", "Dressing/wall_art", (0.04, 0.8, 0.6), 0, 1, stretch=True, facing="out")
TOWEL = _s("Towel", "Dressing/towel Towel", (0.12, 0.5, 0.7), 1, 2, stretch=True, facing="out")

SUPPORTS: dict[str, tuple[Spec, ...]] = {
    "Table": TABLE, "Table/small": SMALL_TABLE, "Desk": DESK, "Counter": WORKTOP, "Shelf": SHELF,
    "Bed": BED, "Sofa": SOFA}
CORNER_ROOMS = ("LivingRoom", "KitchenLivingRoom", "Bedroom", "Office", "Hall", "Standard")
ART_ROOMS = ("LivingRoom", "KitchenLivingRoom", "Bedroom", "Office", "Hall", "Corridor", "Standard",
             "DressingRoom", "Kitchen")
SINGLE_BED = 1.2              # m: a bed this wide or narrower has one pillow, in its middle
WALL_CENTRE = 1.5             # m above the floor: the centre of a picture
TOWEL_TOP = 1.6               # m above the floor: a hanging towel's top


@dataclass(frozen=True)
class Slot:
    """A dressing object that may be placed: fixed by the house and the seed (see the module)."""
    id: str                    # Plate_0
    type: str
    instance: int              # instance id (after the house's)
    room: str
    support: str               # the object it stands on or hangs by (a window), or '<room>/floor|walls'
    spec: Spec
    model_id: str
    size: tuple[float, float, float]      # the fitted model's box: front, across, up
    tidy: bool
    order: int                 # which of its spec on its support (0, 1, ...)

    @property
    def collides(self) -> bool:
        return self.spec.collides

    @property
    def tags(self) -> tuple[str, ...]:
        return (self.type, DRESSING_TAG)


@dataclass(frozen=True)
class Dressed:
    """A placed dressing object: its slot and body pose (box centre, yaw of the model's front)."""
    slot: Slot
    position: tuple[float, float, float]
    yaw: float

    @property
    def id(self) -> str:
        return self.slot.id

    def placed(self) -> Placed:
        """The fitted model in its body frame and the body's pose, as :mod:`ravh_sim.world.solids` has it."""
        made = _made_here(self.slot.model_id)
        if made is not None:
            fitted = made(self.slot.model_id, self.slot.size)
            bounds = _piece_bounds(fitted.vertices, fitted.faces, fitted.face_attributes["piece"])
        else:
            fitted, bounds = _fitted(self.slot.model_id, self.slot.size, 0)
        return Placed((), bounds, self.position, self.yaw, fitted, self.yaw)


def _made_here(model_id: str) -> Callable[[str, tuple[float, float, float]], trimesh.Trimesh] | None:
    """The builder of a model made here to its box (soft furnishings, wall art, books, dish racks); None
    for a library model."""
    if soft_furnishings.is_soft(model_id):
        return soft_furnishings.model
    if made_art.is_made(model_id):
        return made_art.model
    if made_objects.is_made(model_id):
        return made_objects.model
    return None


def kind_models(spec: Spec) -> tuple[library.LibraryRecord, ...]:
    """The library models of the first of the spec's kinds that has any, or else the models made here
    (:mod:`ravh_sim.world.soft_furnishings`: pillows, duvets, cushions, throws;
    :mod:`ravh_sim.world.made_art`: wall art; :mod:`ravh_sim.world.made_objects`: books, dish racks);
    empty: none."""
    for kind in spec.kinds:
        found = (library.models_of(kind) or soft_furnishings.records(kind) or made_art.records(kind)
                 or made_objects.records(kind))
        if found:
            return found
    return ()


def level_keeps(level: str, slot: Slot) -> bool:
    if level not in LEVELS:
        raise ValueError(f"dressing: expected one of {', '.join(LEVELS)}, got {level!r}")
    return level == "lived-in" or level == "tidy" and slot.tidy


def dressing(house: House, models: Mapping[str, int], level: str, seed: int) -> tuple[Dressed, ...]:
    """The dressing objects of ``level`` in ``house`` with object ``models``, drawn from ``seed``."""
    if level == "none":
        return ()
    return tuple(d for d in layout(house, tuple(sorted(models.items())), seed) if level_keeps(level, d.slot))


# --------------------------------------------------------------------------- slots

def _support_kind(obj: HouseObject) -> str | None:
    if obj.type == "Table":
        return "Table/small" if library.kind_of(obj.type, obj.prefab) == "Table/small" else "Table"
    if obj.type == "Standard":             # racks are bookcases (a TV bench is Standard/tv)
        return "Shelf" if library.kind_of(obj.type, obj.prefab) == "Standard" else None
    return obj.type if obj.type in SUPPORTS else None


@functools.lru_cache(maxsize=64)
def slots(house: House, seed: int) -> tuple[Slot, ...]:
    """Every slot of ``house`` for ``seed``, in a fixed order (supports in the house's order, then
    windows, corners, walls; see the module)."""
    plan: list[tuple[str, str, Spec, int]] = []        # (room, support, spec, order)
    racks = _dish_rack_counters(house)
    for obj in house.objects:
        kind = _support_kind(obj)
        for spec in SUPPORTS.get(kind or "", ()):
            if spec.type == "DishRack" and obj.id not in racks:
                continue
            if spec.type == "Pillow" and min(obj.size[:2]) <= SINGLE_BED:     # one pillow on a single bed
                plan.append((obj.room, obj.id, spec, 0))
                continue
            plan += [(obj.room, obj.id, spec, k) for k in range(spec.lived_in)]
        if obj.type in ("Sofa", "Bed"):
            plan.append((obj.room, obj.id, RUG, 0))
    for window in house.windows:
        wide = window.width > 1.3
        wet = house.room(window.room).type in ("Bathroom", "Kitchen")
        draw = random.Random(f"{seed}/dressing/{house.number}/{window.id}").random()
        spec = CURTAIN if not wet and (wide or draw < 0.7) or wet and wide and draw < 0.3 else BLIND
        if spec is CURTAIN and _blocked_below(house, window):
            spec = BLIND                           # furniture under the window: a blind, not long curtains
        plan += [(window.room, window.id, spec, k) for k in range(spec.lived_in)]
    for room in house.rooms:
        if room.type in CORNER_ROOMS:
            plan += [(room.id, f"{room.id}/floor", FLOOR_PLANT, k) for k in range(2)]
        if room.type in ART_ROOMS:
            plan += [(room.id, f"{room.id}/walls", WALL_ART, k) for k in range(2 if room.area > 12 else 1)]
        if room.type == "Bathroom":
            plan += [(room.id, f"{room.id}/walls", TOWEL, k) for k in range(TOWEL.lived_in)]
    numbers: dict[str, int] = {}
    for obj in house.objects:
        head, _, tail = obj.id.rpartition("_")
        if tail.isdigit():
            numbers[head] = max(numbers.get(head, 0), int(tail) + 1)
    first_instance = _instance_count(house) + 1
    out: list[Slot] = []
    for room_id, support, spec, k in plan:
        records = _suitable(kind_models(spec), spec, _box(house, support, spec))
        if not records:
            continue
        name = f"{spec.type}_{numbers.get(spec.type, 0)}"
        numbers[spec.type] = numbers.get(spec.type, 0) + 1
        rng = random.Random(f"{seed}/dressing/{house.number}/{support}/{spec.type}/{k}")   # houses differ
        record = records[rng.randrange(len(records))]
        tidy = k < spec.tidy
        out.append(Slot(name, spec.type, first_instance + len(out), room_id, support, spec, record.id,
                        _size(record.id, spec, _box(house, support, spec)), tidy, k))
    return tuple(out)


def _dish_rack_counters(house: House) -> set[str]:
    """The worktop that holds a kitchen's one dish rack: in each room with a sink, the counter nearest
    it (not the sink's own, which has the basin in it) wide and deep enough for a rack."""
    out = set()
    for sink in (o for o in house.objects if o.type == "Sink"):
        counters = [o for o in house.objects if o.type == "Counter" and o.room == sink.room
                    and "sink" not in o.prefab.lower() and min(o.size[:2]) >= 0.5]
        if counters:
            out.add(min(counters, key=lambda o: math.dist(o.position[:2], sink.position[:2])).id)
    return out


def _blocked_below(house: House, window) -> bool:
    """Whether an object of the house (its box, whatever its model) stands in front of the window
    below its sill, where floor-length curtains would hang."""
    n = np.array([math.cos(window.yaw + math.pi / 2), math.sin(window.yaw + math.pi / 2)])
    centre = np.asarray(window.position[:2], np.float64)
    if not house.room(window.room).contains(*(centre + 0.3 * n)):
        n = -n
    front = _rect(tuple(centre + n * 0.25), (0.4, window.width + 0.5), math.atan2(n[1], n[0]))
    sill = window.position[2] - window.height / 2
    for obj in house.objects:
        if obj.type in ("Wall", "Window", "Door", "Picture", "Mirror", "Light") or obj.room != window.room:
            continue
        if obj.position[2] - obj.size[2] / 2 > sill:
            continue
        if _rect(obj.position[:2], obj.size[:2], obj.yaw).intersects(front):
            return True
    return False


MAX_SCALE = 2.0
"""A model is scaled into its box by at most this (or at least its inverse), or not used there: a
little plant does not become a tree."""


def _suitable(records: tuple[library.LibraryRecord, ...], spec: Spec, box_size: tuple[float, float, float]
              ) -> tuple[library.LibraryRecord, ...]:
    """The models that fit the box without absurd scaling and are the spec's thing (``Spec.unlike``);
    for things hung flat (on a wall, at a window), only flat ones."""
    out = []
    for record in records:
        if any(word in record.id for word in spec.unlike):
            continue
        natural = np.maximum(np.asarray(record.size, np.float64), 1e-4)
        if spec.facing == "out" and natural[0] > 0.5 * max(natural[1], natural[2]):
            continue
        if not spec.stretch:
            scale = float((np.asarray(box_size) / natural).min())
            if not 1 / MAX_SCALE <= scale <= MAX_SCALE:
                continue
        out.append(record)
    return tuple(out)


def _instance_count(house: House) -> int:
    return len(build_instances(house))


def _box(house: House, support: str, spec: Spec) -> tuple[float, float, float]:
    """The box a slot's model is scaled into: the spec's, or one made to measure for its support (the
    house's default box of it: a slot does not depend on the object models)."""
    obj = house.object_by_id.get(support)
    if obj is None:
        return spec.box
    long, short = max(obj.size[:2]), min(obj.size[:2])
    if spec.type == "Duvet":             # over the foot, leaving a pillow's room at the head of a short bed
        return (min(0.62 * long, long - 0.95), 0.96 * short, spec.box[2])
    if spec.type == "Book" and spec.box[2] >= made_objects.ROW_HEIGHT:
        # a row across part of a board, as tall as the case's boards stand apart (about an eighth of it)
        return (spec.box[0], round(float(np.clip(0.45 * long, 0.26, 0.5)), 3),
                round(float(np.clip(0.12 * obj.size[2], 0.13, 0.27)), 3))
    if spec.type == "Throw":
        return (min(0.5, 0.5 * short), min(1.0, 0.45 * long), spec.box[2])
    if spec.type == "Rug":
        return ((1.2, short + 0.7) if obj.type == "Bed" else (1.3, min(long + 0.3, 2.4))) + (spec.box[2],)
    if spec.type in ("Curtain", "Blind"):
        window = next(wd for wd in house.windows if wd.id == support)
        room = house.room(window.room)
        top = min(window.position[2] + window.height / 2 + 0.12, room.ceiling_z - 0.05)
        if spec.type == "Curtain":             # the pair's panels hang beside the window, over its edges
            return (spec.box[0], window.width + 0.5, top - room.floor_z - 0.03)
        return (spec.box[0], window.width + 0.06, min(0.6, 0.45 * window.height))
    return spec.box


def _size(model_id: str, spec: Spec, box_size: tuple[float, float, float]) -> tuple[float, float, float]:
    """The model's box when scaled into ``box_size``: uniformly (keeping its proportions), or as the
    library fits furniture where the spec stretches (a duvet to a bed, a curtain to a window)."""
    if _made_here(model_id) is not None:          # made to measure
        return tuple(round(float(v), 4) for v in box_size)      # type: ignore[return-value]
    natural = np.maximum(np.ptp(library.load_model(model_id).vertices, axis=0), 1e-4)
    box = np.asarray(box_size, np.float64)
    scale = library.fit_scale(natural, box) if spec.stretch else np.full(3, (box / natural).min())
    d, w, h = (round(float(v), 4) for v in natural * scale)
    return d, w, h


# --------------------------------------------------------------------------- the world around a slot

@dataclass
class _Obstacle:
    outline: Polygon
    z0: float
    z1: float


class _Scene:
    """What a layout checks candidates against: every object's pieces, the walls and what was placed."""

    def __init__(self, house: House, models: Mapping[str, int]) -> None:
        self.house, self.models = house, models
        self.placed = {o.id: object_parts(house, o, models.get(o.id)) for o in house.objects}
        self.obstacles: dict[str, list[_Obstacle]] = {}
        for obj in house.objects:
            p = self.placed[obj.id]
            self.obstacles[obj.id] = [_Obstacle(_rect(*fp), lo + p.position[2], hi + p.position[2])
                                      for fp, lo, hi in _piece_rects(p)]
        self.walls: list[_Obstacle] = []
        for room in house.rooms:
            for w in solid_walls(house, room.id):
                (ax, ay), (bx, by) = w.a, w.b
                self.walls.append(_Obstacle(_rect(((ax + bx) / 2, (ay + by) / 2), (max(w.length, 0.01), w.thickness),
                                                  math.atan2(by - ay, bx - ax)), w.z0, w.z1))
        self.dressed: list[_Obstacle] = []
        self.keep_free = [lk.position for lk in room_links(house)] + [d.position[:2] for d in house.doors] + [
            house.station.position[:2]]
        self._triangles: dict[str, np.ndarray] = {}

    def triangles(self, object_id: str) -> np.ndarray:
        """(T, 3, 3) the object's triangles in the house frame (a library model's, or its parts')."""
        if object_id not in self._triangles:
            p = self.placed[object_id]
            mesh = p.model if p.model is not None else p.mesh()
            c, s = math.cos(p.yaw), math.sin(p.yaw)
            turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
            self._triangles[object_id] = np.asarray(mesh.vertices)[np.asarray(mesh.faces)] @ turn.T + p.position
        return self._triangles[object_id]

    def clear(self, outline: Polygon, z0: float, z1: float, skip: str = "", under_feet: bool = False) -> bool:
        """Whether a box of ``outline`` from z0 to z1 keeps clear of every object but ``skip``, the
        walls and the dressing placed so far; ``under_feet``: objects may stand on it by their feet
        (:meth:`only_feet`)."""
        cx, cy = outline.centroid.x, outline.centroid.y
        for oid, obstacles in self.obstacles.items():
            if oid == skip:
                continue
            p = self.placed[oid].position
            if abs(p[0] - cx) < 4.0 and abs(p[1] - cy) < 4.0 and _hits(obstacles, outline, z0, z1) and not (
                    under_feet and self.only_feet(oid, outline, z1)):
                return False
        return not _hits(self.walls, outline, z0, z1) and not _hits(self.dressed, outline, z0, z1)

    def only_feet(self, object_id: str, outline: Polygon, z1: float) -> bool:
        """Whether all of the object that reaches below ``z1`` over ``outline`` is feet: triangles no
        wider than FOOT_SIZE (legs, castors; a sofa's base or a cabinet's plinth is wider)."""
        triangles = self.triangles(object_id)
        low = triangles[triangles[:, :, 2].min(axis=1) < z1]
        x0, y0, x1, y1 = outline.bounds
        lo, hi = low[:, :, :2].min(axis=1), low[:, :, :2].max(axis=1)
        near = low[(hi[:, 0] >= x0) & (lo[:, 0] <= x1) & (hi[:, 1] >= y0) & (lo[:, 1] <= y1)]
        over = [t for t in near if Polygon(t[:, :2]).buffer(1e-6).intersects(outline)]
        return all(np.ptp(t[:, :2], axis=0).max() <= FOOT_SIZE for t in over)


def _hits(obstacles: Sequence[_Obstacle], outline: Polygon, z0: float, z1: float) -> bool:
    return any(o.z0 < z1 and o.z1 > z0 and o.outline.intersects(outline)
               and o.outline.intersection(outline).area > 1e-7 for o in obstacles)


def _piece_rects(p: Placed) -> Iterator[tuple[tuple, float, float]]:
    """Each piece's yawed rectangle on the floor (house frame) and its z range in the body frame."""
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    x, y, _ = p.position
    for lo, hi in p.bounds:
        mx, my = (lo[:2] + hi[:2]) / 2
        yield ((x + c * mx - s * my, y + s * mx + c * my), tuple(hi[:2] - lo[:2] + 1e-4), p.yaw), lo[2], hi[2]


def _rect(centre: tuple[float, float], size: Sequence[float], yaw: float) -> Polygon:
    c, s = math.cos(yaw), math.sin(yaw)
    hx, hy = size[0] / 2, size[1] / 2
    return Polygon([(centre[0] + c * u - s * v, centre[1] + s * u + c * v)
                    for u, v in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy))])


def crossings(triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(P, T) heights where vertical lines through ``points`` (P, 2) cross ``triangles`` (T, 3, 3);
    NaN where a line misses a triangle."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    v0, v1 = (b - a)[:, :2], (c - a)[:, :2]
    denom = v0[:, 0] * v1[:, 1] - v1[:, 0] * v0[:, 1]
    ok = np.abs(denom) > 1e-12
    w = points[:, None, :] - a[None, :, :2]
    safe = np.where(ok, denom, 1.0)
    s = (w[..., 0] * v1[:, 1] - v1[:, 0] * w[..., 1]) / safe
    t = (v0[:, 0] * w[..., 1] - w[..., 0] * v0[:, 1]) / safe
    inside = ok & (s >= -1e-9) & (t >= -1e-9) & (s + t <= 1 + 1e-9)
    z = a[:, 2] + s * (b[:, 2] - a[:, 2]) + t * (c[:, 2] - a[:, 2])
    return np.where(inside, z, np.nan)


def footprint_points(centre: tuple[float, float], size: Sequence[float], yaw: float, n: int = 5,
                     inset: float = 0.001) -> np.ndarray:
    """(n*n, 2) points spread over a yawed rectangle, ``inset`` m inside its edges."""
    u = np.linspace(-size[0] / 2 + inset, size[0] / 2 - inset, n)
    v = np.linspace(-size[1] / 2 + inset, size[1] / 2 - inset, n)
    uu, vv = (g.ravel() for g in np.meshgrid(u, v))
    c, s = math.cos(yaw), math.sin(yaw)
    return np.stack([centre[0] + c * uu - s * vv, centre[1] + s * uu + c * vv], axis=1)


def rest_height(triangles: np.ndarray, centre: tuple[float, float], size: Sequence[float], yaw: float,
                below: float, spec: Spec, xy_bounds: tuple[np.ndarray, np.ndarray] | None = None) -> float | None:
    """Where an object of ``size`` at ``centre``/``yaw`` rests on ``triangles`` at or below ``below``:
    its bottom on the highest crossing under its footprint, or None when part of the support would be
    inside it or too little of its footprint touches (see the module). A coarse lattice (every other
    line of the fine one) turns most candidates down first, at a third of the cost. ``xy_bounds``: the
    triangles' (min, max) over x and y, when the caller keeps them for many candidates."""
    coarse = footprint_points(centre, size, yaw, (REST_SAMPLES + 1) // 2, REST_INSET)
    lo, hi = coarse.min(axis=0) - 1e-3, coarse.max(axis=0) + 1e-3
    tri_lo, tri_hi = xy_bounds or _xy_bounds(triangles)
    near = triangles[np.all((tri_hi >= lo) & (tri_lo <= hi), axis=1)]
    if _resting_bottom(near, coarse, below, size[2], spec) is None:
        return None
    return _resting_bottom(near, footprint_points(centre, size, yaw, REST_SAMPLES, REST_INSET), below, size[2], spec)


def _xy_bounds(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return triangles[:, :, :2].min(axis=1), triangles[:, :, :2].max(axis=1)


def _resting_bottom(triangles: np.ndarray, points: np.ndarray, below: float, height: float, spec: Spec
                    ) -> float | None:
    """:func:`rest_height` on one lattice of footprint ``points``."""
    z = crossings(triangles, points)
    if not z.size:
        return None
    under = np.where(z <= below + REST_TOLERANCE, z, -np.inf)
    top = under.max(axis=1)
    bottom = float(top.max())
    if not math.isfinite(bottom):
        return None
    inside = (z > bottom + REST_TOLERANCE) & (z < bottom + height + 0.01)
    if np.any(inside):
        return None
    if np.mean(top >= bottom - spec.flat) < spec.touching:
        return None
    return bottom


# --------------------------------------------------------------------------- layout

@functools.lru_cache(maxsize=16)
def layout(house: House, models: tuple[tuple[str, int], ...], seed: int) -> tuple[Dressed, ...]:
    """Every slot that finds room, placed (the ``lived-in`` level; ``tidy`` keeps its tidy slots)."""
    scene = _Scene(house, dict(models))
    out = []
    full: set[tuple[str, str, tuple[float, ...]]] = set()     # (support, type, size) with no room left
    # the tidy slots first, so the tidy level is exactly what lived-in places of them
    for slot in sorted(slots(house, seed), key=lambda s: (not s.tidy, s.instance)):
        if (slot.support, slot.type, slot.size) in full:        # it only fills up: the next one fails too
            continue
        rng = random.Random(f"{seed}/dressing/{house.number}/pose/{slot.id}")
        pose = _place(scene, slot, rng)
        if pose is None:
            full.add((slot.support, slot.type, slot.size))
            continue
        dressed = Dressed(slot, *pose)
        out.append(dressed)
        (x, y, z), yaw = dressed.position, dressed.yaw
        scene.dressed.append(_Obstacle(_rect((x, y), slot.size[:2], yaw), z - slot.size[2] / 2,
                                       z + slot.size[2] / 2))
    return tuple(sorted(out, key=lambda d: d.slot.instance))


def _place(scene: _Scene, slot: Slot, rng: random.Random) -> tuple[tuple[float, float, float], float] | None:
    if slot.support.endswith("/floor"):
        return _on_floor_corner(scene, slot, rng)
    if slot.support.endswith("/walls"):
        return _on_wall(scene, slot, rng)
    if slot.support in scene.house.door_by_id:
        return None
    obj = scene.house.object(slot.support)
    if obj.type == "Wall":
        return _at_window(scene, slot, obj, rng)
    if slot.spec is RUG:
        return _rug(scene, slot, obj, rng)
    return _on_support(scene, slot, obj, rng)


def _support_frame(scene: _Scene, obj: HouseObject) -> tuple[np.ndarray, float, np.ndarray, np.ndarray]:
    """(centre xy, front heading, body-frame extent lo, hi) of a support."""
    p = scene.placed[obj.id]
    lo, hi = p.extent()
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    mid = (lo[:2] + hi[:2]) / 2
    centre = np.array([p.position[0] + c * mid[0] - s * mid[1], p.position[1] + s * mid[0] + c * mid[1]])
    return centre, p.front if p.front is not None else p.yaw, lo, hi


def _on_support(scene: _Scene, slot: Slot, obj: HouseObject, rng: random.Random
                ) -> tuple[tuple[float, float, float], float] | None:
    p = scene.placed[obj.id]
    lo, hi = p.extent()
    front = p.front if p.front is not None else p.yaw
    triangles = scene.triangles(obj.id)
    xy_bounds = _xy_bounds(triangles)
    d, w, h = slot.size
    reach = max(d, w) / 2
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    shelf = _support_kind(obj) == "Shelf"
    levels = _boards(triangles, p, lo, hi) if shelf else [p.position[2] + hi[2]]
    dining = obj.type == "Table" and _support_kind(obj) == "Table"
    places = _places(scene, obj, p, lo, hi, reach, rng) if dining and slot.type == "Plate" else []
    for attempt in range(CANDIDATES):
        # a point of the support's top, in its body frame, away from its edges by the object's reach
        span = np.maximum((hi[:2] - lo[:2]) / 2 - reach, 0.0)
        if dining and slot.type in ("FruitBowl", "Vase"):       # the middle of a dining table
            span = span * 0.3
        u, v = (rng.uniform(-1, 1) * span + (lo[:2] + hi[:2]) / 2)
        if places and attempt < 2 * len(places):                 # a plate at a place, before a chair
            u, v = places[(slot.order + attempt) % len(places)]
        if obj.type == "Bed" or obj.type == "Sofa":
            u, v = _soft_spot(slot, p, lo, hi, rng, attempt)
        x, y = p.position[0] + c * u - s * v, p.position[1] + s * u + c * v
        yaw = front if slot.spec.facing == "support" else rng.uniform(-math.pi, math.pi)
        outline = _rect((x, y), (d, w), yaw)
        for level in rng.sample(levels, len(levels)) if shelf else levels:
            bottom = rest_height(triangles, (x, y), (d, w, h), yaw, level, slot.spec, xy_bounds)
            if bottom is None or bottom < p.position[2] + lo[2] + 0.02:
                continue
            z0, z1 = bottom + REST_TOLERANCE, bottom + h
            # on a shelf, clear of the case's own sides, back and dividers too (between the rest lines)
            if scene.clear(outline, z0, z1, skip=obj.id) and not (shelf and _hits(scene.obstacles[obj.id], outline,
                                                                                   z0, z1)):
                return (x, y, bottom + h / 2), yaw
    return None


BOARD_SHARE = 0.15            # of the lines down through a shelf's footprint that cross a board
BOARD_GAP = 0.03              # m: a crossing this close under a board's top is its underside


def _boards(triangles: np.ndarray, p: Placed, lo: np.ndarray, hi: np.ndarray) -> list[float]:
    """The tops of a bookcase's or a shelf's boards (house frame), highest first: heights where many of
    a grid of vertical lines over its footprint cross it (one line at its centre may meet a divider,
    or a model's own books), each board's underside left out. Things rest on them by
    :func:`rest_height`, which keeps them under the board above."""
    u, v = np.meshgrid(np.linspace(lo[0], hi[0], 7)[1:-1], np.linspace(lo[1], hi[1], 13)[1:-1])
    points = np.array([_body_to_house(p, q) for q in np.stack([u.ravel(), v.ravel()], axis=1)])
    zs = crossings(triangles, points)
    found: dict[float, float] = {}
    for row in zs:
        for key in {round(float(z), 2) for z in row[np.isfinite(row)]}:
            found[key] = found.get(key, 0.0) + 1.0 / len(points)
    common = sorted((z for z in zs[np.isfinite(zs)].ravel() if found[round(float(z), 2)] >= BOARD_SHARE),
                    reverse=True)
    tops: list[float] = []
    for z in common:
        if not tops or tops[-1] - z > BOARD_GAP:
            tops.append(float(z))
    return tops or [p.position[2] + hi[2]]


def _places(scene: _Scene, obj: HouseObject, p: Placed, lo: np.ndarray, hi: np.ndarray, reach: float,
            rng: random.Random) -> list[tuple[float, float]]:
    """A dining table's places (body frame): the points of its top nearest each chair at it, a plate's
    reach in from the edge; without chairs, two a side along its long sides."""
    inset = reach + 0.04
    a, b = lo[:2] + inset, hi[:2] - inset
    if np.any(a > b):
        return []
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    out = []
    for other in scene.house.objects:
        if other.type != "Chair" or other.room != obj.room:
            continue
        dx, dy = other.position[0] - p.position[0], other.position[1] - p.position[1]
        u, v = c * dx + s * dy, -s * dx + c * dy
        if lo[0] - 0.9 < u < hi[0] + 0.9 and lo[1] - 0.9 < v < hi[1] + 0.9:
            out.append((float(np.clip(u, a[0], b[0])), float(np.clip(v, a[1], b[1]))))
    if not out:
        long = 0 if hi[0] - lo[0] >= hi[1] - lo[1] else 1
        mid = (a + b) / 2
        for along in (-0.3, 0.3):
            for side in (a[1 - long], b[1 - long]):
                q = [0.0, 0.0]
                q[long] = float(np.clip(mid[long] + along, a[long], b[long]))
                q[1 - long] = float(side)
                out.append((q[0], q[1]))
    rng.shuffle(out)
    return out


def _soft_spot(slot: Slot, p: Placed, lo: np.ndarray, hi: np.ndarray, rng: random.Random, attempt: int = 0
               ) -> tuple[float, float]:
    """Where on a bed or a sofa (body frame): pillows at the head, the duvet over the foot, cushions
    along the back, a throw on the seat by an arm. The body's +x is its front (a bed's foot, a sofa's
    seat edge) turned by the model's facing, so go by the front heading. Later attempts move away from
    the head or the back, where the first found the model's own headboard or back in the way."""
    f = (p.front if p.front is not None else p.yaw) - p.yaw
    fx, fy = math.cos(f), math.sin(f)
    depth = abs(fx) * (hi[0] - lo[0]) + abs(fy) * (hi[1] - lo[1])
    width = abs(fy) * (hi[0] - lo[0]) + abs(fx) * (hi[1] - lo[1])
    mid = (lo[:2] + hi[:2]) / 2
    d, w, _ = slot.size
    step = 0.025 * attempt
    if slot.type == "Pillow":
        along, across = -depth / 2 + d / 2 + 0.03 + step + rng.uniform(0, 0.02), 0.0
        if slot.spec.lived_in > 1 and width > SINGLE_BED:
            across = (-1) ** slot.order * (width / 4 - 0.02) + rng.uniform(-0.02, 0.02)
    elif slot.type == "Duvet":
        along, across = depth / 2 - d / 2 - rng.uniform(0.0, 0.06) - step, 0.0
    elif slot.type == "Cushion":
        along = -depth / 2 + d / 2 + 0.06 + step + rng.uniform(0, 0.03)
        across = (slot.order - 1) * min(w * 1.15, width / 3.2) + rng.uniform(-0.04, 0.04)
    else:                          # by either arm, on the seat's front half
        side = 1 if (attempt + slot.order) % 2 == 0 else -1
        along = rng.uniform(0.0, max(depth / 2 - d / 2 - 0.02, 0.0))
        across = side * max(width / 2 - w / 2 - 0.1 - 0.02 * (attempt // 2), 0.0)
    return mid[0] + fx * along - fy * across, mid[1] + fy * along + fx * across


def _body_to_house(p: Placed, uv: np.ndarray) -> tuple[float, float]:
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    return p.position[0] + c * uv[0] - s * uv[1], p.position[1] + s * uv[0] + c * uv[1]


def _floor_ok(scene: _Scene, slot: Slot, x: float, y: float, room: Room) -> bool:
    if not room.contains(x, y):
        return False
    return all(math.dist((x, y), q) > FLOOR_CLEARANCE + max(slot.size[:2]) / 2 for q in scene.keep_free)


def _rug(scene: _Scene, slot: Slot, obj: HouseObject, rng: random.Random
         ) -> tuple[tuple[float, float, float], float] | None:
    """A rug in front of a sofa or beside a bed's foot, partly under it where nothing of it stands but
    feet (a coffee table's legs may stand on it)."""
    p = scene.placed[obj.id]
    lo, hi = p.extent()
    front = p.front if p.front is not None else p.yaw
    room = scene.house.room(obj.room)
    d, w, h = slot.size
    f = front - p.yaw
    depth = abs(math.cos(f)) * (hi[0] - lo[0]) + abs(math.sin(f)) * (hi[1] - lo[1])
    centre = np.array(_body_to_house(p, (lo + hi)[:2] / 2))
    width = abs(math.sin(f)) * (hi[0] - lo[0]) + abs(math.cos(f)) * (hi[1] - lo[1])
    ahead = np.array([math.cos(front), math.sin(front)])
    beside = np.array([-ahead[1], ahead[0]])
    candidates = [(centre + ahead * (depth / 2 + d / 2 - overlap) + beside * shift, front)
                  for overlap in (0.3, 0.15, 0.0, -0.15) for shift in (0.0, 0.25, -0.25, 0.5, -0.5)]
    if obj.type == "Bed":              # or along either side of a bed, turned across it, towards its foot
        candidates += [(centre + beside * side * (width / 2 + d / 2 - overlap) + ahead * along, front + math.pi / 2)
                       for overlap in (0.2, 0.0) for along in (0.0, 0.3, 0.6) for side in (1, -1)]
    for (x, y), yaw in candidates:
        x, y = x + rng.uniform(-0.02, 0.02), y + rng.uniform(-0.02, 0.02)
        outline = _rect((x, y), (d, w), yaw)
        if not all(room.contains(*q) for q in footprint_points((x, y), (d, w), yaw, 4)):
            continue
        # the robot drives over a rug: it only keeps a doorway's and the station's own spot free
        if any(outline.distance(Point(*q)) < 0.45 for q in scene.keep_free):
            continue
        if scene.clear(outline, room.floor_z + 0.001, room.floor_z + h, under_feet=True):
            return (float(x), float(y), room.floor_z + h / 2), yaw
    return None


def _on_floor_corner(scene: _Scene, slot: Slot, rng: random.Random
                     ) -> tuple[tuple[float, float, float], float] | None:
    room = scene.house.room(slot.room)
    corners = list(range(len(room.floor)))
    rng.shuffle(corners)
    d, w, h = slot.size
    r = max(d, w) / 2
    taken = 0
    for i in corners:
        a, b, c = (np.asarray(room.floor[(i + k) % len(room.floor)], np.float64) for k in (-1, 0, 1))
        e1, e2 = a - b, c - b
        n1, n2 = np.linalg.norm(e1), np.linalg.norm(e2)
        if n1 < 2 * r + 0.1 or n2 < 2 * r + 0.1 or abs(float(np.dot(e1, e2)) / (n1 * n2)) > 0.2:
            continue
        for gap in (0.03, 0.1):
            x, y = b + (e1 / n1 + e2 / n2) * (max(d, w) / 2 + gap)
            if not _floor_ok(scene, slot, x, y, room):
                continue
            yaw = math.atan2(e1[1], e1[0]) + rng.randrange(4) * math.pi / 2
            if scene.clear(_rect((x, y), (d, w), yaw), room.floor_z + 0.001, room.floor_z + h):
                if taken == slot.order:
                    return (x, y, room.floor_z + h / 2), yaw
                taken += 1
                break
    return None


def _room_walls(room: Room) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(start, end, inward normal) of each edge of the room's floor outline: the walls' room faces."""
    out = []
    pts = [np.asarray(q, np.float64) for q in room.floor]
    for i, a in enumerate(pts):
        b = pts[(i + 1) % len(pts)]
        e = b - a
        length = float(np.linalg.norm(e))
        if length < 0.3:
            continue
        n = np.array([-e[1], e[0]]) / length
        mid = (a + b) / 2
        if not room.contains(*(mid + 0.05 * n)):
            n = -n
        out.append((a, b, n))
    return out


def _on_wall(scene: _Scene, slot: Slot, rng: random.Random) -> tuple[tuple[float, float, float], float] | None:
    """A picture or a towel hung flat on a wall of its room, where the wall is solid at that height."""
    room = scene.house.room(slot.room)
    walls = _room_walls(room)
    d, w, h = slot.size
    centre_z = room.floor_z + (WALL_CENTRE if slot.type == "Picture" else TOWEL_TOP - h / 2)
    for _ in range(CANDIDATES * 2):
        a, b, n = walls[rng.randrange(len(walls))]
        length = float(np.linalg.norm(b - a))
        if length < w + 0.3:
            continue
        t = rng.uniform(w / 2 + 0.15, length - w / 2 - 0.15)
        along = (b - a) / length
        x, y = a + along * t + n * (d / 2 + 0.001)
        yaw = math.atan2(n[1], n[0])
        if not _wall_behind(scene, (x, y), n, d, w, centre_z - h / 2, centre_z + h / 2):
            continue
        if scene.clear(_rect((x, y), (d, w + 0.06), yaw), centre_z - h / 2 - 0.05, centre_z + h / 2 + 0.05):
            return (float(x), float(y), centre_z), yaw
    return None


def _wall_behind(scene: _Scene, centre: Sequence[float], n: np.ndarray, d: float, w: float,
                 z0: float, z1: float) -> bool:
    """Whether solid wall stands right behind the whole back of a flat object (no doorway, no window)."""
    back = np.asarray(centre) - n * (d / 2 + 0.02)
    yaw = math.atan2(n[1], n[0])
    strip = _rect(tuple(back), (0.02, w), yaw)
    cover = [o.outline for o in scene.walls if o.z0 <= z0 and o.z1 >= z1 and o.outline.intersects(strip)]
    if not cover:
        return False
    covered = sum(strip.intersection(o).area for o in cover)
    return covered >= 0.98 * strip.area


def _at_window(scene: _Scene, slot: Slot, obj: HouseObject, rng: random.Random
               ) -> tuple[tuple[float, float, float], float] | None:
    """Curtains either side of a window, from above it to just above the floor; a blind over its top."""
    window = next(wd for wd in scene.house.windows if wd.id == obj.id)
    room = scene.house.room(window.room)
    n = np.array([math.cos(window.yaw + math.pi / 2), math.sin(window.yaw + math.pi / 2)])
    along = np.array([math.cos(window.yaw), math.sin(window.yaw)])
    if abs(float(np.dot(n, along))) > 1e-6:
        along = np.array([-n[1], n[0]])
    centre = np.asarray(window.position[:2], np.float64)
    if not room.contains(*(centre + 0.3 * n)):
        n = -n
    # the window's own pieces stand this far into the room from its centre
    reach = max(float(np.dot(np.asarray(q) - centre, n)) for q in
                (xy for poly in (ob.outline for ob in scene.obstacles[obj.id]) for xy in poly.exterior.coords))
    surface = min((_to_segment(centre, wl.a, wl.b), wl.thickness / 2) for wl in scene.house.walls
                  if wl.room == window.room)[1]          # the wall's room face, from the window's centre
    surface = _wall_face(scene, centre, n, along, window.width + 0.2, surface)
    wall = max(reach, surface)
    d, w, h = slot.size
    top = min(window.position[2] + window.height / 2 + 0.12, room.ceiling_z - 0.05)
    yaw = math.atan2(n[1], n[0])
    if slot.type == "Curtain":
        # the pair centred on the window, in front of its frame; solid wall behind both panels' outer parts
        x, y = centre + n * (wall + d / 2 + 0.002)
        z = top - h / 2
        ext = min((w - window.width) / 2, 0.2)
        for side in (1, -1):
            px, py = centre + n * (surface + d / 2 + 0.001) + along * side * (w / 2 - ext / 2)
            if not room.contains(px, py) or not _wall_behind(scene, (px, py), n, d, ext, z - h / 2, z + h / 2):
                return None
        if scene.clear(_rect((x, y), (d, w), yaw), z - h / 2, z + h / 2):
            return (float(x), float(y), z), yaw
        return None
    x, y = centre + n * (wall + d / 2 + 0.002)
    z = top - h / 2
    if scene.clear(_rect((x, y), (d, w), yaw), z - h / 2, z + h / 2):
        return (float(x), float(y), z), yaw
    return None


def _wall_face(scene: _Scene, centre: np.ndarray, n: np.ndarray, along: np.ndarray, width: float,
               fallback: float) -> float:
    """How far from a window's centre its wall's room face stands (along ``n``), as the walls' solids
    have it beside the window (the house's wall lines may stand off its centre)."""
    yaw = math.atan2(n[1], n[0])
    found = []
    for side in (1, -1):           # thin probes across the wall just beside the window
        probe = _rect(tuple(centre + n * 0.05 + along * side * (width / 2)), (0.7, 0.01), yaw)
        for o in scene.walls:
            if not o.outline.intersects(probe):
                continue
            part = o.outline.intersection(probe)
            for poly in getattr(part, "geoms", [part]):
                if poly.area < 1e-7:
                    continue
                t = [float(np.dot(np.asarray(q) - centre, n)) for q in poly.exterior.coords]
                if min(t) <= 0.02 and max(t) < 0.35:          # the wall the window is in, not one across
                    found.append(max(t))
    return max(found) if found else fallback


def _to_segment(p: np.ndarray, a: Sequence[float], b: Sequence[float]) -> float:
    a_, b_ = np.asarray(a, np.float64), np.asarray(b, np.float64)
    e = b_ - a_
    t = float(np.clip(np.dot(p - a_, e) / max(float(np.dot(e, e)), 1e-12), 0.0, 1.0))
    return float(np.linalg.norm(p - (a_ + t * e)))


def dressing_mesh(d: Dressed) -> trimesh.Trimesh:
    """The dressing object's triangles in the house frame (for tests and tools)."""
    p = d.placed()
    assert p.model is not None
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return trimesh.Trimesh(np.asarray(p.model.vertices) @ turn.T + p.position, p.model.faces, process=False)
