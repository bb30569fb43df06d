"""The furniture library: modelled furniture from open catalogues, fitted into the houses' boxes.

Format (``furniture/``, written by ``ravh import-furniture``, :mod:`ravh_sim.importers.furniture`):

- ``catalog.json``: ``{"format": CATALOG_FORMAT, "models": [...]}``; each model names its ``kind``
  (our object type, or ``Type/class`` where a prefab class looks different: office chairs, coffee
  tables, upper kitchen units), its source, creator and licence, its natural ``size`` (m, along
  front, across, up) and its materials (:class:`LibraryMaterial`).
- ``models/<id>.npz``: ``vertices`` (N, 3) float32 in metres, centred on the model's box, z up,
  front along +x; ``faces`` (M, 3); ``uvs`` (N, 2); ``face_material`` (M,) into the materials;
  ``face_piece`` (M,): the connected piece (leg, seat, back...) each face belongs to.
- ``textures/*.jpg``: base-colour textures, at most 256 texels a side.
- The dataset level of detail (:data:`DETAILS`), drawn by the ``dataset`` camera quality only:
  ``models/<id>.full.npz`` (same arrays and materials, up to 8x the triangles: the importer's
  ``DATASET_FACTOR``) where it is materially finer than the live model, and ``textures/full/<name>``
  (up to 1024 texels a side) where the catalogue's texture is larger than the live one. Where a
  model or texture has none, the live one is the dataset level too. The dataset level is visual
  only: colliders, footprints and fitting read the live model (:func:`dataset_model`).
- ``ATTRIBUTION.md``: every model's creator and licence.

A model is fitted into an object's box by :func:`fit`: scaled to the box's height where its
proportions allow, its width and depth within :data:`MAX_STRETCH` of that scale, set on the box's
floor and against its back; so it always lies inside the box the footprint records. An object's
model variants are its kind's models in order of how well they fit its box (:func:`misfit`), so
the default variant is the best-proportioned one.

Glass, decided here once for every sensor:

- Clear glass (an MTL material at most :data:`CLEAR_GLASS_OPACITY` opaque: shower screens, clear
  cabinet panes) is transparent to every sensor: the importer leaves its triangles out of the
  library, so neither the laser's collider, nor the depth, instance or colour image has it. The
  camera and the laser both see what stands behind it (as real lidars and depth cameras mostly do).
- Every other glass (:func:`is_glass`: tinted, smoked or frosted glass up to :data:`GLASS_OPACITY`,
  and materials named glass: table tops, oven, microwave and cabinet doors, lamp shades) is opaque
  to every sensor, like any other surface: the laser collides with it (every triangle of a model is
  in its collider, ``World._model_collision``), the renderer draws it into the depth and instance
  images (dark, glossy, with nothing seen through it: :func:`ravh_sim.look.materials.library_material`).

So the laser and the depth image never disagree about glass: both read a model's ``faces``,
glass faces included, and nothing else.
"""
from __future__ import annotations

import functools
import re
from pathlib import Path
from typing import Literal

import numpy as np
import trimesh
from pydantic import Field

from ravh_sim.errors import UserError
from ravh_sim.paths import FURNITURE_DIR
from ravh_sim.schema import Strict
from ravh_sim.world.mesh import coloured, uv_visual
from ravh_sim.world.palette import PALETTE

CATALOG_FORMAT = "ravh_sim/furniture@1"
DETAILS = ("live", "dataset")
"""Levels of detail: ``live`` (the simulator's, what every sensor and collider reads) and ``dataset``
(finer models and textures that dataset captures draw where the library has them)."""
Detail = Literal["live", "dataset"]
FULL_SUFFIX = ".full.npz"
FIT_TOLERANCE = 1e-6                # m: a fitted model is an affine map of its library model within this
MAX_STRETCH = 1.3
"""Largest per-axis stretch beyond a uniform scale: a sofa may grow a little wider, not turn into
a bench."""

_TEXTURE_STAND_IN = (0.6, 0.5, 0.4)          # a textured material's colour where textures are not drawn
CLEAR_GLASS_OPACITY = 0.35
"""MTL opacity (``d``) at or below which a material is clear glass: transparent to every sensor,
left out of the library at import (:mod:`ravh_sim.importers.furniture`)."""
GLASS_OPACITY = 0.9
"""MTL opacity below which a kept material is glass (tinted, smoked, frosted): opaque to every sensor."""

Kind = Literal["textured", "wood", "fabric", "leather", "metal", "glass", "mirror", "screen", "ceramic",
               "marble", "plant", "emissive", "plain"]

_KIND_WORDS: tuple[tuple[Kind, str], ...] = (
    ("mirror", r"mirror|miroir"),
    ("screen", r"screen|display|lcd|monitor|ecran"),
    ("glass", r"glass|verre|crystal|transp"),
    ("ceramic", r"white[-_ ]?metal|paint"),      # painted steel (a washer's body, blind slats): enamel, not bare
    ("metal", r"chrom|metal|steel|inox|alumin|silver|iron|brass|gold|nickel|copper"),
    ("leather", r"leather|cuir"),
    ("fabric", r"fabric|cloth|cushion|textile|velvet|linen|cotton|tissu|sheet|pillow|mattress|blanket|curtain"),
    ("wood", r"wood|bois|oak|pine|walnut|teak|beech|cherry|maple|mahogany|birch|parquet"),
    ("marble", r"marble|granit|stone"),
    ("ceramic", r"ceramic|porcelain|enamel|faience|email"),
    ("plant", r"leaf|leaves|plant|foliage|grass|flower"),
    ("emissive", r"bulb|lamp_?light|emissi|neon"),
)


def is_clear_glass(opacity: float) -> bool:
    """Whether an MTL material of this opacity is clear glass, which no sensor sees (see Glass above)."""
    return opacity <= CLEAR_GLASS_OPACITY


def material_kind(name: str, textured: bool, opacity: float) -> Kind:
    """What an MTL material is made of, from its name (textured ones keep their texture)."""
    if textured:
        return "textured"
    lowered = name.lower()
    if opacity < GLASS_OPACITY:
        return "glass"
    for kind, pattern in _KIND_WORDS:
        if re.search(pattern, lowered):
            return kind
    return "plain"


class LibraryMaterial(Strict):
    """One material of a library model: MTL diffuse colour (sRGB), texture, roughness (from Ns)."""
    name: str
    colour: tuple[float, float, float]
    texture: str | None = None
    roughness: float = Field(ge=0.0, le=1.0)
    kind: Kind


def is_glass(material: LibraryMaterial) -> bool:
    """Whether a library material is glass: opaque to every sensor, drawn as glass (see Glass above)."""
    return material.kind == "glass"


class LibraryRecord(Strict):
    id: str
    kind: str
    name: str
    catalogue: str
    catalogue_id: str
    creator: str
    licence: str
    size: tuple[float, float, float]
    triangles: int
    materials: list[LibraryMaterial]


class LibraryCatalog(Strict):
    format: Literal["ravh_sim/furniture@1"]
    models: list[LibraryRecord]


def record(model: trimesh.Trimesh) -> LibraryRecord:
    """What the catalogue says of a library model (loaded or fitted)."""
    return model.metadata["record"]


def face_material(model: trimesh.Trimesh) -> np.ndarray:
    """(M,) each face's material, an index into ``record(model).materials``."""
    return model.face_attributes["material"]


def glass_faces(model: trimesh.Trimesh) -> np.ndarray:
    """(M,) bool: the faces of glass materials (:func:`is_glass`), which collide and are drawn
    like every other face."""
    glass = np.array([is_glass(m) for m in record(model).materials], bool)
    return glass[face_material(model)] if len(glass) else np.zeros(len(model.faces), bool)


def _model(entry: LibraryRecord, vertices: np.ndarray, faces: np.ndarray, uvs: np.ndarray,
           attributes: dict[str, np.ndarray]) -> trimesh.Trimesh:
    """A library model's triangles: its record in ``metadata``, its material and piece per face
    in ``face_attributes``, its texture coordinates in a ``TextureVisuals``."""
    return trimesh.Trimesh(vertices, faces, process=False, face_attributes=attributes, visual=uv_visual(uvs),
                           metadata={"record": entry})


def with_vertices(model: trimesh.Trimesh, vertices: np.ndarray) -> trimesh.Trimesh:
    """The model with its vertices moved (fitted into an object's box, in the body frame): every
    triangle, glass included, is what the laser collides with and what the camera draws."""
    return _model(record(model), vertices, model.faces, model.visual.uv, model.face_attributes)


_PREFAB_CLASSES: tuple[tuple[str, str, str], ...] = (
    ("Chair", r"office", "office"),
    ("Table", r"small", "small"),
    ("Standard", r"tv", "tv"),
    ("Decoration", r"vase", "vase"),
    ("KitchenFurniture", r"corner up", "corner_upper"),
    ("KitchenFurniture", r"corner", "corner"),
    ("KitchenFurniture", r"up$", "upper"),
    ("KitchenFurniture", r"sink", "sink"),
    ("KitchenFurniture", r"burner|oven", "stove"),
)


def kind_of(object_type: str, prefab: str) -> str:
    """The library kind of an object: its type, or ``Type/class`` for prefabs that look different."""
    lowered = prefab.lower().strip()
    for type_, pattern, cls in _PREFAB_CLASSES:
        if object_type == type_ and re.search(pattern, lowered):
            return f"{type_}/{cls}"
    return object_type


@functools.lru_cache(maxsize=1)
def catalog() -> LibraryCatalog:
    """The committed library (an installation without it is broken, not a house without furniture)."""
    path = FURNITURE_DIR / "catalog.json"
    if not path.exists():
        raise FileNotFoundError(f"the furniture library is missing: {path} (reinstall ravh_sim)")
    return LibraryCatalog.model_validate_json(path.read_text())


@functools.cache
def models_of(kind: str) -> tuple[LibraryRecord, ...]:
    """The library's models of a kind, in catalogue order (empty: the kind has none)."""
    return tuple(r for r in catalog().models if r.kind == kind)


def full_texture(texture: str) -> str:
    """Where the dataset level of a library texture (``textures/<name>``) is: ``textures/full/<name>``."""
    folder, _, name = texture.rpartition("/")
    return f"{folder}/full/{name}"


def texture_file(texture: str, detail: Detail = "live") -> Path:
    """The file of a library material's texture at a level of detail (the live one where the
    dataset level has none). House models' textures are absolute paths, which have one level."""
    if detail == "dataset" and not Path(texture).is_absolute():
        full = FURNITURE_DIR / full_texture(texture)
        if full.exists():
            return full
    return FURNITURE_DIR / texture


def has_dataset_level(model_id: str) -> bool:
    """Whether the library has a finer dataset level of a model (``models/<id>.full.npz``)."""
    return (FURNITURE_DIR / "models" / f"{model_id}{FULL_SUFFIX}").exists()


@functools.lru_cache(maxsize=256)
def load_model(model_id: str, detail: Detail = "live") -> trimesh.Trimesh:
    """A library model in its own frame (centred box, z up, front along +x), at a level of detail
    (:data:`DETAILS`; the live model where the library has no dataset level of it)."""
    found = next(r for r in catalog().models if r.id == model_id)
    name = f"{model_id}{FULL_SUFFIX}" if detail == "dataset" and has_dataset_level(model_id) else f"{model_id}.npz"
    with np.load(FURNITURE_DIR / "models" / name) as data:
        return _model(found, data["vertices"].astype(np.float64), data["faces"].astype(np.int64),
                      data["uvs"].astype(np.float32), {"material": data["face_material"].astype(np.int64),
                                                       "piece": data["face_piece"].astype(np.int64)})


@functools.lru_cache(maxsize=256)
def load_model_file(path: Path) -> trimesh.Trimesh:
    """A house's own model (``ravh import-home``): a library model's arrays and its ``record`` (JSON) in
    one npz, its textures in the npz's folder (their paths made absolute here, which the renderer reads
    as they are). Indices are checked: the file came from a user's folder."""
    try:
        with np.load(path) as data:
            found = LibraryRecord.model_validate_json(str(data["record"]))
            vertices, faces = data["vertices"].astype(np.float64), data["faces"].astype(np.int64)
            uvs, materials = data["uvs"].astype(np.float32), data["face_material"].astype(np.int64)
            pieces = data["face_piece"].astype(np.int64)
    except (OSError, KeyError, ValueError) as e:
        raise UserError(f"{path}: not a model file of ravh import-home: {str(e)[:200]}") from None
    if (faces.ndim != 2 or faces.shape[1] != 3 or not len(faces) or faces.min() < 0 or faces.max() >= len(vertices)
            or len(uvs) != len(vertices) or len(materials) != len(faces) or len(pieces) != len(faces)
            or materials.max() >= len(found.materials)):
        raise UserError(f"{path}: inconsistent model arrays")
    textured = [m if m.texture is None else m.model_copy(update={"texture": str(path.parent / m.texture)})
                for m in found.materials]
    return _model(found.model_copy(update={"materials": textured}), vertices, faces, uvs,
                  {"material": materials, "piece": pieces})


def dataset_model(fitted: trimesh.Trimesh) -> trimesh.Trimesh:
    """The dataset level of a fitted library model, placed as the fitted one is: the affine map from
    the live library model to ``fitted`` (however it was fitted: :func:`fit` and a turn, a dressing
    object's scale) applied to the dataset level's vertices. So both levels stand in the same box,
    and the live model stays what collides (the dataset level is drawn only; its surface lies within
    a few mm of the live one's). The fitted model itself where there is no finer level, where it is
    not a library model, or where it is not an affine map of it (a house's own model)."""
    model_id = record(fitted).id
    if not any(r.id == model_id for r in catalog().models) or not has_dataset_level(model_id):
        return fitted
    live = load_model(model_id)
    if len(live.vertices) != len(fitted.vertices):
        return fitted
    homogeneous = np.column_stack([live.vertices, np.ones(len(live.vertices))])
    affine, *_ = np.linalg.lstsq(homogeneous, fitted.vertices, rcond=None)
    if np.abs(homogeneous @ affine - fitted.vertices).max() > FIT_TOLERANCE:
        return fitted
    full = load_model(model_id, "dataset")
    vertices = np.column_stack([full.vertices, np.ones(len(full.vertices))]) @ affine
    return _model(record(fitted), vertices, full.faces, full.visual.uv, full.face_attributes)


def fit_scale(natural: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Per-axis scale of a model of ``natural`` extents into a box of ``size``: the box's height
    where the model's proportions allow it (the height says most about an object: a fridge, a
    wardrobe), each horizontal axis within MAX_STRETCH of the height's scale, never beyond the box."""
    natural = np.maximum(np.asarray(natural, np.float64), 1e-6)
    ratio = np.asarray(size, np.float64) / natural
    up = min(ratio[2], MAX_STRETCH * ratio[:2].min())
    return np.array([min(ratio[0], MAX_STRETCH * up), min(ratio[1], MAX_STRETCH * up), up])


def misfit(natural: np.ndarray, size: np.ndarray) -> float:
    """How far a box's proportions are from a model's: the largest log ratio between the scales its
    axes would need (0: the model fills the box unstretched)."""
    ratio = np.log(np.asarray(size, np.float64) / np.maximum(np.asarray(natural, np.float64), 1e-6))
    return float(ratio.max() - ratio.min())



def made_to_box(vertices: np.ndarray, size: tuple[float, float, float]) -> np.ndarray:
    """A shape made here, moved and scaled to fill a box of ``size`` centred on the origin exactly, as
    :func:`fit` sets a library model (soft furnishings, books, dish racks)."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    return (vertices - (lo + hi) / 2) / np.maximum(hi - lo, 1e-9) * np.asarray(size, np.float64)


def made_model(fitted: np.ndarray, faces: np.ndarray, uv: np.ndarray, record: LibraryRecord,
               material: np.ndarray, piece: np.ndarray) -> trimesh.Trimesh:
    """A model made here in a library model's form: its ``record`` (with its triangle count) in
    ``metadata``, a ``material`` and ``piece`` per face, texture coordinates."""
    return trimesh.Trimesh(fitted, faces, process=False, visual=uv_visual(uv.astype(np.float32)),
                           face_attributes={"material": material, "piece": piece},
                           metadata={"record": record.model_copy(update={"triangles": len(faces)})})


def fit(model: trimesh.Trimesh, size: np.ndarray) -> np.ndarray:
    """The model's vertices scaled into a box of ``size`` (front, across, up) centred at the origin
    (:func:`fit_scale`), standing on the box's floor with its back against the box's back
    (x = -size/2), centred across."""
    natural = np.ptp(model.vertices, axis=0)
    size = np.asarray(size, np.float64)
    scale = fit_scale(natural, size)
    vertices = (model.vertices - model.vertices.min(axis=0)) * scale
    extent = np.maximum(natural, 1e-6) * scale
    offset = np.array([-size[0] / 2, -extent[1] / 2, -size[2] / 2])
    return vertices + offset


def piece_labels(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Per face, the connected piece it belongs to (faces touching at a vertex position are one
    piece, across texture seams): union-find over the faces' corners."""
    _, corner = np.unique(np.round(vertices, 5), axis=0, return_inverse=True)
    corner = corner.reshape(-1)[faces]                           # (M, 3) position ids
    parent = np.arange(int(corner.max()) + 1 if len(corner) else 0)

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b, c in corner.tolist():
        ra = root(a)
        parent[root(b)] = ra
        parent[root(c)] = ra
    roots = np.array([root(i) for i in range(len(parent))], np.int64)
    return np.unique(roots[corner[:, 0]], return_inverse=True)[1].reshape(-1)


def palette_stand_in(fitted: trimesh.Trimesh) -> trimesh.Trimesh:
    """The fitted model coloured with the nearest palette colour of each material: what pybullet's
    TinyRenderer fallback draws (it knows one texture per body, not a model's textures)."""
    srgb = np.array([m.colour if m.texture is None else _TEXTURE_STAND_IN for m in record(fitted).materials])
    nearest = np.argmin(np.linalg.norm(PALETTE.rgb[None, :, :] - srgb[:, None, :], axis=2), axis=1)
    return coloured(fitted.vertices, fitted.faces, nearest[face_material(fitted)])
