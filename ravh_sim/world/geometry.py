"""2D geometry on floor polygons: shapely's tests and measures over the house files' outlines.

Outlines are tuples of (x, y) points, as the house files give them. Triangulation stays an ear
clipping of our own: the floor meshes index the outline's own vertices, which shapely's
triangulations (new vertices, Delaunay) do not keep.
"""
from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np
import shapely

from ravh_sim.poses import rotation_z

Polygon = tuple[tuple[float, float], ...]


def shape(poly: Sequence[Sequence[float]]) -> shapely.Polygon:
    """The shapely polygon of an outline, built once per outline and prepared for fast tests."""
    return _prepared(tuple((float(x), float(y)) for x, y in poly))


@functools.lru_cache(maxsize=4096)
def _prepared(poly: Polygon) -> shapely.Polygon:
    polygon = shapely.Polygon(poly)
    shapely.prepare(polygon)
    return polygon


def polygon_area(poly: Polygon) -> float:
    return float(shape(poly).area)


def point_in_polygon(x: float, y: float, poly: Polygon) -> bool:
    """Whether (x, y) lies inside ``poly`` or on its outline."""
    return bool(shapely.intersects_xy(shape(poly), x, y))


def points_in_polygon(xs: np.ndarray, ys: np.ndarray, poly: Polygon) -> np.ndarray:
    """Vectorised :func:`point_in_polygon` over arrays of equal shape."""
    return shapely.intersects_xy(shape(poly), xs, ys)


def distance_to_polygon(x: float, y: float, poly: Polygon) -> float:
    """Distance from (x, y) to the outline of ``poly`` (0 on an edge)."""
    return float(shapely.distance(shape(poly).exterior, shapely.Point(x, y)))


def self_intersection(poly: Polygon) -> tuple[int, int] | None:
    """The first pair of non-adjacent edges (i, j) that cross or touch; None for a simple polygon."""
    if shapely.LinearRing(poly).is_simple:
        return None
    n = len(poly)
    edges = shapely.linestrings([(poly[i], poly[(i + 1) % n]) for i in range(n)])
    for i in range(n):
        last = n - 1 if i == 0 else n          # the closing edge meets the first one at a vertex
        meets = np.flatnonzero(shapely.intersects(edges[i], edges[i + 2:last]))
        if meets.size:
            return i, i + 2 + int(meets[0])
    return None


def polygon_centroid(poly: Polygon) -> tuple[float, float]:
    """Area centroid (the vertex mean for degenerate polygons)."""
    centre = shape(poly).centroid
    if shape(poly).area < 1e-12 or centre.is_empty:
        return (sum(p[0] for p in poly) / len(poly), sum(p[1] for p in poly) / len(poly))
    return (centre.x, centre.y)


def box_corners(center: tuple[float, float], size: tuple[float, float], yaw: float) -> np.ndarray:
    """The 4 corners (4, 2) of a yawed rectangle, counter-clockwise."""
    hx, hy = size[0] / 2, size[1] / 2
    local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    return local @ rotation_z(yaw)[:2, :2].T + np.asarray(center)


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
