"""A small triangle-mesh type with low-poly primitives and OBJ export.

Why: pybullet's EGL renderer crashes on inline vertex meshes but renders OBJ
files, and every body costs a draw call on the software renderer.  So each
object is assembled from primitives into ONE mesh whose faces carry palette
colour indices, and written as one OBJ file whose UVs point into the shared
palette texture (see ``palette.py``).

Conventions: metres, right-handed, z up; faces are counter-clockwise seen
from outside, so the right-hand normal points outwards.
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from ravh_sim.poses import rotation_z

Vec3 = Sequence[float] | np.ndarray          # three floats, as a sequence or an array


class UvSource(Protocol):
    """What ``Mesh.write_obj`` needs from a palette."""

    def uv(self, index: int) -> tuple[float, float]: ...


@dataclass(frozen=True)
class Mesh:
    """Triangles with one palette colour index per face."""

    vertices: np.ndarray  # (N, 3) float64
    faces: np.ndarray  # (M, 3) int32, counter-clockwise seen from outside
    colours: np.ndarray  # (M,) int32 palette indices

    def __post_init__(self) -> None:
        object.__setattr__(self, 'vertices', np.asarray(self.vertices, np.float64).reshape(-1, 3))
        object.__setattr__(self, 'faces', np.asarray(self.faces, np.int32).reshape(-1, 3))
        object.__setattr__(self, 'colours', np.asarray(self.colours, np.int32).reshape(-1))
        if len(self.colours) != len(self.faces):
            raise ValueError('need exactly one colour per face')

    @staticmethod
    def merged(meshes: Iterable[Mesh]) -> Mesh:
        """One mesh holding all triangles of ``meshes``."""
        meshes = list(meshes)
        offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
        return Mesh(
            np.concatenate([m.vertices for m in meshes] or [np.zeros((0, 3))]),
            np.concatenate([m.faces + o for m, o in zip(meshes, offsets)] or [np.zeros((0, 3))]),
            np.concatenate([m.colours for m in meshes] or [np.zeros(0)]))

    @property
    def triangle_count(self) -> int:
        return len(self.faces)

    def transformed(self, rotation: float | np.ndarray = 0.0,
                    translation: Vec3 = (0.0, 0.0, 0.0)) -> Mesh:
        """Rotate (yaw angle in radians, or a 3x3 matrix), then translate.

        A mirroring matrix (negative determinant) also reverses the face
        winding so faces stay counter-clockwise seen from outside.
        """
        matrix = np.asarray(rotation, np.float64)
        if matrix.ndim == 0:                                  # a yaw angle
            matrix = rotation_z(float(matrix))
        faces = self.faces if np.linalg.det(matrix) > 0 else self.faces[:, ::-1]
        return Mesh(self.vertices @ matrix.T + np.asarray(translation, np.float64), faces, self.colours)

    def scaled(self, factors: Vec3 | float) -> Mesh:
        """Scale about the origin per axis; a mirroring scale also reverses the face winding."""
        per_axis = np.broadcast_to(np.asarray(factors, np.float64), (3,))
        faces = self.faces if np.prod(np.sign(per_axis)) > 0 else self.faces[:, ::-1]
        return Mesh(self.vertices * per_axis, faces, self.colours)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned (min corner, max corner)."""
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    def face_cross(self) -> np.ndarray:
        """Per-face (v1 - v0) x (v2 - v0): outward, with twice the area as length."""
        v0, v1, v2 = (self.vertices[self.faces[:, k]] for k in range(3))
        return np.cross(v1 - v0, v2 - v0)

    def face_areas(self) -> np.ndarray:
        return 0.5 * np.linalg.norm(self.face_cross(), axis=1)

    def signed_volume(self) -> float:
        """Enclosed volume; positive when faces wind outwards."""
        v0, v1, v2 = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(np.einsum('ij,ij->', v0, np.cross(v1, v2)) / 6.0)

    def write_obj(self, path: str | Path, palette: UvSource) -> None:
        """Write a flat-shaded, palette-textured Wavefront OBJ file.

        Each face gets its own normal and the UV of its colour's palette cell;
        normals and UVs are de-duplicated in sorted order, so the same mesh
        always produces a byte-identical file.
        """
        Path(path).write_text(self.obj_text(palette), encoding='ascii')

    def obj_text(self, palette: UvSource) -> str:
        """The text ``write_obj`` writes."""
        cross = self.face_cross()
        length = np.linalg.norm(cross, axis=1, keepdims=True)
        normals = np.where(length > 0, cross / np.where(length > 0, length, 1.0), (0.0, 0.0, 1.0))
        normals, normal_of_face = np.unique(_clean(normals, 4), axis=0, return_inverse=True)
        used, uv_of_face = np.unique(self.colours, return_inverse=True)
        uvs = [palette.uv(int(c)) for c in used]
        per_face = np.column_stack([uv_of_face.reshape(-1), normal_of_face.reshape(-1)]) + 1
        corner = np.concatenate([self.faces[:, :, None] + 1, np.repeat(per_face[:, None, :], 3, axis=1)],
                                axis=2)  # (face, corner, v/vt/vn)
        lines = [f'# ravh_sim procedural mesh: {len(self.vertices)} vertices, '
                 f'{len(self.faces)} triangles']
        lines += ['v %.5f %.5f %.5f' % tuple(v) for v in _clean(self.vertices, 5)]
        lines += ['vt %.6f %.6f' % uv for uv in uvs]
        lines += ['vn %.4f %.4f %.4f' % tuple(n) for n in normals]
        lines += ['f %d/%d/%d %d/%d/%d %d/%d/%d' % tuple(c.ravel()) for c in corner]
        return '\n'.join(lines) + '\n'


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


def _solid(vertices: np.ndarray, faces: np.ndarray, colour: int) -> Mesh:
    return Mesh(vertices, faces, np.full(len(faces), colour))


def box(center: Vec3, size: Vec3, colour: int) -> Mesh:
    """Axis-aligned cuboid (12 triangles)."""
    corners = np.array([[x, y, z] for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)])
    return _solid(corners * np.abs(size) + np.asarray(center, np.float64), _quads(_BOX_QUADS), colour)


def frustum(center: Vec3, radius_bottom: float, radius_top: float, height: float, colour: int,
            segments: int = 8, axis: str = 'z') -> Mesh:
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
             segments: int = 8, axis: str = 'z') -> Mesh:
    """Closed prism approximating a cylinder (4 * segments - 4 triangles)."""
    return frustum(center, radius, radius, height, colour, segments, axis)


def _convex(vertices: np.ndarray, faces: np.ndarray, center: Vec3, colour: int) -> Mesh:
    """Orient faces of a convex solid centred at the origin outwards, then place it."""
    v0, v1, v2 = (vertices[faces[:, k]] for k in range(3))
    inward = np.einsum('ij,ij->i', np.cross(v1 - v0, v2 - v0), v0 + v1 + v2) < 0
    faces = np.where(inward[:, None], faces[:, ::-1], faces)
    return _solid(vertices + np.asarray(center, np.float64), faces, colour)


def rounded_box(center: Vec3, size: Vec3, colour: int, bevel: float) -> Mesh:
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


def ellipsoid(center: Vec3, size: Vec3, colour: int) -> Mesh:
    """Icosahedron stretched to fill ``size`` (20 triangles): foliage, globes."""
    unit = _ICOSAHEDRON / _ICOSAHEDRON.max(axis=0)
    return _convex(unit * np.abs(np.asarray(size, np.float64)) / 2, _ICOSAHEDRON_FACES, center, colour)


def hulls_obj_text(parts: Sequence[Mesh]) -> str:
    """OBJ text with one object per part (positions and faces only) for a collision shape.

    pybullet loads such a file as a compound of one convex hull per object, which is exactly the
    part when the part is convex (as every primitive here is).
    """
    lines, offset = [f'# ravh_sim collision parts: {len(parts)} convex hulls'], 1
    for i, part in enumerate(parts):
        lines.append(f'o part{i}')
        lines += ['v %.5f %.5f %.5f' % tuple(v) for v in _clean(part.vertices, 5)]
        lines += ['f %d %d %d' % tuple(f) for f in part.faces + offset]
        offset += len(part.vertices)
    return '\n'.join(lines) + '\n'
