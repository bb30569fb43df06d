"""The semantic-map format (read/write, clear errors) and box overlap geometry."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ravh_sim.errors import FileFieldError, UserError
from ravh_sim.eval.semantic_map import (
    FORMAT,
    LabelledBox,
    SemanticMap,
    box_of_points,
    convex_overlap_area,
    intersection_volume,
    iou,
    read_map,
    write_map,
)


def test_round_trip(tmp_path):
    m = SemanticMap(20, [LabelledBox("Chair", (1.0, 2.0, 0.5), (0.5, 0.4, 1.0), 0.3, 0.8, (1, 4)),
                         LabelledBox("Table", (0.0, 0.0, 0.4), (1.2, 0.8, 0.8))])
    write_map(m, tmp_path / "m.json")
    back = read_map(tmp_path / "m.json")
    assert back.house == 20 and back.boxes == m.boxes


@pytest.mark.parametrize("box, field", [
    ({"center": [0, 0, 0], "size": [1, 1, 1]}, "boxes[0].type"),
    ({"type": "Chair", "center": [0, 0], "size": [1, 1, 1]}, "boxes[0].center"),
    ({"type": "Chair", "center": [0, 0, 0], "size": [1, 0, 1]}, "boxes[0].size"),
    ({"type": "Chair", "center": [0, 0, 0], "size": [1, 1, 1], "yaw": "x"}, "boxes[0].yaw"),
    ({"type": "Chair", "center": [0, 0, 0], "size": [1, 1, 1], "captures": [1.5]}, "boxes[0].captures"),
])
def test_bad_fields_are_named(tmp_path, box, field):
    path = tmp_path / "m.json"
    path.write_text(json.dumps({"format": FORMAT, "house": 1, "boxes": [box]}))
    with pytest.raises(FileFieldError) as e:
        read_map(path)
    assert e.value.field == field and str(path) in str(e.value)


def test_missing_or_foreign_file(tmp_path):
    with pytest.raises(UserError, match="no such"):
        read_map(tmp_path / "none.json")
    (tmp_path / "x.json").write_text('{"format": "other"}')
    with pytest.raises(FileFieldError, match="format"):
        read_map(tmp_path / "x.json")


def test_overlap_of_rotated_squares():
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)
    diamond = square @ np.array([[math.cos(math.pi / 4), math.sin(math.pi / 4)],
                                 [-math.sin(math.pi / 4), math.cos(math.pi / 4)]])
    # a unit-half-side square and the same square turned 45 degrees share an octagon: 8 (sqrt 2 - 1)
    assert convex_overlap_area(square, diamond) == pytest.approx(8 * (math.sqrt(2) - 1))
    assert convex_overlap_area(square, square + [3, 0]) == 0.0
    assert convex_overlap_area(square, square + [1, 1]) == pytest.approx(1.0)


def test_iou_and_intersection():
    a = LabelledBox("Chair", (0, 0, 0.5), (1, 1, 1))
    assert iou(a, a) == pytest.approx(1.0)
    half = LabelledBox("Chair", (0.5, 0, 0.5), (1, 1, 1))
    assert intersection_volume(a, half) == pytest.approx(0.5)
    assert iou(a, half) == pytest.approx(0.5 / 1.5)
    above = LabelledBox("Chair", (0, 0, 2.0), (1, 1, 1))
    assert intersection_volume(a, above) == 0.0
    turned = LabelledBox("Chair", (0, 0, 0.5), (1, 1, 1), math.pi / 2)
    assert iou(a, turned) == pytest.approx(1.0)


def test_box_of_points_and_contains():
    rng = np.random.default_rng(1)
    truth = LabelledBox("Table", (2.0, -1.0, 0.4), (1.2, 0.6, 0.8), 0.5)
    local = rng.uniform(-0.5, 0.5, (2000, 3)) * truth.size
    c, s = math.cos(truth.yaw), math.sin(truth.yaw)
    points = np.column_stack((local[:, 0] * c - local[:, 1] * s, local[:, 0] * s + local[:, 1] * c,
                              local[:, 2])) + truth.center
    assert truth.contains(points).all()
    assert not truth.contains(points + [0, 0, 1.0]).any()
    box = box_of_points("Table", points, 0.05, captures=[3, 1, 3])
    assert iou(box, truth) > 0.95 and box.captures == (1, 3)
    flat = box_of_points("Picture", np.column_stack((points[:, :2], np.ones(len(points)))), 0.05)
    assert flat.size[2] == pytest.approx(0.05)
