"""``ravh import-furniture``: the furniture library built from Sweet Home 3D's open catalogues.

Why: a detector trained on photos recognises modelled furniture, not boxes. Sweet Home 3D's
catalogues (Debian's ``sweethome3d-furniture`` and the default catalogue in ``sweethome3d.jar``) are
the standard open library of home furniture: zip archives of OBJ + MTL + textures with a
``*FurnitureCatalog.properties`` that names every model, its category, size, creator and licence.

This maintainer's tool (like ``ravh import-houses``) picks models for our object types by name and
category (:data:`RULES`), turns them into our frame (Sweet Home 3D models are Y-up with their front
towards +z, scaled to the catalogue's width/depth/height in cm; ours are z-up, front along +x, in
metres, centred on their box), simplifies each to :data:`TRIANGLE_BUDGET` triangles, shrinks
textures to :data:`TEXTURE_TEXELS` and writes the compact committed set under ``furniture/`` (see
:mod:`ravh_sim.world.library` for the format and its reader) with ``ATTRIBUTION.md``. Users never
need the catalogues: the committed set is all the simulator reads.
"""
from __future__ import annotations

import hashlib
import io
import json
import re
import shutil
import zipfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

import cv2
import numpy as np
import trimesh

from ravh_sim.errors import UserError
from ravh_sim.world.library import (
    CATALOG_FORMAT,
    CLEAR_GLASS_OPACITY,
    FULL_SUFFIX,
    LibraryMaterial,
    full_texture,
    is_clear_glass,
    material_kind,
    piece_labels,
)

TRIANGLE_BUDGET = 1000
"""Triangles of a model 1.5 m or larger after simplification (smaller ones get a share in proportion
to their size, at least MIN_TRIANGLES). A 640x480 frame shows a sofa over ~300 px: 1k triangles keep
its silhouette and cushions; on llvmpipe every triangle costs in the depth pre-pass and in partly
covered shading quads, and pybullet builds a collider of each, so house 15 went from 11k triangles
(procedural) to 52k here (80k with 2k per model: +50 % frame time under load; 130k in house 23 with
2.5k: 830 MB peak in one process)."""
MIN_TRIANGLES = 150
OVER_BUDGET = 1.5
ABSOLUTE_BUDGET = 1500
"""A model that simplification cannot bring within OVER_BUDGET times its budget (keeping AREA_KEPT of its
surface), nor under ABSOLUTE_BUDGET (thousands of loose pieces), is passed over for the kind's next
match; a kind whose every match is over keeps its smallest."""
APPLIANCE_TRIANGLES = 2500
"""Triangles of an appliance, sink or washbasin whatever its size (see :data:`APPLIANCES`): a house has a
handful, in one kitchen and its bathrooms, and what names them is small detail (handles, a display, an
oven window, knobs, taps) that 1,000 triangles decimate away; the catalogues' best ones keep 2,500-3,600."""
OVEN_TRIANGLES = 3500
OVEN_ALLOWED = 6000
"""An oven's budget and the most triangles it may keep (``Rule.allowed``): the built-in oven keeps its
window and racks at 5,600 (simplified towards 3,500, then AREA_KEPT); at APPLIANCE_TRIANGLES its window
went, or it was passed over, leaving a small oven that reads as a space heater. A kitchen has one."""
TABLEWARE_TRIANGLES = 400
"""Least triangles of a small dressing object (tableware, kettles, pans, bottles, plants): at
MIN_TRIANGLES a pan became a cone and a teapot a box; they are seen close up on tables and worktops."""
TEXTURE_TEXELS = 256
"""Longest texture side: fabric, wood and labels tile or cover a few hundred pixels in a frame."""
DATASET_FACTOR = 3
"""The dataset level of detail (``models/<id>.full.npz``, drawn by the ``dataset`` camera quality only),
chosen by purpose: the kinds whose rule asks for it (``Rule.dataset``: appliances, sinks and
washbasins, where what names them is small curved detail that the live budget facets: bowls, taps,
handles, knobs) are simplified to DATASET_FACTOR times their live budget, never beyond the catalogue's
own triangles nor DATASET_MAX_TRIANGLES. Not every model: a process drawing house 23 peaks at 567 MB
at the live level; 3x for every model (268k triangles instead of 132k) took it to 681 MB, over the
600 MB a node may use, for furniture whose live silhouette already holds at 640x480."""
DATASET_MAX_TRIANGLES = 7500
DATASET_MIN_GAIN = 1.5
"""A model gets a dataset level only where it is materially finer: at least this many times the
live model's triangles (otherwise the live model is the dataset level too)."""
DATASET_TEXELS = 1024
"""Longest side of a dataset-level texture (``textures/full/<live name>.jpg``, written only where the
catalogue's texture is larger than TEXTURE_TEXELS)."""
AREA_KEPT = 0.7
"""Share of a material's surface its simplified mesh keeps (:func:`_decimate`): below it decimation
has eaten whole panels (a vase's body, a table's top), not detail."""
FOLIAGE_AREA_KEPT = 0.5
"""AREA_KEPT of a plant's leaves (``Rule.foliage``): decimation thins leaves rather than breaking
panels, and a plant keeping 70 % of its thousands of leaves would be past any budget."""
WHOLE_PIECE = 48
"""Triangles of a piece simplification keeps whole (:func:`_whole_pieces`): boxes, panels, a bevelled slab."""
AREA_ATTEMPTS = 3
"""Tries at AREA_KEPT, the share doubling after each (at most 4x the material's share)."""
WHOLE_MATERIAL = 600
"""Triangles of a material left whole where AREA_ATTEMPTS tries still lose its surface (a bed's drawer
panel, a small share of a large model's budget); a larger one keeps its last try."""
MAX_PER_TYPE = 4
DROPPED_OPACITY = CLEAR_GLASS_OPACITY
"""Materials at most this opaque (clear glass panes) are left out: no sensor of ours sees them (the
library's one decision about glass, :mod:`ravh_sim.world.library`)."""

INDOOR = ("Bathroom", "Bedroom", "Kitchen", "Living room", "Office", "Lights", "Miscellaneous")


@dataclass(frozen=True)
class Rule:
    """Which catalogue entries model one of our object kinds: a name pattern, categories, exclusions;
    ``ids`` takes entries by catalogue id whatever their name (a pot the catalogue calls a bowl),
    ``skip_ids`` passes over entries whose name matches but whose model does not look the part (an oven
    that reads as a microwave); ``least``/``most`` bound the kind's triangle budget (default
    MIN_TRIANGLES / TRIANGLE_BUDGET, read when used); ``dataset``: its models get a finer dataset level
    (DATASET_FACTOR); ``foliage``: its models are mostly leaves, which decimation thins rather than
    breaks, so their simplification keeps FOLIAGE_AREA_KEPT of the surface, not AREA_KEPT: a plant
    keeping 70 % of its thousands of leaves would be past any budget."""
    name: str
    categories: tuple[str, ...] = INDOOR
    exclude: str = r"$^"
    ids: str = r"$^"
    skip_ids: str = r"$^"
    least: int | None = None
    most: int | None = None
    dataset: bool = False               # a finer dataset level (DATASET_FACTOR) is written for its models
    foliage: bool = False
    allowed: int | None = None          # most triangles a model may keep (default: see ABSOLUTE_BUDGET)


def triangle_budget(rule: Rule, longest_m: float) -> int:
    """The triangles a model of ``rule``'s kind is simplified towards: TRIANGLE_BUDGET for 1.5 m or
    more, a share in proportion below, within the rule's bounds."""
    least = MIN_TRIANGLES if rule.least is None else rule.least
    most = TRIANGLE_BUDGET if rule.most is None else rule.most
    return int(np.clip(TRIANGLE_BUDGET * longest_m / 1.5, least, max(least, most)))


def allowed_triangles(rule: Rule, budget: int) -> float:
    """Most triangles a model of ``rule``'s kind may keep, simplified towards ``budget``."""
    return rule.allowed if rule.allowed is not None else max(OVER_BUDGET * budget, ABSOLUTE_BUDGET)


def _appliance(name: str, categories: tuple[str, ...] = INDOOR, ids: str = r"$^", skip_ids: str = r"$^",
               triangles: int = APPLIANCE_TRIANGLES, allowed: int | None = None) -> Rule:
    return Rule(name, categories, ids=ids, skip_ids=skip_ids, least=triangles, most=triangles, dataset=True,
                allowed=allowed)


def _tableware(name: str, ids: str = r"$^", skip_ids: str = r"$^") -> Rule:
    return Rule(name, ids=ids, skip_ids=skip_ids, least=TABLEWARE_TRIANGLES)


HOLLOW = r"#kitchenDrawersCabinet$"
"""Drawer fronts with nothing behind them: the laser passes the 1 cm gaps between the drawers, which
no camera pixel resolves, and reads the cabinet as not there."""

RULES: dict[str, Rule] = {
    "Armchair": Rule(r"armchair$|^armchair", exclude=r"ottoman|rattan|office"),
    "Bathtub": Rule(r"^bath$|bathtub|^fitted bath|^island bath"),
    "Bed": Rule(r"^bed\b|^double bed|^iron bed|^captain's bed", ("Bedroom",),
                exclude=r"side|bunk|loft|child|baby|sofa"),
    "Burner": _appliance(r"cooktop|induction cooker|^hob|^stove$"),
    "Cabinet": Rule(r"^cupboard$|glass door cabinet|^chest$|filing cabinet", exclude=r"kitchen"),
    "Chair": Rule(r"^chair$|^oak chair$|chair with cushion|^osaka chair", ("Living room", "Kitchen"),
                  skip_ids=r"#antiqueChair$|^Blend Swap CC-0#chair2$"),  # baroque and banquet chairs: no home's
    "Chair/office": Rule(r"chair|armchair", ("Office",), exclude=r"class|child"),
    "Closet": Rule(r"^wardrobe$"),
    "Cup": Rule(r"^coffee cup$|^coffee mug$|^cup$"),
    "Decoration": Rule(r"^plant$|little plant|indoor plant|yucca|succulent|spider plant|cactus", foliage=True),
    "Decoration/vase": Rule(r"^vase$"),
    "Desk": Rule(r"^desk$|wooden desk|^desk table"),
    "Dishwasher": _appliance(r"dishwasher"),
    "Dresser": Rule(r"^dresser|chest of drawers|drawers cabinet|^chest$", exclude=r"kitchen", skip_ids=HOLLOW),
    "Drying": Rule(r"towel rack|radiator"),
    "KitchenFurniture": Rule(r"^lower cabinet$|^kitchen cabinet$|^drawers cabinet$", ("Kitchen",), skip_ids=HOLLOW),
    "KitchenFurniture/upper": Rule(r"upper cabinet", ("Kitchen",), exclude=r"corner|shelves"),
    "KitchenFurniture/corner": Rule(r"lower corner cabinet|^lower cabinet$|^kitchen cabinet$", ("Kitchen",)),
    "KitchenFurniture/corner_upper": Rule(r"upper corner cabinet|upper cabinet", ("Kitchen",)),
    "KitchenFurniture/sink": Rule(r"^sink cabinet$|^lower cabinet$|^kitchen cabinet$", ("Kitchen",)),
    "KitchenFurniture/stove": _appliance(r"^cooker$|^large stove$", ("Kitchen",),
                                         skip_ids=r"^Scopia#cooker$"),         # a rice cooker
    "Lamp": Rule(r"^lamp$|little lamp|desk lamp|floor uplight|pedestal vase lamp", ("Lights",)),
    "Laptop": Rule(r"^laptop$|ibook"),
    "Light": Rule(r"ceiling lamp|pendant lamp|hanging light", ("Lights",)),
    "Microwave": Rule(r"microwave"),     # the catalogues' one, over any budget: kept as it was
    "Nightstand": Rule(r"bedside table|night ?stand|night table"),
    "Oven": _appliance(r"^oven$|^small oven$", skip_ids=r"^eTeks#oven$",  # a bare box: read as a microwave
                       triangles=OVEN_TRIANGLES, allowed=OVEN_ALLOWED),
    "Refrigerator": _appliance(r"fridge|refrigerator", skip_ids=r"^eTeks#fridge"),  # plain boxes: "wardrobe"
    "ShowerCabin": Rule(r"^shower$|shower stall|shower cabin"),
    "Sink": _appliance(r"^small lavatory$", ids=r"^Scopia#bathroom4$"),   # a bowl with taps, not a cabinet
    "Sofa": Rule(r"^sofa|^couch$|winchester sofa|burlap sofa|clear sofa|^futon couch",
                 exclude=r"convertible|rattan|corner"),
    "Standard": Rule(r"bookcase|^shelves$"),
    "Standard/tv": Rule(r"tv unit|tv stand|television cabinet"),
    "Stool": Rule(r"stool", exclude=r"piano|foot"),
    "Table": Rule(r"^table$|^oak table$|^square table$|^round table$|wooden (alder |teak )?table", exclude=r"children"),
    "Table/small": Rule(r"coffee table|^glass table$"),
    "Toilet": Rule(r"toilets? unit|^toilet$"),
    "Towel": Rule(r"^towel$"),
    "Tv": Rule(r"^tv|flat tv|wall flat tv", exclude=r"unit|stand|remote|cabinet"),
    "Washbasin": _appliance(r"^washbasin$", ("Bathroom",),
                            skip_ids=r"^Scopia#bathroom[13]$"),  # a bare worktop; a unit with its own mirror
    "WashingMachine": _appliance(r"washing machine|^clothes washer$",
                                 skip_ids=r"^Blend Swap CC-BY#washing_machine$"),  # decimated to a crumpled box
    "Dressing/plate": _tableware(r"^plate$|^oval plate$|^plate, glass(es)? and cutlery$"),
    "Dressing/bowl": _tableware(r"^bowl$|^bowl with salad$", skip_ids=r"^Kator Legaz#bowl$"),  # a pot
    "Dressing/cup": _tableware(r"^coffee cup$|^coffee mug$|^cup$"),       # glasses: clear, unseen
    "Dressing/fruit_bowl": _tableware(r"^bowl with fruits$|^apples$"),
    "Dressing/vase": _tableware(r"^flowers$|^tulips$|^orchids$|^white lily$|^vase$"),
    "Dressing/pan": _tableware(r"$^", ids=r"^Kator Legaz#bowl$"),        # the large pan simplifies to a cone
    "Dressing/kettle": _tableware(r"espresso kettle|^teapot$"),            # the kettle ("boiler") to a diamond
    "Dressing/bottle": _tableware(r"wine bottle|beer bottle|oil servers"),
    "Dressing/box": _tableware(r"cardboard box$|^gift$"),
    "Dressing/plant": Rule(r"^little plant$|^succulent plant$|^bamboo$|^cactus$", least=TABLEWARE_TRIANGLES,
                           foliage=True),
    "Dressing/floor_plant": Rule(r"^yucca$|^ficus$|^decorative plant$|^spathiphyllum$",
                                 ids=r"^Scopia#maceta$|^Blend Swap CC-0#plant$", foliage=True),
    "Dressing/towel": Rule(r"^towel$"),
    "Dressing/rug": Rule(r"oriental rug|round carpet|^bathmat$|^doormat$"),
    "Dressing/curtain": Rule(r"^curtains?$"),
    "Dressing/blind": Rule(r"venetian blind|window blind"),
}
"""Our object kinds (``Type`` or ``Type/prefab-class``, see :func:`ravh_sim.world.library.kind_of`), and
``Dressing/*``: the small things people leave about (:mod:`ravh_sim.world.dressing`). The catalogues have
no pillow, duvet, cushion, throw or dish rack, their one book simplifies to 6,000 triangles, and their
one picture frame is a blank canvas: those dressing kinds have no model."""


# --- reading the catalogues --------------------------------------------------------------------

@dataclass(frozen=True)
class Entry:
    """One catalogue model: where it is and what the catalogue says of it."""
    archive: Path
    catalogue: str
    id: str
    name: str
    category: str
    creator: str
    licence: str
    model: str                          # path of the OBJ inside the archive
    size_cm: tuple[float, float, float]  # width (x), depth (z), height (y)
    rotation: tuple[float, ...] | None   # modelRotation: a row-major 3x3 matrix
    door_or_window: bool


def read_properties(text: str) -> dict[str, str]:
    """A Java ``.properties`` file as a dict (``key=value`` lines, ``\\uXXXX`` escapes, comments)."""
    out = {}
    for line in text.splitlines():
        line = line.strip()
        if not line or line[0] in "#!" or "=" not in line:
            continue
        key, value = line.split("=", 1)
        out[key.strip()] = re.sub(r"\\u([0-9a-fA-F]{4})", lambda m: chr(int(m.group(1), 16)), value.strip())
    return out


def catalogue_entries(archive: Path) -> list[Entry]:
    """The models of one ``.sh3f`` or ``.jar`` archive."""
    with zipfile.ZipFile(archive) as zf:
        names = [n for n in zf.namelist() if re.search(r"(^|/)\w*FurnitureCatalog\.properties$", n)]
        if not names:
            raise UserError(f"{archive}: no *FurnitureCatalog.properties: not a furniture catalogue")
        props = read_properties(zf.read(names[0]).decode("latin-1"))
    numbers = sorted({int(k.split("#")[1]) for k in props if k.startswith("id#")})
    entries = []
    for i in numbers:
        def get(key: str, default: str = "", i: int = i) -> str:
            return props.get(f"{key}#{i}", default)
        try:
            size = (float(get("width")), float(get("depth")), float(get("height")))
        except ValueError:
            continue
        rotation = tuple(float(v) for v in get("modelRotation").split()) or None
        entries.append(Entry(archive, archive.stem, get("id"), get("name"), get("category"),
                             get("creator", props.get("creator", "")),
                             get("license", props.get("license", "")).strip(), get("model").lstrip("/"),
                             size, rotation if rotation and len(rotation) == 9 else None,
                             get("doorOrWindow") == "true"))
    return entries


@dataclass
class ObjModel:
    """An OBJ's triangles grouped by material, with the MTL materials and their texture bytes."""
    vertices: np.ndarray                 # (N, 3)
    uvs: np.ndarray                      # (N, 2); zeros where the OBJ has none
    faces: np.ndarray                    # (M, 3) into vertices
    face_material: np.ndarray            # (M,) index into materials
    materials: list[dict] = field(default_factory=list)   # name, Kd, Ns, d, map_Kd (bytes or None)


def read_obj(zf: zipfile.ZipFile, path: str) -> ObjModel:
    """Parse an OBJ (v, vt, f with any polygon, usemtl, mtllib) and its MTL files from an archive.

    Corners are split per (v, vt) pair so each vertex has one texture coordinate; polygons become
    triangle fans, as Sweet Home 3D reads them.
    """
    base = PurePosixPath(path).parent
    positions: list[list[float]] = []
    texcoords: list[list[float]] = []
    corner_index: dict[tuple[int, int], int] = {}
    vertices: list[int] = []
    uvs: list[int] = []
    faces: list[list[int]] = []
    face_material: list[int] = []
    material_names: list[str] = []
    libraries: list[str] = []
    current = _material_slot(material_names, "default")
    for raw in zf.read(path).decode("latin-1").splitlines():
        parts = raw.split()
        if not parts:
            continue
        tag = parts[0]
        if tag == "v":
            positions.append([float(p) for p in parts[1:4]])
        elif tag == "vt":
            texcoords.append([float(p) for p in (parts[1:3] + ["0"])[:2]])
        elif tag == "f":
            corners = []
            for token in parts[1:]:
                fields = token.split("/")
                v = int(fields[0])
                v = v - 1 if v > 0 else len(positions) + v
                t = int(fields[1]) if len(fields) > 1 and fields[1] else 0
                t = t - 1 if t > 0 else (len(texcoords) + t if t < 0 else -1)
                key = (v, t)
                if key not in corner_index:
                    corner_index[key] = len(vertices)
                    vertices.append(v)
                    uvs.append(t)
                corners.append(corner_index[key])
            for k in range(1, len(corners) - 1):
                faces.append([corners[0], corners[k], corners[k + 1]])
                face_material.append(current)
        elif tag == "usemtl" and len(parts) > 1:
            current = _material_slot(material_names, " ".join(parts[1:]))
        elif tag == "mtllib":
            libraries += parts[1:]
    mtl = {}
    for library in libraries:
        name = str(base / library)
        if name in zf.namelist():
            mtl.update(_read_mtl(zf, name, base))
    xyz = np.asarray(positions, np.float64).reshape(-1, 3)
    st = np.asarray(texcoords, np.float64).reshape(-1, 2)
    uv_index = np.asarray(uvs, np.int64)
    corner_uv = np.zeros((len(uv_index), 2))
    if len(st):
        corner_uv = np.where((uv_index >= 0)[:, None], st[np.clip(uv_index, 0, len(st) - 1)], 0.0)
    materials = [mtl.get(name, {"name": name, "Kd": (0.7, 0.7, 0.7), "Ns": 10.0, "d": 1.0, "map_Kd": None})
                 for name in material_names]
    return ObjModel(xyz[np.asarray(vertices, np.int64)], corner_uv,
                    np.asarray(faces, np.int64).reshape(-1, 3), np.asarray(face_material, np.int64), materials)


def _material_slot(names: list[str], name: str) -> int:
    if name not in names:
        names.append(name)
    return names.index(name)


def _read_mtl(zf: zipfile.ZipFile, path: str, base: PurePosixPath) -> dict[str, dict]:
    out: dict[str, dict] = {}
    current: dict | None = None
    for raw in zf.read(path).decode("latin-1").splitlines():
        parts = raw.split()
        if not parts:
            continue
        tag = parts[0]
        if tag == "newmtl":
            name = " ".join(parts[1:])
            current = out[name] = {"name": name, "Kd": (0.7, 0.7, 0.7), "Ns": 10.0, "d": 1.0, "map_Kd": None}
        elif current is None:
            continue
        elif tag == "Kd" and len(parts) >= 4:
            current["Kd"] = tuple(float(p) for p in parts[1:4])
        elif tag == "Ns":
            current["Ns"] = float(parts[1])
        elif tag == "d":
            current["d"] = float(parts[1])
        elif tag == "Tr":
            current["d"] = 1.0 - float(parts[1])
        elif tag == "map_Kd":
            texture = str(base / parts[-1])
            current["map_Kd"] = zf.read(texture) if texture in zf.namelist() else None
    return out


# --- turning a catalogue model into a library model ---------------------------------------------

@dataclass
class Converted:
    """A model in our frame, ready to write."""
    mesh: trimesh.Trimesh
    uvs: np.ndarray
    face_material: np.ndarray
    materials: list[LibraryMaterial]
    textures: dict[str, bytes]           # file name -> JPEG bytes
    budget: int                          # the triangles it was simplified towards
    full: tuple[trimesh.Trimesh, np.ndarray, np.ndarray] | None = None
    """The dataset level (mesh, uvs, face material into ``materials``), where materially finer."""


def convert(entry: Entry, zf: zipfile.ZipFile, rule: Rule = Rule("")) -> Converted:
    """Read, orient, scale, simplify (to its kind's :func:`triangle_budget`) and texture one catalogue
    model."""
    obj = read_obj(zf, entry.model)
    keep_material = np.array([not is_clear_glass(m["d"]) for m in obj.materials], bool)
    keep = keep_material[obj.face_material]
    faces, face_material = obj.faces[keep], obj.face_material[keep]
    vertices = obj.vertices
    if entry.rotation is not None:
        vertices = vertices @ np.asarray(entry.rotation).reshape(3, 3).T
    # Sweet Home 3D: x = width, y = up, z = depth with the front towards +z.
    # Ours: x = front (their +z), y = their x, z = up (their y): a proper rotation (a cyclic swap).
    vertices = vertices[:, [2, 0, 1]]
    lo, hi = vertices[faces].reshape(-1, 3).min(axis=0), vertices[faces].reshape(-1, 3).max(axis=0)
    width, depth, height = entry.size_cm
    target = np.array([depth, width, height]) / 100.0
    vertices = (vertices - (lo + hi) / 2) * (target / np.maximum(hi - lo, 1e-9))
    budget = triangle_budget(rule, float(target.max()))
    full_faces, full_material = faces, face_material
    area_kept = FOLIAGE_AREA_KEPT if rule.foliage else AREA_KEPT
    mesh, uvs, face_material = _simplify(vertices, obj.uvs, faces, face_material, budget, area_kept)
    materials, textures = _materials(obj.materials, np.unique(face_material))
    remap = {old: new for new, old in enumerate(np.unique(face_material))}
    full = None
    if rule.dataset and len(full_faces) >= DATASET_MIN_GAIN * len(mesh.faces):
        known = np.isin(full_material, list(remap))      # a material the live level lost is left out of both
        full_mesh, full_uvs, full_used = _simplify(vertices, obj.uvs, full_faces[known], full_material[known],
                                                   min(DATASET_FACTOR * budget, DATASET_MAX_TRIANGLES), area_kept)
        if len(full_mesh.faces) >= DATASET_MIN_GAIN * len(mesh.faces):
            full = (full_mesh, full_uvs, np.array([remap[m] for m in full_used], np.uint8))
    return Converted(mesh, uvs, np.array([remap[m] for m in face_material], np.uint8), materials, textures,
                     budget, full)


def _simplify(vertices: np.ndarray, uvs: np.ndarray, faces: np.ndarray, face_material: np.ndarray,
              budget: int, area_kept: float = AREA_KEPT) -> tuple[trimesh.Trimesh, np.ndarray, np.ndarray]:
    """Each material's triangles simplified to its share of the budget: its small pieces whole
    (:func:`_whole_pieces`), the rest keeping ``area_kept`` of its surface (:func:`_decimate`)."""
    total = len(faces)
    chunks = []
    for material in np.unique(face_material):
        sub = faces[face_material == material]
        used, local = np.unique(sub, return_inverse=True)
        points, tris, uv = vertices[used], local.reshape(-1, 3), uvs[used]
        share = max(12, int(budget * len(sub) / max(total, 1)))
        if len(tris) > share and len(tris) > 24:
            whole = _whole_pieces(points, tris, share)
            kept_points, kept_uv, kept_tris = _decimate(points, uv, tris[~whole], share - int(whole.sum()), area_kept)
            joined = np.concatenate([tris[whole], kept_tris + len(points)])
            used, corner = np.unique(joined, return_inverse=True)
            points, uv = np.concatenate([points, kept_points])[used], np.concatenate([uv, kept_uv])[used]
            tris = corner.reshape(-1, 3)
        chunks.append((np.asarray(points, np.float64), np.asarray(tris, np.int64), uv, material))
    offsets = np.cumsum([0] + [len(c[0]) for c in chunks[:-1]])
    mesh = trimesh.Trimesh(np.concatenate([c[0] for c in chunks]),
                           np.concatenate([c[1] + o for c, o in zip(chunks, offsets)]), process=False)
    uv_all = np.concatenate([c[2] for c in chunks])
    material_all = np.concatenate([np.full(len(c[1]), c[3]) for c in chunks])
    valid = mesh.nondegenerate_faces()
    mesh.update_faces(valid)
    return mesh, uv_all, material_all[valid]


def _whole_pieces(points: np.ndarray, tris: np.ndarray, share: int) -> np.ndarray:
    """Per triangle, whether it belongs to a small piece kept whole: pieces of at most WHOLE_PIECE
    triangles, the largest in area first, up to half the material's ``share``. Quadric decimation
    collapses such a piece (a table's top is a box of 12 triangles) for less than the cost of thinning
    a curved part, and then the piece is gone, not coarser."""
    pieces = piece_labels(points, tris)
    counts = np.bincount(pieces)
    small = np.flatnonzero(counts <= WHOLE_PIECE)
    small = small[np.argsort(-np.bincount(pieces, weights=_triangle_areas(points, tris))[small], kind="stable")]
    chosen = small[np.cumsum(counts[small]) <= share // 2]
    return np.isin(pieces, chosen)


def _decimate(points: np.ndarray, uv: np.ndarray, tris: np.ndarray, share: int, area_kept: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One material's mesh simplified towards ``share`` triangles by quadric decimation, keeping
    ``area_kept`` of its surface where AREA_ATTEMPTS doublings of the share can (else whole, up to
    WHOLE_MATERIAL triangles).

    The decimation sees the mesh welded by position: an OBJ splits its vertices at every hard edge,
    so a box's faces are loose quads, and a loose flat quad collapses at no cost; unwelded, a
    table lost its top and a cabinet its sides. Each kept vertex is then put back on an original
    vertex it absorbed (the nearest), so a flat top stays flat, and each kept corner takes the
    texture coordinate of the absorbed vertex on its own side of a hard edge
    (:func:`_corner_sources`), so texture seams stay seams."""
    import fast_simplification  # the maintainer's tool's own dependency
    _, weld = np.unique(np.round(points, 5), axis=0, return_inverse=True)
    weld = weld.reshape(-1)
    welded = np.zeros((int(weld.max()) + 1, 3))
    welded[weld] = points
    joined = weld[tris]
    joined = joined[(joined[:, 0] != joined[:, 1]) & (joined[:, 1] != joined[:, 2]) & (joined[:, 0] != joined[:, 2])]
    source_area = _surface(welded, joined)
    for _ in range(AREA_ATTEMPTS):
        if share >= len(joined):
            return points, uv, tris
        kept, kept_tris, collapses = fast_simplification.simplify(
            welded.astype(np.float32), joined.astype(np.int32), 1.0 - share / len(joined), return_collapses=True)
        kept = np.asarray(kept, np.float64)
        if len(kept_tris) and _surface(kept, kept_tris) >= area_kept * source_area:
            break
        share *= 2
    else:
        if len(tris) <= WHOLE_MATERIAL:
            return points, uv, tris
    _, _, mapping = fast_simplification.replay_simplification(
        welded.astype(np.float32), joined.astype(np.int32), collapses)
    mapping = np.asarray(mapping)                                # welded vertex -> kept vertex
    nearest = np.lexsort((np.linalg.norm(welded - kept[mapping], axis=1), mapping))
    first = nearest[np.r_[True, mapping[nearest][1:] != mapping[nearest][:-1]]]
    kept[mapping[first]] = welded[first]
    source = _corner_sources(points, tris, mapping[weld], kept, kept_tris)
    pairs, corner_vertex = np.unique(np.stack([kept_tris.reshape(-1), source.reshape(-1)], axis=1), axis=0,
                                     return_inverse=True)
    return kept[pairs[:, 0]], uv[pairs[:, 1]], corner_vertex.reshape(-1, 3)


def _corner_sources(points: np.ndarray, tris: np.ndarray, kept_of: np.ndarray, kept: np.ndarray,
                    kept_tris: np.ndarray) -> np.ndarray:
    """Per corner of the kept triangles, the original vertex whose texture coordinate it takes: of
    the vertices its kept vertex absorbed (``kept_of``: original vertex -> kept vertex), the one
    whose normal is closest to the kept triangle's (an OBJ vertex at a hard edge belongs to one side)."""
    corners = points[tris]
    vertex_normals = np.zeros_like(points)
    np.add.at(vertex_normals, tris.reshape(-1),
              np.repeat(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), 3, axis=0))
    vertex_normals /= np.maximum(np.linalg.norm(vertex_normals, axis=1, keepdims=True), 1e-12)
    kept_corners = kept[kept_tris]
    normals = np.cross(kept_corners[:, 1] - kept_corners[:, 0], kept_corners[:, 2] - kept_corners[:, 0])
    order = np.argsort(kept_of, kind="stable")
    starts = np.searchsorted(kept_of[order], np.arange(len(kept) + 1))
    source = np.empty(kept_tris.shape, np.int64)
    for f, triangle in enumerate(kept_tris):
        for c, vertex in enumerate(triangle):
            absorbed = order[starts[vertex]:starts[vertex + 1]]
            source[f, c] = absorbed[np.argmax(vertex_normals[absorbed] @ normals[f])]
    return source


def _surface(points: np.ndarray, tris: np.ndarray) -> float:
    """Area of a mesh's triangles, a triangle given twice (both sides of a sheet) counted once."""
    _, first = np.unique(np.sort(tris, axis=1), axis=0, return_index=True)
    return float(_triangle_areas(points, tris[first]).sum())


def _triangle_areas(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    corners = points[tris]
    return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)


def _materials(mtl: Sequence[dict], used: np.ndarray) -> tuple[list[LibraryMaterial], dict[str, bytes]]:
    """The library materials of the used MTL materials and their textures: the live one
    (``textures/<hash>.jpg``) and, where the catalogue's is larger, the dataset level's
    (``textures/full/<hash>.jpg``, same hash)."""
    materials, textures = [], {}
    for index in used:
        m = mtl[int(index)]
        texture = None
        if m["map_Kd"] is not None:
            jpeg = _small_jpeg(m["map_Kd"])
            if jpeg is not None:
                texture = f"textures/{hashlib.sha1(jpeg).hexdigest()[:16]}.jpg"
                textures[texture] = jpeg
                full = _small_jpeg(m["map_Kd"], DATASET_TEXELS, larger_than=TEXTURE_TEXELS)
                if full is not None:
                    textures[full_texture(texture)] = full
        r, g, b = (float(np.clip(c, 0.0, 1.0)) for c in m["Kd"])
        roughness = float(np.clip(np.sqrt(2.0 / (max(m["Ns"], 0.0) + 2.0)), 0.05, 1.0))
        kind = material_kind(m["name"], texture is not None, float(m["d"]))
        materials.append(LibraryMaterial(name=m["name"], colour=(r, g, b), texture=texture, roughness=roughness,
                                         kind=kind))
    return materials, textures


def _small_jpeg(data: bytes, texels: int = TEXTURE_TEXELS, larger_than: int = 0) -> bytes | None:
    """The image as a JPEG at most ``texels`` a side; None if it is not an image or not larger than
    ``larger_than`` texels a side."""
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    if image is None or max(image.shape[:2]) <= larger_than:
        return None
    scale = texels / max(image.shape[:2])
    if scale < 1:
        image = cv2.resize(image, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    ok, jpeg = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 85])
    return jpeg.tobytes() if ok else None


# --- choosing and writing ----------------------------------------------------------------------

def matches(entries: Sequence[Entry], rules: dict[str, Rule] = RULES) -> dict[str, list[Entry]]:
    """Per object kind, the catalogue entries whose name (or id) and category match its rule, in
    catalogue order."""
    def chosen(e: Entry, rule: Rule) -> bool:
        named = re.search(rule.name, e.name.lower()) and not re.search(rule.exclude, e.name.lower())
        return (not e.door_or_window and e.category in rule.categories and not re.search(rule.skip_ids, e.id)
                and bool(named or re.search(rule.ids, e.id)))
    return {kind: [e for e in entries if chosen(e, rule)] for kind, rule in rules.items()}


def import_furniture(archives: Sequence[Path], out: Path, rules: dict[str, Rule] = RULES,
                     per_kind: int = MAX_PER_TYPE, progress: bool = True) -> dict[str, list[str]]:
    """Import the chosen models of ``archives`` into ``out`` (replacing it); returns kind -> model ids."""
    entries = [e for archive in archives for e in catalogue_entries(Path(archive))]
    chosen = matches(entries, rules)
    if out.exists():
        shutil.rmtree(out)
    (out / "models").mkdir(parents=True)
    (out / "textures" / "full").mkdir(parents=True)
    records: list[dict] = []
    written: dict[str, list[str]] = {}
    archives_open = {a: zipfile.ZipFile(a) for a in {e.archive for es in chosen.values() for e in es}}
    try:
        for kind, picked in chosen.items():
            written[kind] = []
            kept: list[tuple[Entry, Converted]] = []
            smallest: tuple[Entry, Converted] | None = None
            for entry in picked:
                if len(kept) == per_kind:
                    break
                converted = convert(entry, archives_open[entry.archive], rules[kind])
                if len(converted.mesh.faces) <= allowed_triangles(rules[kind], converted.budget):
                    kept.append((entry, converted))
                elif smallest is None or len(converted.mesh.faces) < len(smallest[1].mesh.faces):
                    smallest = (entry, converted)
            for entry, converted in kept or ([smallest] if smallest else []):
                model_id = _model_id(kind, entry)
                _write_model(out / "models" / f"{model_id}.npz", converted.mesh, converted.uvs,
                             converted.face_material)
                if converted.full is not None:
                    _write_model(out / "models" / f"{model_id}{FULL_SUFFIX}", *converted.full)
                for name, data in converted.textures.items():
                    (out / name).write_bytes(data)
                records.append(_record(model_id, kind, entry, converted))
                written[kind].append(model_id)
                if progress:
                    print(f"{kind:28s} {model_id:40s} {len(converted.mesh.faces):5d} triangles  {entry.name}")
    finally:
        for zf in archives_open.values():
            zf.close()
    (out / "catalog.json").write_text(json.dumps({"format": CATALOG_FORMAT, "models": records}, indent=1) + "\n")
    (out / "ATTRIBUTION.md").write_text(attribution(records))
    return written


def _model_id(kind: str, entry: Entry) -> str:
    slug = re.sub(r"[^a-z0-9]+", "_", f"{entry.catalogue}_{entry.id.split('#')[-1]}".lower()).strip("_")
    return f"{kind.replace('/', '_').lower()}__{slug}"


def _write_model(path: Path, mesh: trimesh.Trimesh, uvs: np.ndarray, face_material: np.ndarray) -> None:
    buffer = io.BytesIO()
    np.savez_compressed(buffer, vertices=mesh.vertices.astype(np.float32),
                        faces=mesh.faces.astype(np.uint32), uvs=uvs.astype(np.float32),
                        face_material=face_material.astype(np.uint8),
                        face_piece=piece_labels(mesh.vertices, mesh.faces).astype(np.uint16))
    path.write_bytes(buffer.getvalue())


def _record(model_id: str, kind: str, entry: Entry, converted: Converted) -> dict:
    return {"id": model_id, "kind": kind, "name": entry.name, "catalogue": entry.catalogue,
            "catalogue_id": entry.id, "creator": entry.creator, "licence": entry.licence,
            "size": [round(float(v), 4) for v in converted.mesh.extents],
            "triangles": int(len(converted.mesh.faces)),
            "materials": [m.model_dump() for m in converted.materials]}


def attribution(records: Sequence[dict]) -> str:
    """ATTRIBUTION.md: every shipped model with its creator, licence and source catalogue."""
    lines = ["# Furniture models: attribution", "",
             "Every model here comes from Sweet Home 3D's furniture catalogues (Debian packages",
             "`sweethome3d-furniture` and `sweethome3d`), converted by `ravh import-furniture`",
             "(simplified meshes, downsized textures). Each is shipped under the licence named below;",
             "CC-BY models require this attribution to be kept.", "",
             "| model file | name | creator | licence | catalogue (id) |", "| --- | --- | --- | --- | --- |"]
    for r in records:
        lines.append(f"| `models/{r['id']}.npz` | {r['name']} | {r['creator']} | {r['licence']} | "
                     f"{r['catalogue']} ({r['catalogue_id']}) |")
    return "\n".join(lines) + "\n"


def iter_archives(paths: Sequence[Path]) -> Iterator[Path]:
    """The catalogue archives among ``paths`` (files, or folders searched for .sh3f and .jar)."""
    for path in paths:
        if path.is_dir():
            yield from sorted(p for p in path.rglob("*") if p.suffix in (".sh3f", ".jar"))
        elif path.is_file():
            yield path
        else:
            raise UserError(f"{path}: no such file or folder")
