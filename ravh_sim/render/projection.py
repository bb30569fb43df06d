"""Pinhole camera <-> OpenGL matrices, exact to the pixel.

The projection is built from K (fx, fy, cx, cy, near, far), so a 3D point projected with K lands on
the pixel where it is drawn (OpenCV pixel convention: pixel i covers [i - 0.5, i + 0.5]).
"""
from __future__ import annotations

import math

import numpy as np

# Optical frame -> OpenGL eye frame (x right, y up, z backwards).
OPTICAL_TO_GL = np.diag([1.0, -1.0, -1.0])


def projection_from_K(K: np.ndarray, width: int, height: int, near: float, far: float,
                      sample_offset: tuple[float, float] = (0.5, 0.5)) -> np.ndarray:
    """OpenGL projection (row-major 4x4) whose pixels match the pinhole model K exactly.

    OpenCV's pixel (u, v) has its centre at (u, v). A renderer colours it with what it finds at
    window x = u + ox and, rows being flipped, y = height - v - oy, with (ox, oy) = ``sample_offset``:
    (0.5, 0.5) for OpenGL, which samples pixel centres. Solving NDC = f(K) for both axes gives the
    principal-point terms.
    """
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    ox, oy = sample_offset
    return np.array([
        [2 * fx / width, 0.0, 1 - 2 * (cx + ox) / width, 0.0],
        [0.0, 2 * fy / height, 2 * (cy + oy) / height - 1, 0.0],
        [0.0, 0.0, -(far + near) / (far - near), -2 * far * near / (far - near)],
        [0.0, 0.0, -1.0, 0.0]])


def view_matrix(position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """OpenGL view matrix (row-major 4x4) of an optical frame (rotation columns = x right, y down, z fwd)."""
    eye = rotation @ OPTICAL_TO_GL                 # eye-frame axes in the house frame
    view = np.eye(4)
    view[:3, :3] = eye.T
    view[:3, 3] = -eye.T @ position
    return view


def look_at(forward: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Rotation-only view matrix (4x4) looking along ``forward``."""
    f = forward / np.linalg.norm(forward)
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    return view


def perspective(fov_y: float, aspect: float, near: float, far: float) -> np.ndarray:
    f = 1.0 / math.tan(fov_y / 2)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)], [0, 0, -1, 0]])


def orthographic(left: float, right: float, bottom: float, top: float, near: float, far: float
                 ) -> np.ndarray:
    return np.array([[2 / (right - left), 0, 0, -(right + left) / (right - left)],
                     [0, 2 / (top - bottom), 0, -(top + bottom) / (top - bottom)],
                     [0, 0, -2 / (far - near), -(far + near) / (far - near)], [0, 0, 0, 1]])
