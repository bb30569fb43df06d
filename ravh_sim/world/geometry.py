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


def distance_to_polygon(x: float, y: float, poly: Polygon) -> float:
    """Distance from (x, y) to the outline of ``poly`` (0 on an edge)."""
    return min(_distance_to_segment(x, y, a, b) for a, b in zip(poly, poly[1:] + poly[:1]))


def _distance_to_segment(x: float, y: float, a, b) -> float:
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((x - a[0]) * dx + (y - a[1]) * dy) / length2))
    return math.hypot(x - a[0] - t * dx, y - a[1] - t * dy)


def self_intersection(poly: Polygon) -> tuple[int, int] | None:
    """The first pair of non-adjacent edges (i, j) that cross or touch; None for a simple polygon."""
    n = len(poly)
    edges = [(poly[i], poly[(i + 1) % n]) for i in range(n)]
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue                       # the closing edge meets the first one at a vertex
            if _segments_meet(*edges[i], *edges[j]):
                return i, j
    return None


def _segments_meet(a, b, c, d) -> bool:
    d1, d2, d3, d4 = _cross(c, d, a), _cross(c, d, b), _cross(a, b, c), _cross(a, b, d)
    if (d1 > 0) != (d2 > 0) and (d3 > 0) != (d4 > 0) and 0 not in (d1, d2, d3, d4):
        return True
    return any(abs(o) < 1e-12 and _on_segment(p, q, r) for o, p, q, r in (
        (d1, c, d, a), (d2, c, d, b), (d3, a, b, c), (d4, a, b, d)))


def _on_segment(p, q, r) -> bool:
    """r lies within the bounding box of segment pq (r is known to be collinear)."""
    return min(p[0], q[0]) - 1e-12 <= r[0] <= max(p[0], q[0]) + 1e-12 and \
        min(p[1], q[1]) - 1e-12 <= r[1] <= max(p[1], q[1]) + 1e-12


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
