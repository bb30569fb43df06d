"""Semantic-map metrics on hand-made cases, and on a recorded dataset's ground truth."""
from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from evaldata import small_dataset

from ravh_sim.dataset.api import MIN_PIXELS, Dataset
from ravh_sim.errors import UserError
from ravh_sim.eval.semantic_eval import (
    GroundTruthObject,
    draw_result,
    evaluate,
    evaluate_datasets,
    format_table,
    ground_truth,
    table,
)
from ravh_sim.eval.semantic_map import LabelledBox, SemanticMap, write_map


def _truth() -> list[GroundTruthObject]:
    """Two chairs side by side, a table, a sofa, and a cup nobody saw."""
    boxes = [LabelledBox("Chair", (0.0, 0.0, 0.5), (0.5, 0.5, 1.0)),
             LabelledBox("Chair", (0.6, 0.0, 0.5), (0.5, 0.5, 1.0)),
             LabelledBox("Table", (0.3, 1.2, 0.4), (1.2, 0.8, 0.8)),
             LabelledBox("Sofa", (3.0, 0.0, 0.4), (2.0, 0.9, 0.8), 1.0),
             LabelledBox("Cup", (5.0, 5.0, 0.8), (0.1, 0.1, 0.1))]
    seen = [500, 800, 4000, 9000, MIN_PIXELS - 1]
    return [GroundTruthObject(i + 1, f"{b.type}_{i}", b, px) for i, (b, px) in enumerate(zip(boxes, seen))]


def _perfect_map(truth) -> SemanticMap:
    return SemanticMap(20, [o.box for o in truth if o.detectable])


def test_map_equal_to_ground_truth_is_perfect():
    truth = _truth()
    r = evaluate(_perfect_map(truth), truth, 20)
    assert (r.total.precision, r.total.recall) == (1.0, 1.0)
    assert (r.total.boxes, r.total.detectable) == (4, 4)          # the unseen cup is not counted
    assert r.total.covered_by_one_box == r.total.found_by_several == 0


def test_one_wrong_label_drops_precision_and_recall_by_one():
    truth = _truth()
    boxes = _perfect_map(truth).boxes
    boxes[2] = replace(boxes[2], type="Sofa")                     # the table called a sofa
    r = evaluate(SemanticMap(20, boxes), truth, 20)
    assert r.total.precision == pytest.approx(3 / 4) and r.total.recall == pytest.approx(3 / 4)
    assert (r.by_type["Sofa"].boxes, r.by_type["Sofa"].correct) == (2, 1)
    assert (r.by_type["Table"].detectable, r.by_type["Table"].found, r.by_type["Table"].recall) == (1, 0, 0.0)
    assert r.by_type["Chair"].precision == r.by_type["Chair"].recall == 1.0
    assert r.box_correct == [True, True, False, True]


def test_box_over_two_chairs_and_two_boxes_on_one_sofa():
    truth = _truth()
    both_chairs = LabelledBox("Chair", (0.3, 0.0, 0.5), (1.2, 0.6, 1.0))
    sofa_left = LabelledBox("Sofa", (2.5, 0.0, 0.4), (0.9, 0.8, 0.7), 1.0)
    sofa_right = LabelledBox("Sofa", (3.5, 0.0, 0.4), (0.9, 0.8, 0.7), 1.0)
    r = evaluate(SemanticMap(20, [both_chairs, truth[2].box, sofa_left, sofa_right]), truth, 20)
    assert r.total.precision == 1.0 and r.total.recall == 1.0
    assert r.by_type["Chair"].covered_by_one_box == 2
    assert r.by_type["Sofa"].found_by_several == 1


def test_threshold_and_misplaced_box():
    truth = _truth()
    shifted = replace(truth[2].box, center=(0.3 + 0.9, 1.2, 0.4))            # 0.3 m of 1.2 still overlap
    assert evaluate(SemanticMap(20, [shifted]), truth, 20).total.correct == 0
    assert evaluate(SemanticMap(20, [shifted]), truth, 20, threshold=0.2).total.correct == 1
    far = replace(truth[2].box, center=(9.0, 9.0, 0.4))
    r = evaluate(SemanticMap(20, [far]), truth, 20, threshold=0.01)
    assert (r.total.correct, r.total.found) == (0, 0)


def test_map_of_another_house_is_refused():
    with pytest.raises(UserError, match="house 3"):
        evaluate(SemanticMap(3, []), _truth(), 20)


def test_table_averages_houses():
    truth = _truth()
    perfect = evaluate(_perfect_map(truth), truth, 20)
    half = evaluate(SemanticMap(21, [truth[0].box, replace(truth[2].box, type="Cup")]), truth, 21)
    doc = table([perfect, half])
    assert doc["mean"]["precision"] == pytest.approx((1.0 + 0.5) / 2)
    assert doc["mean"]["recall"] == pytest.approx((1.0 + 0.25) / 2)
    assert doc["by_type"]["Chair"]["detectable"] == 4
    assert "house 21" in format_table(doc)


def test_ground_truth_from_a_dataset(tmp_path_factory, tmp_path):
    dataset = Dataset(small_dataset(tmp_path_factory))
    truth = ground_truth(dataset)
    objects = [r for r in dataset.instances.values() if r["kind"] == "object"]
    assert len(truth) == len(objects)
    seen = {int(i) for s in dataset for i, n in enumerate(np.bincount(s.instance.ravel())) if n >= MIN_PIXELS}
    assert {o.id for o in truth if o.detectable} == {r["id"] for r in objects} & seen
    gt_map = SemanticMap(20, [o.box for o in truth if o.detectable])
    write_map(gt_map, tmp_path / "gt.json")
    doc = evaluate_datasets([(dataset.dir, tmp_path / "gt.json")], picture_dir=tmp_path)
    assert doc["houses"][0]["precision"] == doc["houses"][0]["recall"] == 1.0
    assert (tmp_path / "gt_house20.png").stat().st_size > 10_000
    result = evaluate(gt_map, truth, 20)
    assert draw_result(dataset, gt_map, result, truth).ndim == 3
    json.dumps(doc)
