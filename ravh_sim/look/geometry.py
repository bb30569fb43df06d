"""The World's bodies as one vertex array for the GPU.

Every triangle corner carries its house-frame position, a shading normal, its position in the body's
own frame (procedural patterns are evaluated there, so a wood grain moves with its table and does
not swim when a door swings), a material index (ravh_sim.look.materials), the instance id that
instance images store and a texture coordinate (library models' textures; zero elsewhere). Normals
come from trimesh: smooth across gentle bends (cushions, bowls, lamp shades), flat across creases
(box edges), decided per corner by a crease angle. At the ``dataset`` level of detail library models
are drawn at the library's dataset level (:func:`ravh_sim.world.library.dataset_model`), in the same
place as the live model that collides.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh

from ravh_sim.look.materials import MaterialTable
from ravh_sim.poses import pose_matrix
from ravh_sim.world import library
from ravh_sim.world.library import Detail
from ravh_sim.world.mesh import colours
from ravh_sim.world.scene import Visual, World

FLOATS_PER_VERTEX = 13                       # position 3, normal 3, local 3, material 1, instance 1, uv 2
VERTEX_FORMAT = "3f 3f 3f 1f 1f 2f"
ATTRIBUTES = ("in_position", "in_normal", "in_local", "in_material", "in_instance", "in_uv")
CREASE_COS = math.cos(math.radians(40.0))    # corners bent less than this share a smooth normal
WELD_DECIMALS = 5                            # corners this close (10 um) are one place for smoothing
SOFT_MODELS = ("Armchair", "Sofa", "Bed", "Toilet", "Washbasin", "Sink", "Bathtub")
"""Library kinds shaded smooth across their split vertices: upholstery and moulded ceramics, decimated
into facets that their authors' seams left unwelded (hard furniture keeps its authors' edges)."""


@dataclass(frozen=True)
class BodyArrays:
    """One body's corners in its own frame: (3F, 3) positions and normals, (3F,) material indices,
    (3F, 2) texture coordinates."""
    local: np.ndarray
    normals: np.ndarray
    materials: np.ndarray
    uvs: np.ndarray


def palette_arrays(mesh: trimesh.Trimesh) -> BodyArrays:
    """Corners, crease-aware normals and palette indices of a palette-coloured model."""
    return BodyArrays(mesh.vertices[mesh.faces.ravel()], corner_normals(mesh.vertices, mesh.faces),
                      np.repeat(colours(mesh), 3), np.zeros((3 * len(mesh.faces), 2)))


def model_arrays(fitted: trimesh.Trimesh, slots: np.ndarray) -> BodyArrays:
    """Corners, normals, material slots (``slots[k]``: the table index of the model's material k)
    and texture coordinates of a fitted library model."""
    faces = fitted.faces
    material = library.face_material(fitted)
    soft = library.record(fitted).kind.split("/")[0] in SOFT_MODELS
    return BodyArrays(fitted.vertices[faces.ravel()], corner_normals(fitted.vertices, faces, soft),
                      np.repeat(slots[material], 3), fitted.visual.uv[faces.ravel()])


def corner_normals(vertices: np.ndarray, faces: np.ndarray, welded: bool = False) -> np.ndarray:
    """(3F, 3) normals: smooth across gentle bends, flat across creases (CREASE_COS). A split vertex
    is a hard edge (the model's author put it there: a cabinet door's raised panel), and each corner
    takes its vertex's mean normal unless its face bends away from it. A ``welded`` model is soft
    (:data:`SOFT_MODELS`): its split vertices are seams, not edges (an armchair's 368
    places have 1,600 vertices, and its upholstery had shaded as facets): their corners at one place
    share the mean of the faces there that bend less than CREASE_COS from their own (so a box's corner
    stays a crease however its sides are cut into triangles), weighted by the faces' angles there."""
    face_n, valid = trimesh.triangles.normals(vertices[faces])
    face_n = _scatter(face_n, valid, len(faces))
    if welded:
        return _welded_normals(vertices, faces, face_n)
    corner_face_n = np.repeat(face_n, 3, axis=0)
    summed = np.zeros((len(vertices), 3))
    np.add.at(summed, faces, face_n[:, None, :])            # trimesh's mean without scipy.sparse
    corner_vertex_n = trimesh.util.unitize(summed)[faces.ravel()]
    smooth = np.einsum("ij,ij->i", corner_face_n, corner_vertex_n) > CREASE_COS
    return np.where(smooth[:, None], corner_vertex_n, corner_face_n)


def _welded_normals(vertices: np.ndarray, faces: np.ndarray, face_n: np.ndarray) -> np.ndarray:
    """(3F, 3) per-corner smoothing groups over places (see :func:`corner_normals`)."""
    weight = np.nan_to_num(trimesh.triangles.angles(vertices[faces])).ravel()
    _, place = np.unique(np.round(vertices, WELD_DECIMALS), axis=0, return_inverse=True)
    corner_place = place.reshape(-1)[faces].ravel()
    corner_n = np.repeat(face_n, 3, axis=0)
    order = np.argsort(corner_place, kind="stable")          # every pair of corners at one place
    counts = np.bincount(corner_place)[corner_place[order]]
    first = np.searchsorted(corner_place[order], corner_place[order])
    rows = np.repeat(np.arange(len(order)), counts)
    step = np.arange(len(rows)) - np.repeat(np.cumsum(counts) - counts, counts)
    corner, other = order[rows], order[first[rows] + step]
    near = np.einsum("ij,ij->i", corner_n[corner], corner_n[other]) > CREASE_COS
    summed = np.zeros((len(corner_n), 3))
    np.add.at(summed, corner[near], corner_n[other[near]] * weight[other[near], None])
    return np.where(np.linalg.norm(summed, axis=1)[:, None] > 0, trimesh.util.unitize(summed), corner_n)


def _scatter(normals: np.ndarray, valid: np.ndarray, count: int) -> np.ndarray:
    """Face normals for every face: degenerate faces (no normal from trimesh) get zero."""
    out = np.zeros((count, 3))
    out[valid] = normals
    return out


class SceneBuilder:
    """Builds the vertex array of a World, keeping each model's corners between rebuilds."""

    def __init__(self, world: World, materials: MaterialTable, detail: Detail = "live") -> None:
        self.world, self.materials, self.detail = world, materials, detail
        self._arrays: dict[int, BodyArrays] = {}           # id(mesh or fitted model) -> its arrays
        self._kept: dict[int, trimesh.Trimesh] = {}         # keeps those alive (ids stay unique)

    def build(self) -> np.ndarray:
        """(3T, FLOATS_PER_VERTEX) float32 of every visible body, in instance order, written into one
        array (no per-body copies: the dataset level of detail has several times the triangles)."""
        shown_bodies = []
        for inst in self.world.instances:
            visual = self.world.visuals.get(inst.body)
            if visual is not None:
                shown_bodies.append((visual, inst.name, inst.id, self._corners(visual)))
        out = np.empty((sum(n for *_, n in shown_bodies), FLOATS_PER_VERTEX), np.float32)
        start = 0
        for visual, name, instance_id, n in shown_bodies:
            self._body(visual, name, instance_id, out[start:start + n])
            start += n
        shown = {id(v.model if v.model is not None else v.mesh) for v in self.world.visuals.values()}
        for key in set(self._arrays) - shown:              # models swapped out: forget their arrays
            del self._arrays[key], self._kept[key]
        return out

    def _corners(self, visual: Visual) -> int:
        """How many corners a body has (its arrays made and kept on the way for a model)."""
        if visual.structure is not None:
            return 3 * len(visual.structure.faces)
        return len(self._model_arrays(visual).local)

    def _model_arrays(self, visual: Visual) -> BodyArrays:
        source = visual.model if visual.model is not None else visual.mesh
        assert source is not None
        key = id(source)
        if key not in self._arrays:
            if visual.model is not None:
                record = library.record(source)
                slots = np.array([self.materials.library(record.id, k, m) for k, m in enumerate(record.materials)])
                fitted = library.dataset_model(source) if self.detail == "dataset" else source
                arrays = model_arrays(fitted, slots)
            else:
                arrays = palette_arrays(source)
            # kept in single precision, what the GPU reads: a house's unique models are as many
            # corners as the vertex buffer (several times more at the dataset level)
            self._arrays[key] = BodyArrays(arrays.local.astype(np.float32), arrays.normals.astype(np.float32),
                                           arrays.materials.astype(np.int32), arrays.uvs.astype(np.float32))
            self._kept[key] = source
        return self._arrays[key]

    def _body(self, visual: Visual, name: str, instance_id: int, out: np.ndarray) -> None:
        if visual.structure is not None:
            mesh = visual.structure
            corners = mesh.vertices[mesh.faces.ravel()]
            normals = mesh.vertex_normals[mesh.faces.ravel()]
            material = np.full(len(corners), self.materials.paint(visual.paint, visual.surface), np.float64)
            _pack(out, corners, normals, corners, material, instance_id, np.zeros((len(corners), 2)))
            return
        arrays = self._model_arrays(visual)
        pose = pose_matrix(*self.world.object_pose(name))
        world_pos = arrays.local @ pose[:, :3].T + pose[:, 3]
        _pack(out, world_pos, arrays.normals @ pose[:, :3].T, arrays.local,
              arrays.materials.astype(np.float64), instance_id, arrays.uvs)


def _pack(out: np.ndarray, position: np.ndarray, normal: np.ndarray, local: np.ndarray, material: np.ndarray,
          instance_id: int, uvs: np.ndarray) -> None:
    """One body's corners into its rows of the vertex array (float32: what the GPU reads)."""
    out[:, 0:3], out[:, 3:6], out[:, 6:9] = position, normal, local
    out[:, 9], out[:, 10], out[:, 11:13] = material, instance_id, uvs
