"""Whole-image descriptors: the baseline's invariances and the plug-in interface."""
from __future__ import annotations

import numpy as np
import pytest
from evaldata import small_dataset

from ravh_sim.errors import UserError
from ravh_sim.eval.descriptors import BASELINE, CELLS, ORIENTATIONS, describe, gradient_grid, load_descriptor


def _scene(seed: int) -> np.ndarray:
    """A synthetic room-like picture: random rectangles of random colours."""
    rng = np.random.default_rng(seed)
    img = np.full((480, 640, 3), 120, np.uint8)
    for _ in range(12):
        x0, y0 = rng.integers(0, 560), rng.integers(0, 400)
        img[y0:y0 + rng.integers(20, 200), x0:x0 + rng.integers(20, 200)] = rng.integers(0, 255, 3)
    return img


def test_baseline_shape_and_determinism():
    v = gradient_grid(_scene(1))
    assert v.shape == (CELLS[0] * CELLS[1] * ORIENTATIONS,)
    assert np.array_equal(v, gradient_grid(_scene(1)))


def test_baseline_ignores_brightness_but_tells_places_apart():
    day = _scene(1)
    dusk = (day.astype(np.float32) * 0.45).astype(np.uint8)
    other = _scene(2)
    d = describe([day, dusk, other], gradient_grid)
    assert d[0] @ d[1] > 0.97
    assert d[0] @ d[2] < d[0] @ d[1] - 0.2


def test_plug_in_by_name_and_callable():
    assert load_descriptor(None) == (BASELINE, gradient_grid)
    name, function = load_descriptor("numpy:ravel")
    assert name == "numpy:ravel" and function(np.zeros((2, 2, 3))).shape == (12,)
    d = describe([_scene(1), _scene(2)], lambda im: im.mean(axis=(0, 1)))
    assert d.shape == (2, 3) and np.allclose(np.linalg.norm(d, axis=1), 1.0)


def test_built_in_descriptors_by_name():
    assert load_descriptor("gradient_grid") == (BASELINE, gradient_grid)
    name, blind = load_descriptor("constant")
    assert name == "constant"
    d = describe([_scene(1), _scene(2)], blind)                 # sees nothing: every image alike
    assert np.array_equal(d[0], d[1])


@pytest.mark.parametrize("spec, needle", [("nothing", "module:function"), ("no_such_module_x:f", "cannot load"),
                                          ("numpy:no_such_function_x", "cannot load"), ("numpy:pi", "not callable")])
def test_bad_plug_ins(spec, needle):
    with pytest.raises(UserError, match=needle):
        load_descriptor(spec)


def test_inconsistent_or_non_finite_vectors_are_refused():
    sizes = iter([3, 4])
    with pytest.raises(UserError, match="returned 4 values"):
        describe([_scene(1), _scene(2)], lambda im: np.ones(next(sizes)))
    with pytest.raises(UserError, match="non-finite"):
        describe([_scene(1)], lambda im: np.array([1.0, np.nan]))


def test_the_shipped_cnn_reproduces_the_pytorch_network_it_was_exported_from():
    from ravh_sim.eval.cnn_descriptor import REFERENCE, efficientnet_lite0
    check = np.load(REFERENCE)                  # written by tools/export_cnn_onnx.py with torch's own pooling
    assert np.abs(efficientnet_lite0(check["image"]) - check["descriptor"]).max() < 1e-5


def test_the_cnn_descriptor_finds_each_view_again_in_dimmer_light(tmp_path_factory):
    from ravh_sim.dataset.api import Dataset
    from ravh_sim.eval.cnn_descriptor import GRID, efficientnet_lite0
    views = [s.rgb for s in Dataset(small_dataset(tmp_path_factory))]      # 2 spots x 6 headings, house 20
    v = efficientnet_lite0(views[0])
    assert v.shape == (GRID * GRID * 1280,) and np.array_equal(v, efficientnet_lite0(views[0]))
    dim = [(im.astype(np.float32) * 0.5).astype(np.uint8) for im in views]
    similarity = describe(dim, efficientnet_lite0) @ describe(views, efficientnet_lite0).T
    assert np.array_equal(np.argmax(similarity, axis=1), np.arange(len(views)))   # each view is itself
