"""Palette-coloured meshes: low-poly primitives and their OBJ export.

Why: pybullet's EGL renderer crashes on inline vertex meshes but renders OBJ
files, and every body costs a draw call on the software renderer.  So each
object is assembled from primitives into ONE mesh whose faces carry palette
colour indices, and written as one OBJ file whose UVs point into the shared
palette texture (see ``palette.py``).

One mesh type everywhere: ``trimesh.Trimesh``.  What it lacks travels in it:
a palette colour per face in ``face_attributes`` (:func:`coloured`,
:func:`colours`), texture coordinates in a ``TextureVisuals``
(:func:`uv_visual`; library models add a material slot per face, see
``library.py``).  Meshes are built with ``process=False``, so vertices and
faces stay exactly as given, and transformed here rather than by trimesh's
homogeneous matrices, so every coordinate keeps its bits.

Conventions: metres, right-handed, z up; faces are counter-clockwise seen
from outside, so the right-hand normal points outwards.
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Protocol

import numpy as np
import trimesh
from trimesh.exchange.obj import export_obj
from trimesh.visual import TextureVisuals
from trimesh.visual.material import SimpleMaterial

from ravh_sim.poses import rotation_z

Vec3 = Sequence[float] | np.ndarray          # three floats, as a sequence or an array
PALETTE_INDEX = 'palette'                    # face attribute: each face's palette colour


class UvSource(Protocol):
    """What :func:`write_palette_obj` needs from a palette."""

    def uv(self, index: int) -> tuple[float, float]: ...


def coloured(vertices: np.ndarray, faces: np.ndarray, colours: np.ndarray) -> trimesh.Trimesh:
    """Triangles with one palette colour index per face."""
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    colours = np.asarray(colours, np.int32).reshape(-1)
    if len(colours) != len(faces):
        raise ValueError('need exactly one colour per face')
    return trimesh.Trimesh(np.asarray(vertices, np.float64).reshape(-1, 3), faces, process=False,
                           face_attributes={PALETTE_INDEX: colours})


def colours(mesh: trimesh.Trimesh) -> np.ndarray:
    """(M,) palette colour index of each face."""
    return mesh.face_attributes[PALETTE_INDEX]


def uv_visual(uv: np.ndarray) -> TextureVisuals:
    """Per-vertex texture coordinates; the image (palette, paint, library texture) is bound by
    whoever draws."""
    return TextureVisuals(uv=uv, material=SimpleMaterial())


def merged(meshes: Iterable[trimesh.Trimesh]) -> trimesh.Trimesh:
    """One palette mesh holding all triangles of ``meshes``."""
    meshes = list(meshes)
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return coloured(np.concatenate([m.vertices for m in meshes] or [np.zeros((0, 3))]),
                    np.concatenate([m.faces + o for m, o in zip(meshes, offsets)] or [np.zeros((0, 3))]),
                    np.concatenate([colours(m) for m in meshes] or [np.zeros(0)]))


def transformed(mesh: trimesh.Trimesh, rotation: float | np.ndarray = 0.0,
                translation: Vec3 = (0.0, 0.0, 0.0)) -> trimesh.Trimesh:
    """Rotate (yaw angle in radians, or a 3x3 matrix), then translate.

    A mirroring matrix (negative determinant) also reverses the face
    winding so faces stay counter-clockwise seen from outside.
    """
    matrix = np.asarray(rotation, np.float64)
    if matrix.ndim == 0:                                  # a yaw angle
        matrix = rotation_z(float(matrix))
    faces = mesh.faces if np.linalg.det(matrix) > 0 else mesh.faces[:, ::-1]
    return coloured(np.asarray(mesh.vertices) @ matrix.T + np.asarray(translation, np.float64), faces,
                    colours(mesh))


def scaled(mesh: trimesh.Trimesh, factors: Vec3 | float) -> trimesh.Trimesh:
    """Scale about the origin per axis; a mirroring scale also reverses the face winding."""
    per_axis = np.broadcast_to(np.asarray(factors, np.float64), (3,))
    faces = mesh.faces if np.prod(np.sign(per_axis)) > 0 else mesh.faces[:, ::-1]
    return coloured(np.asarray(mesh.vertices) * per_axis, faces, colours(mesh))


def write_palette_obj(mesh: trimesh.Trimesh, path: str | Path, palette: UvSource) -> None:
    """Write a flat-shaded, palette-textured Wavefront OBJ file (trimesh's writer).

    Each face gets its own three corners, with the face's normal and the UV of its colour's
    palette cell; positions are rounded to 5 decimals and normals to 4, so the same mesh always
    produces a byte-identical file.
    """
    Path(path).write_text(palette_obj_text(mesh, palette), encoding='ascii')


def palette_obj_text(mesh: trimesh.Trimesh, palette: UvSource) -> str:
    """The text :func:`write_palette_obj` writes."""
    cross = mesh.triangles_cross
    length = np.linalg.norm(cross, axis=1, keepdims=True)
    normals = np.where(length > 0, cross / np.where(length > 0, length, 1.0), (0.0, 0.0, 1.0))
    used, uv_of_face = np.unique(colours(mesh), return_inverse=True)
    uvs = np.array([palette.uv(int(c)) for c in used], np.float64).reshape(-1, 2)
    corners = trimesh.Trimesh(_clean(np.asarray(mesh.vertices), 5)[mesh.faces.ravel()],
                              np.arange(3 * len(mesh.faces)).reshape(-1, 3), process=False,
                              vertex_normals=np.repeat(_clean(normals, 4), 3, axis=0),
                              visual=uv_visual(np.repeat(uvs[uv_of_face.reshape(-1)], 3, axis=0)))
    return export_obj(corners, include_normals=True, digits=6,
                      header=f'ravh_sim procedural mesh: {len(mesh.faces)} triangles')


def _clean(values: np.ndarray, decimals: int) -> np.ndarray:
    """Round and turn negative zeros positive so printed text is canonical."""
    return np.round(values, decimals) + 0.0


# --- primitives -------------------------------------------------------------

_BOX_QUADS = ((0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6))
_AXIS_FRAMES = {  # columns: where the primitive's local x, y, z go (cyclic, so proper rotations)
    'z': np.eye(3),
    'x': np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    'y': np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
}


def _quads(quads: Iterable[Sequence[int]]) -> np.ndarray:
    return np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])


def _solid(vertices: np.ndarray, faces: np.ndarray, colour: int) -> trimesh.Trimesh:
    return coloured(vertices, faces, np.full(len(faces), colour))


def box(center: Vec3, size: Vec3, colour: int) -> trimesh.Trimesh:
    """Axis-aligned cuboid (12 triangles)."""
    corners = np.array([[x, y, z] for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)])
    return _solid(corners * np.abs(size) + np.asarray(center, np.float64), _quads(_BOX_QUADS), colour)


def frustum(center: Vec3, radius_bottom: float, radius_top: float, height: float, colour: int,
            segments: int = 8, axis: str = 'z') -> trimesh.Trimesh:
    """Tapered cylinder along ``axis``; a zero radius gives a cone (apex, no cap).

    ``segments`` divisible by 4 makes the bounding box exactly +-radius.
    """
    n = max(3, segments)
    angle = 2.0 * np.pi * np.arange(n) / n
    ring = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    top_is_apex = radius_top <= 0.0
    bottom = np.column_stack([ring * radius_bottom, np.full(n, -height / 2)])
    top = (np.array([[0.0, 0.0, height / 2]]) if top_is_apex
           else np.column_stack([ring * radius_top, np.full(n, height / 2)]))
    k, k1, fan = np.arange(n), (np.arange(n) + 1) % n, np.arange(1, n - 1)
    bottom_cap = np.column_stack([np.zeros(n - 2, int), fan + 1, fan])
    if top_is_apex:
        faces = np.concatenate([np.column_stack([k, k1, np.full(n, n)]), bottom_cap])
    else:
        sides = np.concatenate([np.column_stack([k, k1, k1 + n]), np.column_stack([k, k1 + n, k + n])])
        top_cap = np.column_stack([np.full(n - 2, n), fan + n, fan + n + 1])
        faces = np.concatenate([sides, bottom_cap, top_cap])
    vertices = np.concatenate([bottom, top]) @ _AXIS_FRAMES[axis].T + np.asarray(center, np.float64)
    return _solid(vertices, faces, colour)


def cylinder(center: Vec3, radius: float, height: float, colour: int,
             segments: int = 8, axis: str = 'z') -> trimesh.Trimesh:
    """Closed prism approximating a cylinder (4 * segments - 4 triangles)."""
    return frustum(center, radius, radius, height, colour, segments, axis)


def _convex(vertices: np.ndarray, faces: np.ndarray, center: Vec3, colour: int) -> trimesh.Trimesh:
    """Orient faces of a convex solid centred at the origin outwards, then place it."""
    v0, v1, v2 = (vertices[faces[:, k]] for k in range(3))
    inward = np.einsum('ij,ij->i', np.cross(v1 - v0, v2 - v0), v0 + v1 + v2) < 0
    faces = np.where(inward[:, None], faces[:, ::-1], faces)
    return _solid(vertices + np.asarray(center, np.float64), faces, colour)


def rounded_box(center: Vec3, size: Vec3, colour: int, bevel: float) -> trimesh.Trimesh:
    """Cuboid with all 12 edges chamfered by ``bevel`` (44 triangles).

    Good for cushions, mattresses and pillows.  Falls back to ``box`` when
    the bevel is negligible.
    """
    half = np.abs(np.asarray(size, np.float64)) / 2
    bevel = min(bevel, 0.45 * half.min())
    if bevel <= 1e-6 * max(half.max(), 1e-9):
        return box(center, size, colour)
    signs = [(i, j, k) for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)]
    index = {}
    vertices: list[np.ndarray] = []
    for corner in signs:
        for axis in range(3):
            point = np.array(corner) * (half - bevel)
            point[axis] = corner[axis] * half[axis]
            index[corner, axis] = len(vertices)
            vertices.append(point)
    quads = []
    for axis in range(3):
        u, w = [a for a in range(3) if a != axis]
        for sign in (-1, 1):  # the flat face
            quads.append([index[_corner(axis, sign, u, su, w, sw), axis]
                          for su, sw in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
        for su in (-1, 1):  # the chamfers along this axis
            for sw in (-1, 1):
                lo, hi = (_corner(axis, s, u, su, w, sw) for s in (-1, 1))
                quads.append([index[lo, u], index[hi, u], index[hi, w], index[lo, w]])
    corners = np.array([[index[c, 0], index[c, 1], index[c, 2]] for c in signs])
    return _convex(np.array(vertices), np.concatenate([_quads(quads), corners]), center, colour)


def _corner(axis: int, sign: int, u: int, su: int, w: int, sw: int) -> tuple[int, int, int]:
    corner = [0, 0, 0]
    corner[axis], corner[u], corner[w] = sign, su, sw
    x, y, z = corner
    return (x, y, z)


_PHI = (1.0 + 5.0 ** 0.5) / 2.0
_ICOSAHEDRON = np.array([[-1, _PHI, 0], [1, _PHI, 0], [-1, -_PHI, 0], [1, -_PHI, 0],
                         [0, -1, _PHI], [0, 1, _PHI], [0, -1, -_PHI], [0, 1, -_PHI],
                         [_PHI, 0, -1], [_PHI, 0, 1], [-_PHI, 0, -1], [-_PHI, 0, 1]])
_ICOSAHEDRON_FACES = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
                               [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
                               [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
                               [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])


def ellipsoid(center: Vec3, size: Vec3, colour: int) -> trimesh.Trimesh:
    """Icosahedron stretched to fill ``size`` (20 triangles): foliage, globes."""
    unit = _ICOSAHEDRON / _ICOSAHEDRON.max(axis=0)
    return _convex(unit * np.abs(np.asarray(size, np.float64)) / 2, _ICOSAHEDRON_FACES, center, colour)


def hulls_obj_text(parts: Sequence[trimesh.Trimesh]) -> str:
    """OBJ text with one object per part (positions and faces only) for a collision shape.

    pybullet loads such a file as a compound of one convex hull per object, which is exactly the
    part when the part is convex (as every primitive here is).
    """
    scene = trimesh.Scene()
    for i, part in enumerate(parts):
        scene.add_geometry(trimesh.Trimesh(_clean(np.asarray(part.vertices), 5), part.faces, process=False),
                           geom_name=f'part{i}')
    return export_obj(scene, include_normals=False, include_texture=False, digits=5,
                      header=f'ravh_sim collision parts: {len(parts)} convex hulls')
