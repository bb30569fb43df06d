"""Detections -> semantic map: back-projection against the footprint, and the fusion rules."""
from __future__ import annotations

import numpy as np
import pytest
from evaldata import small_dataset

from ravh_sim.dataset.api import Dataset
from ravh_sim.eval.fusion import CameraModel, Detection, MapFuser, build_map
from ravh_sim.eval.mappers import visible_objects
from ravh_sim.eval.semantic_eval import ground_truth


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return Dataset(small_dataset(tmp_path_factory))


def test_mask_pixels_land_in_their_objects_box(dataset):
    """Back-projected pixels of an object fall inside its footprint box (an independent geometry)."""
    camera = CameraModel(dataset)
    truth = {o.id: o.box.grown(0.03) for o in ground_truth(dataset)}
    checked = 0
    for sample in dataset:
        for i in visible_objects(dataset, sample):
            points = camera.points(sample, sample.instance == i)
            if len(points) >= 200:
                assert truth[i].contains(points).mean() > 0.97, dataset.instances[i]["name"]
                checked += 1
    assert checked >= 10


def _cube(center, side=0.4, n=300, seed=0):
    rng = np.random.default_rng(seed)
    return np.asarray(center) + rng.uniform(-side / 2, side / 2, (n, 3))


def test_partial_views_fuse_and_neighbours_stay_apart(dataset):
    fuser = MapFuser(dataset)
    chair_a, chair_b = _cube((0, 0, 0.5)), _cube((0.6, 0, 0.5), seed=1)
    fuser.add_points("Chair", chair_a[chair_a[:, 0] < -0.1], 0.9, 1)       # a partial view of chair a
    fuser.add_points("Chair", chair_a, 0.7, 2)                             # then all of it
    fuser.add_points("Chair", chair_b, 0.8, 2)                             # its neighbour, 0.2 m away
    fuser.add_points("Table", chair_a, 0.5, 3)                             # other type: never fused
    boxes = fuser.semantic_map().boxes
    assert sorted(b.type for b in boxes) == ["Chair", "Chair", "Table"]
    first = next(b for b in boxes if b.type == "Chair" and b.center[0] < 0.3)
    assert first.captures == (1, 2) and first.score == pytest.approx(0.8)
    assert first.size[0] == pytest.approx(0.4, abs=0.03)


def test_a_bridging_view_joins_two_fragments(dataset):
    fuser = MapFuser(dataset)
    sofa = _cube((0, 0, 0.4), side=1.0, n=3000)
    fuser.add_points("Sofa", sofa[sofa[:, 0] < -0.3], 1.0, 0)
    fuser.add_points("Sofa", sofa[sofa[:, 0] > 0.3], 1.0, 1)
    assert len(fuser.semantic_map().boxes) == 2
    fuser.add_points("Sofa", sofa, 1.0, 2)
    (box,) = fuser.semantic_map().boxes
    assert box.captures == (0, 1, 2)


def test_build_map_drops_tiny_detections(dataset):
    sample = dataset[0]
    tiny = np.zeros(sample.instance.shape, bool)
    tiny[100:103, 100:103] = True                                          # 9 px: below MIN_POINTS
    semantic_map = build_map(dataset, lambda s: [Detection("Chair", tiny)] if s.index == 0 else [])
    assert semantic_map.boxes == [] and semantic_map.house == 20
