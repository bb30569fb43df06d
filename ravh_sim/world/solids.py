"""What each object is made of where it stands: its model's parts, placed in the house.

Why one place: the pybullet world draws an object as its parts merged and collides with each part
(so the laser sees between table legs and hits a door leaf where the camera sees it), and the
free-space map blocks the floor under the parts that a robot's body would hit (a table top blocks
a tall robot; the empty corner of an L-shaped sofa does not), and the obstacle map (/map) is their cut
at the laser's height (:meth:`Placed.section`). Physics, sensors and navigation then agree on every
surface because they read the same parts.

A :class:`Placed` object holds its model in its body frame (box centre at the origin, unrotated)
and the body's pose; the world turns it by ``yaw`` about z and moves it to ``position``. The model is
a furniture-library model (:mod:`ravh_sim.world.library`: modelled, textured, colliding as its own
triangles) where the library has one of the object's kind, else procedural convex parts
(:mod:`ravh_sim.world.furniture`: doors, windows, worktops, pictures, mirrors, wall shelves,
toilet brushes, the station).
"""
from __future__ import annotations

import functools
import math
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
from shapely.geometry import MultiPoint, Polygon

from ravh_sim.world import library, made_art
from ravh_sim.world.facing import OPENING_FRONT, choose_facing, front_axis, suits_box
from ravh_sim.world.furniture import build_parts, variant_count
from ravh_sim.world.geometry import box_corners
from ravh_sim.world.house import Door, House, HouseObject
from ravh_sim.world.mesh import box, merged
from ravh_sim.world.palette import PALETTE
from ravh_sim.world.structure import doorway_ends

DOOR_LEAF_THICKNESS = 0.05
"""m: the door leaf model's thickness (the doorway's frame is part of the walls)."""
JAMB_COLOUR = "white"
_Y = np.array([0.0, 1.0, 0.0])             # a door body's axis along the doorway
MAX_FOOTPRINT_BOXES = 48                   # a library model's floor footprint: its largest pieces' boxes
APPLIANCE_LEAST_WIDTH_SCALE = 0.85
"""Least scale of an appliance model's front width (``OPENING_FRONT``): appliances are built in standard
widths, so a model squeezed further reads as another appliance (a 93 cm side-by-side fridge fitted to a
63 cm combi's box has 30 cm doors, named "shoji" or "prison" by an ImageNet classifier). Models that
fit without it rank first; a box none fits takes the best proportions as before."""

Footprint = tuple[tuple[float, float], tuple[float, float], float]
"""A yawed rectangle on the floor: centre (x, y), size (along yaw, across), yaw."""


@dataclass(frozen=True)
class Placed:
    """An object's model in its body frame and the body's pose in the house: procedural convex
    ``parts``, or a fitted library ``model`` (then ``parts`` is empty)."""
    parts: tuple[trimesh.Trimesh, ...]
    bounds: np.ndarray                     # (pieces, 2, 3): each part's (or model piece's) min and max corner
    position: tuple[float, float, float]
    yaw: float
    model: trimesh.Trimesh | None = None     # a library model, fitted (library.with_vertices)
    front: float | None = None             # heading of a library model's front in the house frame

    def mesh(self) -> trimesh.Trimesh:
        """The procedural parts merged: what the camera draws of them."""
        return merged(self.parts)

    def extent(self) -> tuple[np.ndarray, np.ndarray]:
        """(min corner, max corner) of everything the object is, in its body frame."""
        return self.bounds[:, 0].min(axis=0), self.bounds[:, 1].max(axis=0)

    def footprints(self, z_low: float, z_high: float, min_size: float = 0.0) -> Iterator[Footprint]:
        """Floor rectangles (in the body's yawed frame) of the parts that reach into the height
        band (z_low, z_high) of the house frame: a part's rectangle is its extent along the body's
        axes, exact for the boxes most parts are and a little larger for round or slanted ones.

        A rectangle narrower than ``min_size`` grows to it towards the middle of the object, so a
        raster that draws thin shapes as lines one cell wide never draws beyond the object.
        """
        x, y, z = self.position
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        reach = (hi[:, 2] + z > z_low) & (lo[:, 2] + z < z_high)
        lo, hi = lo[reach, :2], hi[reach, :2]
        half = np.maximum(hi - lo, min_size) / 2
        whole_lo, whole_hi = self.bounds[:, 0, :2].min(axis=0), self.bounds[:, 1, :2].max(axis=0)
        middle = np.clip((lo + hi) / 2, np.minimum(whole_lo + half, 0.0), np.maximum(whole_hi - half, 0.0))
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        for (mx, my), (hx, hy) in zip(middle.tolist(), half.tolist()):
            yield (x + c * mx - s * my, y + s * mx + c * my), (2 * hx, 2 * hy), self.yaw

    def section(self, z: float) -> np.ndarray:
        """Where the horizontal plane at height ``z`` (house frame) cuts the object as the collision world
        has it, so where a planar laser at that height ends on it: (n, 2, 2) segments, two (x, y) ends
        each, in the house frame (empty where nothing reaches the plane).

        A procedural part collides as its convex hull (the world's ``_parts_collision``), so its cut is
        the hull's outline, a closed convex polygon (one point or segment where the plane only touches
        it); a library model collides as its own triangles (``_model_collision``), so its cut is where
        the plane crosses them: closed outlines where the model is closed around that height, open
        ones (an open shelf's front) where it is not.
        """
        local_z = z - self.position[2]
        if self.model is not None:
            local = _model_section(self.model, local_z)
        else:
            reach = (self.bounds[:, 0, 2] <= local_z + _ON_PLANE) & (self.bounds[:, 1, 2] >= local_z - _ON_PLANE)
            cuts = [_hull_section(self.parts[i].vertices, local_z) for i in np.flatnonzero(reach)]
            local = np.concatenate(cuts) if cuts else np.zeros((0, 2, 2))
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return local @ np.array([[c, s], [-s, c]]) + np.asarray(self.position[:2], np.float64)


_ON_PLANE = 1e-9                           # m: a vertex this close to a cutting plane lies in it


def _hull_section(vertices: np.ndarray, z: float) -> np.ndarray:
    """(k, 2, 2) edges of the convex polygon where the plane at height ``z`` cuts the convex hull of
    ``vertices``: the hull of the vertices in the plane and of the crossings of every segment from a
    vertex above it to one below (the cut of a convex hull is the hull of those points)."""
    height = vertices[:, 2] - z
    above, below = vertices[height > _ON_PLANE], vertices[height < -_ON_PLANE]
    da, db = above[:, None, 2] - z, below[None, :, 2] - z                      # (a, 1) > 0, (1, b) < 0
    crossings = above[:, None, :2] + (da / (da - db))[..., None] * (below[None, :, :2] - above[:, None, :2])
    points = np.concatenate([vertices[np.abs(height) <= _ON_PLANE, :2], crossings.reshape(-1, 2)])
    if not len(points):
        return np.zeros((0, 2, 2))
    hull = _convex_hull(points)
    return np.stack([hull, np.roll(hull, -1, axis=0)], axis=1)


def _convex_hull(points: np.ndarray) -> np.ndarray:
    """(k, 2) corners of the convex hull of (n, 2) points (shapely; collinear points dropped, so a flat
    set gives its two ends and a single point itself)."""
    hull = MultiPoint(points).convex_hull
    corners = np.asarray(hull.exterior.coords if isinstance(hull, Polygon) else hull.coords, np.float64)
    return corners[:-1] if isinstance(hull, Polygon) else corners


def _model_section(fitted: trimesh.Trimesh, z: float) -> np.ndarray:
    """(n, 2, 2) segments where the plane at height ``z`` (body frame) crosses a library model's triangles."""
    heights = fitted.vertices[:, 2]
    if not heights.min() <= z <= heights.max():
        return np.zeros((0, 2, 2))
    segments = trimesh.intersections.mesh_plane(fitted, (0.0, 0.0, 1.0), (0.0, 0.0, z))
    return np.asarray(segments, np.float64).reshape(-1, 2, 3)[:, :, :2]


def object_parts(house: House, obj: HouseObject, model: int | None) -> Placed:
    """``obj`` as model variant ``model`` shows it (doors: the leaf, closed, see :func:`door_parts`)."""
    if obj.id in house.door_by_id:
        return door_parts(house, house.door_by_id[obj.id], model)
    box = obj.box(model)
    variant = obj.default_model if model is None else model
    if obj.own_model is not None:              # variant 0: the house's own model, the others shift by one
        if variant == 0:
            fitted, bounds = _own_fitted(obj.own_model, tuple(box.size))
            return Placed((), bounds, box.position, obj.yaw, fitted, obj.yaw)
        variant -= 1
    walls = tuple((w.a, w.b) for w in house.walls if w.room == obj.room and w.kind != "lintel")
    facing = _facing(tuple(box.position[:2]), obj.yaw, tuple(box.size), walls, front_axis(obj.type),
                     _blockers(house, obj))
    records = _models_of(obj)
    if records:
        record, facing = _library_choice(records, variant, np.asarray(box.size), facing, front_axis(obj.type))
        fitted, bounds = _fitted(record.id, tuple(box.size), facing)
        return Placed((), bounds, box.position, obj.yaw, fitted, obj.yaw + facing * math.pi / 2)
    parts, bounds = _parts(obj.type, tuple(box.size), variant, facing, obj.prefab)
    return Placed(parts, bounds, box.position, obj.yaw)


def _models_of(obj: HouseObject) -> tuple[library.LibraryRecord, ...]:
    """The models an object's variants choose among: its kind's library models; for a picture, the wall
    art made here (:mod:`ravh_sim.world.made_art`), each picture starting at its own (seeded by where
    it hangs: the houses' pictures all name upstream model 0)."""
    if obj.type != "Picture":
        return library.models_of(library.kind_of(obj.type, obj.prefab))
    art = made_art.records(made_art.KIND)
    start = zlib.crc32(f"{obj.id}/{np.round(obj.position, 3).tolist()}".encode()) % len(art)
    return art[start:] + art[:start]


def _library_choice(records: tuple[library.LibraryRecord, ...], variant: int, size: np.ndarray, facing: int,
                    front: str) -> tuple[library.LibraryRecord, int]:
    """Model variant ``variant`` of an object and the facing it is drawn at: the kind's models in
    order of how well they fit the box, each turned the way it fits best where the type's front
    may look either way along the box ('any': a table's long side follows the box's long side)."""
    if not suits_box(front, size, facing):
        facing = (facing + 1) % 4
    facings = (facing, (facing + 1) % 4) if front == "any" else (facing,)

    def box_for(f: int) -> np.ndarray:
        return size[[0, 1, 2] if f % 2 == 0 else [1, 0, 2]]

    def misfit(record: library.LibraryRecord, f: int) -> float:
        return library.misfit(np.asarray(record.size), box_for(f))

    def squeezed(record: library.LibraryRecord) -> bool:    # front width: the model's y (its front is +x)
        return front == "door" and box_for(facing)[1] < APPLIANCE_LEAST_WIDTH_SCALE * record.size[1]

    ranked = sorted(records, key=lambda r: (squeezed(r), min(misfit(r, f) for f in facings)))
    record = ranked[variant % len(ranked)]
    return record, min(facings, key=lambda f: misfit(record, f))


def model_count(obj: HouseObject) -> int:
    """How many models the Object Models setting chooses among for ``obj``: its kind's library
    models (a picture's: the wall art made here), or the procedural variants of its type, after the
    house's own model where it has one."""
    own = obj.own_model is not None
    return own + (len(_models_of(obj)) or variant_count(obj.type))


def door_parts(house: House, door: Door, model: int | None) -> Placed:
    """The closed door: its leaf (see :func:`door_pose`) and jambs from the leaf's edges to the wall
    ends beside the doorway, where a leaf narrower than its gap in the walls would leave see-through
    slits. The jambs go with the leaf: an open doorway keeps its whole width."""
    width, _, height = door.leaf
    variant = house.object(door.id).default_model if model is None else model
    leaf, _ = _parts("Door", (DOOR_LEAF_THICKNESS, width, height), variant, 0, "")
    left, right = doorway_ends(house, door)
    jambs = tuple(box(((a + b) / 2 * _Y), (DOOR_LEAF_THICKNESS, b - a, height), PALETTE.index(JAMB_COLOUR))
                  for a, b in ((left, -width / 2), (width / 2, right)) if b - a > 1e-4)
    parts = leaf + jambs
    return Placed(parts, np.array([part.bounds for part in parts]), *door_pose(house, door))


def door_pose(house: House, door: Door) -> tuple[tuple[float, float, float], float]:
    """Where a closed door's leaf stands: across the doorway on the lower of its rooms' floors,
    its thickness along the doorway's depth (body position, yaw)."""
    floor = min(house.room(r).floor_z for r in door.rooms)
    return (door.position[0], door.position[1], floor + door.leaf[2] / 2), door.yaw - math.pi / 2


@functools.lru_cache(maxsize=8192)
def _parts(object_type: str, size: tuple[float, float, float], variant: int, facing: int,
           prefab: str) -> tuple[tuple[trimesh.Trimesh, ...], np.ndarray]:
    """The parts and their bounds, cached: the world, every free-space map and every door or model
    change ask again."""
    parts = tuple(build_parts(object_type, np.asarray(size), variant, facing, prefab))
    return parts, np.array([part.bounds for part in parts])


@functools.lru_cache(maxsize=1024)
def _fitted(model_id: str, size: tuple[float, float, float], facing: int
            ) -> tuple[trimesh.Trimesh, np.ndarray]:
    """A library model (or wall art made to the box) fitted into a box (turned to ``facing`` as
    procedural models are) and the boxes of its largest pieces, cached like :func:`_parts`."""
    extents = np.asarray(size, np.float64)
    d, w, h = extents[[0, 1, 2] if facing % 2 == 0 else [1, 0, 2]]
    model = made_art.model(model_id, (d, w, h)) if made_art.is_made(model_id) else library.load_model(model_id)
    turn = trimesh.transformations.rotation_matrix(facing * np.pi / 2, (0, 0, 1))[:3, :3]
    vertices = library.fit(model, np.array([d, w, h])) @ turn.T
    return library.with_vertices(model, vertices), _piece_bounds(vertices, model.faces, model.face_attributes["piece"])


@functools.lru_cache(maxsize=1024)
def _own_fitted(path: Path, size: tuple[float, float, float]) -> tuple[trimesh.Trimesh, np.ndarray]:
    """A house's own model stretched to fill its box exactly, as the home's drawing sizes it (it was
    drawn for this box and faces the object's yaw), with its pieces' boxes, cached like :func:`_fitted`."""
    model = library.load_model_file(path)
    lo, hi = model.vertices.min(axis=0), model.vertices.max(axis=0)
    vertices = (model.vertices - (lo + hi) / 2) * (np.asarray(size, np.float64) / np.maximum(hi - lo, 1e-9))
    return library.with_vertices(model, vertices), _piece_bounds(vertices, model.faces, model.face_attributes["piece"])


def _piece_bounds(vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """(pieces, 2, 3) boxes of a model's connected pieces (legs, seat, back...), the largest
    MAX_FOOTPRINT_BOXES kept and every smaller piece merged into the nearest kept box, so the
    boxes cover the model and the free-space map sees between its legs."""
    corners = vertices[faces]                                    # (M, 3, 3)
    count = int(labels.max()) + 1
    lo = np.full((count, 3), np.inf)
    hi = np.full((count, 3), -np.inf)
    np.minimum.at(lo, labels, corners.min(axis=1))
    np.maximum.at(hi, labels, corners.max(axis=1))
    order = np.argsort(-np.prod(np.maximum(hi - lo, 1e-3), axis=1), kind="stable")
    keep, rest = order[:MAX_FOOTPRINT_BOXES], order[MAX_FOOTPRINT_BOXES:]
    lo_k, hi_k = lo[keep].copy(), hi[keep].copy()
    centres = (lo_k + hi_k) / 2
    for piece in rest:
        nearest = int(np.argmin(np.linalg.norm(centres - (lo[piece] + hi[piece]) / 2, axis=1)))
        lo_k[nearest] = np.minimum(lo_k[nearest], lo[piece])
        hi_k[nearest] = np.maximum(hi_k[nearest], hi[piece])
    return np.stack([lo_k, hi_k], axis=1)


@functools.lru_cache(maxsize=8192)
def _facing(center: tuple[float, float], yaw: float, size: tuple[float, float, float],
            walls: tuple, front: str, blockers: tuple) -> int:
    """Cached :func:`choose_facing`: every free-space map asks again for every object."""
    return choose_facing(center, yaw, size, walls, front=front, blockers=blockers)


STANDING_HEIGHT_M = 0.5          # a neighbour this tall, standing on the floor, blocks a door in front of it


def _blockers(house: House, obj: HouseObject) -> tuple:
    """The edges of the house's boxes of what stands on the floor in an appliance's room (kitchen
    units, a washbasin's cabinet, another appliance); nothing for other types."""
    if obj.type not in OPENING_FRONT:
        return ()
    edges = []
    for other in house.objects:
        x, y, z = other.position
        w, d, h = other.size
        if other is obj or other.room != obj.room or h < STANDING_HEIGHT_M or z - h / 2 > 0.1:
            continue
        corners = [(float(cx), float(cy)) for cx, cy in box_corners((x, y), (w, d), other.yaw)]
        edges += [(corners[k], corners[(k + 1) % 4]) for k in range(4)]
    return tuple(edges)
