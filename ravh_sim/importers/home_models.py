"""A home's own furniture models (the numbered OBJ entries of a ``.sh3d``) written in the library's format.

Why: the home's author chose each piece's model, colours and textures; the robot's camera should see
those, not the library's nearest match. Each distinct look (model entry, rotation, mirroring, colour and
material overrides) becomes one ``<id>.npz`` (the arrays of :mod:`ravh_sim.world.library` plus its
``record`` as JSON, textures under ``textures/``) in the home's models folder, read back by
:func:`ravh_sim.world.library.load_model_file`. The model is turned into our frame (front along +x, z up),
centred on its box and sized to the first piece that uses it; the world stretches it to each piece's box,
as Sweet Home 3D does. Reading, simplifying and texturing reuse the furniture importer's functions.
"""
from __future__ import annotations

import hashlib
import io
import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ravh_sim.importers.default_materials import DEFAULT_MATERIALS
from ravh_sim.importers.furniture import MIN_TRIANGLES, TRIANGLE_BUDGET, _materials, _simplify, read_obj
from ravh_sim.importers.sh3d_archive import Sh3dArchive
from ravh_sim.world.library import GLASS_OPACITY, LibraryRecord, is_clear_glass, piece_labels

_UNSET_KD = (0.7, 0.7, 0.7)               # what read_obj gives a material no MTL defines
Colour = tuple[float, float, float]


@dataclass(frozen=True)
class Look:
    """Everything that decides how one piece's model looks."""
    entry: str                              # zip entry of the OBJ
    rotation: tuple[float, ...] | None      # modelRotation, row-major 3x3
    mirrored: bool
    colour: Colour | None                   # the piece's colour: every material
    materials: tuple[tuple[str, Colour | None, str | None], ...]   # (name, colour, texture entry) overrides
    texture: str | None                     # the piece's texture entry: every material
    window: bool = False                    # a window's model: its glass panes are clear (:func:`is_pane`)


@dataclass(frozen=True)
class Described:
    """What the record says of a model besides its arrays."""
    name: str
    home: str
    catalogue_id: str
    creator: str
    licence: str


def write_model(archive: Sh3dArchive, look: Look, size: np.ndarray, described: Described, folder: Path,
                model_id: str, element: str) -> str:
    """Convert ``look`` into ``folder/<model_id>.npz`` sized ``size`` (depth, width, height in m);
    returns the file's name. Raises FileFieldError (naming ``element``) for an unreadable entry."""
    archive.read(look.entry, element)                               # bounded, present, inside the archive
    obj = read_obj(archive.zip, look.entry)
    materials = [_restyled(archive, m, look, element) for m in obj.materials]
    keep = np.array([not (is_clear_glass(m["d"]) or look.window and is_pane(m)) for m in materials],
                    bool)[obj.face_material]
    faces, face_material = obj.faces[keep], obj.face_material[keep]
    if not len(faces):
        raise ValueError("no visible triangle")
    vertices = obj.vertices
    if look.rotation is not None:
        vertices = vertices @ np.asarray(look.rotation).reshape(3, 3).T
    vertices = vertices[:, [2, 0, 1]]          # theirs: x width, y up, z front; ours: x front, y width, z up
    if look.mirrored:
        vertices = vertices * np.array([1.0, -1.0, 1.0])
        faces = faces[:, ::-1]
    used = vertices[faces].reshape(-1, 3)
    lo, hi = used.min(axis=0), used.max(axis=0)
    vertices = (vertices - (lo + hi) / 2) * (size / np.maximum(hi - lo, 1e-9))
    budget = int(np.clip(TRIANGLE_BUDGET * size.max() / 1.5, MIN_TRIANGLES, TRIANGLE_BUDGET))
    mesh, uvs, face_material = _simplify(vertices, obj.uvs, faces, face_material, budget)
    kept = np.unique(face_material)
    library_materials, textures = _materials(materials, kept)
    remap = np.zeros(int(kept.max()) + 1, np.int64)
    remap[kept] = np.arange(len(kept))
    for name, data in textures.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)
    x, y, z = (round(float(v), 4) for v in mesh.extents)
    record = LibraryRecord(id=model_id, kind="own", name=described.name, catalogue=described.home,
                           catalogue_id=described.catalogue_id, creator=described.creator,
                           licence=described.licence, size=(x, y, z),
                           triangles=len(mesh.faces), materials=library_materials)
    buffer = io.BytesIO()
    np.savez_compressed(buffer, vertices=mesh.vertices.astype(np.float32), faces=mesh.faces.astype(np.uint32),
                        uvs=uvs.astype(np.float32), face_material=remap[face_material].astype(np.uint8),
                        face_piece=piece_labels(mesh.vertices, mesh.faces).astype(np.uint16),
                        record=np.array(json.dumps(record.model_dump(mode="json"))))
    file_name = f"{model_id}.npz"
    (folder / file_name).write_bytes(buffer.getvalue())
    return file_name


def is_pane(material: dict) -> bool:
    """Whether a material of a window's model is its pane: any see-through material (opacity below
    the library's glass cut-off) not named frosted. A window pane is clear glass, which no sensor sees
    (:mod:`ravh_sim.world.library`), however the catalogue tinted it: Sweet Home 3D's windows use
    half-transparent grey (``flltgrey``) and tinted glass for their panes."""
    return material["d"] < GLASS_OPACITY and not re.search(FROSTED, str(material["name"]).lower())


FROSTED = r"frost|opaque|matt|sandblast|satin|obscur|milk"


def _restyled(archive: Sh3dArchive, material: dict, look: Look, element: str) -> dict:
    """An OBJ material as the home shows it: Java 3D's defaults for names no MTL defines, then the home's
    colour and texture overrides (the piece's, then the material's own)."""
    m = dict(material)
    name = m["name"]
    if name in DEFAULT_MATERIALS and tuple(m["Kd"]) == _UNSET_KD and m["map_Kd"] is None:
        kd, opacity, shininess = DEFAULT_MATERIALS[name]
        m.update(Kd=kd, d=opacity, Ns=shininess)
    if look.colour is not None:
        m.update(Kd=look.colour, map_Kd=None)
    if look.texture is not None:
        m.update(map_Kd=archive.read(look.texture, element), Kd=(1.0, 1.0, 1.0))
    for override, colour, texture in look.materials:
        if override == name and colour is not None:
            m.update(Kd=colour, map_Kd=None)
        if override == name and texture is not None:
            m.update(map_Kd=archive.read(texture, element))
    return m


def model_id(look: Look, name: str) -> str:
    """A stable file stem for a look: the piece's name and a digest of the look."""
    slug = "".join(c if c.isalnum() else "_" for c in name.lower()).strip("_")[:40] or "model"
    return f"{slug}_{hashlib.sha1(repr(look).encode()).hexdigest()[:10]}"
