"""Small 2D geometry helpers on floor polygons and wall segments (pure Python/numpy)."""
from __future__ import annotations

import math

import numpy as np

Polygon = tuple[tuple[float, float], ...]


def polygon_area(poly: Polygon) -> float:
    """Unsigned area by the shoelace formula."""
    s = 0.0
    for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]):
        s += x0 * y1 - x1 * y0
    return abs(s) / 2.0


def point_in_polygon(x: float, y: float, poly: Polygon) -> bool:
    """Even-odd ray casting; points on an edge may fall either way."""
    inside = False
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def points_in_polygon(xs: np.ndarray, ys: np.ndarray, poly: Polygon) -> np.ndarray:
    """Vectorised :func:`point_in_polygon` over arrays of equal shape."""
    inside = np.zeros(np.shape(xs), dtype=bool)
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        if y0 == y1:
            continue
        crosses = (y0 > ys) != (y1 > ys)
        x_cross = x0 + (ys - y0) * (x1 - x0) / (y1 - y0)
        inside ^= crosses & (xs < x_cross)
    return inside


def polygon_centroid(poly: Polygon) -> tuple[float, float]:
    """Area centroid (falls back to the vertex mean for degenerate polygons)."""
    a = cx = cy = 0.0
    for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]):
        c = x0 * y1 - x1 * y0
        a += c
        cx += (x0 + x1) * c
        cy += (y0 + y1) * c
    if abs(a) < 1e-12:
        return (sum(p[0] for p in poly) / len(poly), sum(p[1] for p in poly) / len(poly))
    return (cx / (3 * a), cy / (3 * a))


def box_corners(center: tuple[float, float], size: tuple[float, float], yaw: float) -> np.ndarray:
    """The 4 corners (4, 2) of a yawed rectangle, counter-clockwise."""
    c, s = math.cos(yaw), math.sin(yaw)
    hx, hy = size[0] / 2, size[1] / 2
    local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    rot = np.array([[c, -s], [s, c]])
    return local @ rot.T + np.asarray(center)


def quaternion_from_yaw(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation about +z."""
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def triangulate(poly: Polygon) -> list[tuple[int, int, int]]:
    """Ear-clipping triangulation of a simple polygon; triangles are counter-clockwise.

    Room floors are simple polygons of a few to a few dozen vertices, so O(n^3) is plenty.
    """
    pts = list(poly)
    idx = list(range(len(pts)))
    if _signed_area(pts) < 0:
        idx.reverse()
    triangles: list[tuple[int, int, int]] = []
    guard = 0
    while len(idx) > 3 and guard < 10 * len(pts):
        guard += 1
        for k in range(len(idx)):
            i, j, m = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            if _is_ear(pts, idx, i, j, m):
                triangles.append((i, j, m))
                idx.pop(k)
                break
        else:                       # degenerate (collinear runs): drop the flattest vertex
            k = min(range(len(idx)), key=lambda k: abs(_cross(pts[idx[k - 1]], pts[idx[k]],
                                                              pts[idx[(k + 1) % len(idx)]])))
            idx.pop(k)
    if len(idx) == 3:
        triangles.append((idx[0], idx[1], idx[2]))
    return [t for t in triangles if abs(_cross(pts[t[0]], pts[t[1]], pts[t[2]])) > 1e-12]


def _signed_area(pts: list) -> float:
    return sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1])) / 2


def _cross(a, b, c) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def _is_ear(pts: list, idx: list[int], i: int, j: int, m: int) -> bool:
    a, b, c = pts[i], pts[j], pts[m]
    if _cross(a, b, c) <= 1e-12:
        return False
    for k in idx:
        if k in (i, j, m):
            continue
        p = pts[k]
        if _cross(a, b, p) >= 0 and _cross(b, c, p) >= 0 and _cross(c, a, p) >= 0:
            return False
    return True
