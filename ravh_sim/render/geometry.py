"""The World's bodies as one vertex array for the GPU.

Every triangle corner carries its house-frame position, a shading normal, its position in the body's
own frame (procedural patterns are evaluated there, so a wood grain moves with its table and does
not swim when a door swings), a material index (ravh_sim.render.materials) and the instance id that
instance images store. Normals come from trimesh: smooth across gentle bends (cushions, bowls,
lamp shades), flat across creases (box edges), decided per corner by a crease angle.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh

from ravh_sim.render.materials import MaterialTable
from ravh_sim.world.mesh import Mesh
from ravh_sim.world.scene import Visual, World

FLOATS_PER_VERTEX = 11                       # position 3, normal 3, local 3, material 1, instance 1
VERTEX_FORMAT = "3f 3f 3f 1f 1f"
ATTRIBUTES = ("in_position", "in_normal", "in_local", "in_material", "in_instance")
CREASE_COS = math.cos(math.radians(40.0))    # corners bent less than this share a smooth normal


@dataclass(frozen=True)
class BodyArrays:
    """One body's corners in its own frame: (3F, 3) positions and normals, (3F,) palette indices."""
    local: np.ndarray
    normals: np.ndarray
    materials: np.ndarray


def palette_arrays(mesh: Mesh) -> BodyArrays:
    """Corners, crease-aware normals and palette indices of a palette-coloured model."""
    face_n, valid = trimesh.triangles.normals(mesh.vertices[mesh.faces])
    face_n = _scatter(face_n, valid, len(mesh.faces))
    summed = np.zeros((len(mesh.vertices), 3))
    np.add.at(summed, mesh.faces, face_n[:, None, :])       # trimesh's mean without scipy.sparse
    vertex_n = trimesh.util.unitize(summed)
    corner_face_n = np.repeat(face_n, 3, axis=0)
    corner_vertex_n = vertex_n[mesh.faces.ravel()]
    smooth = np.einsum("ij,ij->i", corner_face_n, corner_vertex_n) > CREASE_COS
    normals = np.where(smooth[:, None], corner_vertex_n, corner_face_n)
    return BodyArrays(mesh.vertices[mesh.faces.ravel()], normals, np.repeat(mesh.colours, 3))


def _scatter(normals: np.ndarray, valid: np.ndarray, count: int) -> np.ndarray:
    """Face normals for every face: degenerate faces (no normal from trimesh) get zero."""
    out = np.zeros((count, 3))
    out[valid] = normals
    return out


def pose_matrix(position, orientation) -> np.ndarray:
    """3x4 [R | t] of a pybullet pose (quaternion x, y, z, w)."""
    x, y, z, w = orientation
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    return np.hstack([r, np.asarray(position, np.float64)[:, None]])


class SceneBuilder:
    """Builds the vertex array of a World, keeping each model's corners between rebuilds."""

    def __init__(self, world: World, materials: MaterialTable) -> None:
        self.world, self.materials = world, materials
        self._palette: dict[int, BodyArrays] = {}          # id(mesh) -> its arrays
        self._meshes: dict[int, Mesh] = {}                  # keeps those meshes alive (ids stay unique)

    def build(self) -> np.ndarray:
        """(3T, FLOATS_PER_VERTEX) float32 of every visible body, in instance order."""
        chunks = []
        for inst in self.world.instances:
            visual = self.world.visuals.get(inst.body)
            if visual is None:
                continue
            chunks.append(self._body(visual, inst.name, inst.id))
        return np.concatenate(chunks).astype(np.float32)

    def _body(self, visual: Visual, name: str, instance_id: int) -> np.ndarray:
        if visual.structure is not None:
            mesh = visual.structure
            corners = mesh.vertices[mesh.faces.ravel()]
            normals = mesh.normals[mesh.faces.ravel()]
            material = np.full(len(corners), self.materials.paint(visual.paint, visual.surface), np.float64)
            return _pack(corners, normals, corners, material, instance_id)
        assert visual.mesh is not None
        key = id(visual.mesh)
        if key not in self._palette:
            self._palette[key] = palette_arrays(visual.mesh)
            self._meshes[key] = visual.mesh
        arrays = self._palette[key]
        pose = pose_matrix(*self.world.object_pose(name))
        world_pos = arrays.local @ pose[:, :3].T + pose[:, 3]
        return _pack(world_pos, arrays.normals @ pose[:, :3].T, arrays.local,
                     arrays.materials.astype(np.float64), instance_id)


def _pack(position: np.ndarray, normal: np.ndarray, local: np.ndarray, material: np.ndarray,
          instance_id: int) -> np.ndarray:
    out = np.empty((len(position), FLOATS_PER_VERTEX), np.float64)
    out[:, 0:3], out[:, 3:6], out[:, 6:9] = position, normal, local
    out[:, 9], out[:, 10] = material, instance_id
    return out
