"""Floor-outline geometry: areas, inside tests, distances, crossings and ear clipping."""
from __future__ import annotations

import numpy as np
import pytest

from ravh_sim.world.geometry import (
    box_corners,
    distance_to_polygon,
    point_in_polygon,
    points_in_polygon,
    polygon_area,
    polygon_centroid,
    self_intersection,
    triangulate,
)

L_SHAPE = ((0.0, 0.0), (4.0, 0.0), (4.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0))


def test_l_shape_measures():
    assert polygon_area(L_SHAPE) == pytest.approx(6.0)
    assert polygon_centroid(L_SHAPE) == pytest.approx((1.5, 1.0))
    assert point_in_polygon(0.5, 2.5, L_SHAPE) and not point_in_polygon(2.5, 2.5, L_SHAPE)
    xs, ys = np.array([[0.5, 2.5], [3.5, -0.5]]), np.array([[2.5, 2.5], [0.5, 0.5]])
    assert points_in_polygon(xs, ys, L_SHAPE).tolist() == [[True, False], [True, False]]
    assert distance_to_polygon(2.0, 2.0, L_SHAPE) == pytest.approx(1.0)
    assert distance_to_polygon(0.5, 0.5, L_SHAPE) == pytest.approx(0.5)


def test_self_intersection_names_the_crossing_edges():
    assert self_intersection(L_SHAPE) is None
    bow_tie = ((0.0, 0.0), (2.0, 2.0), (2.0, 0.0), (0.0, 2.0))
    assert self_intersection(bow_tie) == (0, 2)


def test_triangulation_covers_the_outline_counter_clockwise():
    triangles = triangulate(L_SHAPE[::-1])
    pts = L_SHAPE[::-1]
    areas = [polygon_area((pts[a], pts[b], pts[c])) * np.sign((pts[b][0] - pts[a][0]) * (pts[c][1] - pts[a][1])
                                                               - (pts[b][1] - pts[a][1]) * (pts[c][0] - pts[a][0]))
             for a, b, c in triangles]
    assert len(triangles) == 4 and min(areas) > 0 and sum(areas) == pytest.approx(6.0)


def test_box_corners_turn_with_yaw():
    corners = box_corners((1.0, 2.0), (2.0, 1.0), np.pi / 2)
    assert corners.tolist() == [[1.5, 1.0], [1.5, 3.0], [0.5, 3.0], [0.5, 1.0]]
