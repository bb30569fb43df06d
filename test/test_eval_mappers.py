"""The reference mappers: the oracle bounds the evaluation, each degradation moves its own number."""
from __future__ import annotations

import pytest
from evaldata import small_dataset

from ravh_sim.dataset.api import Dataset
from ravh_sim.errors import UserError
from ravh_sim.eval.mappers import Degradation, run_mapper
from ravh_sim.eval.semantic_eval import evaluate, ground_truth

NONE = Degradation(miss=0.0, confuse=0.0, merge_radius=0.0, center_sigma=0.0, size_sigma=0.0)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return Dataset(small_dataset(tmp_path_factory))


@pytest.fixture(scope="module")
def truth(dataset):
    return ground_truth(dataset)


def _score(dataset, truth, mapper="degraded", seed=0, errors=NONE):
    return evaluate(run_mapper(dataset, mapper, seed, errors), truth, 20).total


def test_oracle_is_near_perfect(dataset, truth):
    t = _score(dataset, truth, "oracle")
    assert t.precision >= 0.95 and t.recall >= 0.9, t


def test_degraded_without_errors_is_the_oracle(dataset):
    assert run_mapper(dataset, "degraded", 3, NONE).boxes == run_mapper(dataset, "oracle").boxes


def test_each_error_moves_its_number(dataset, truth):
    base = _score(dataset, truth)
    missed = _score(dataset, truth, errors=Degradation(0.5, 0.0, 0.0, 0.0, 0.0))
    assert missed.recall < base.recall and missed.precision >= 0.95
    confused = _score(dataset, truth, errors=Degradation(0.0, 0.5, 0.0, 0.0, 0.0))
    assert confused.precision < base.precision - 0.2
    merged = _score(dataset, truth, errors=Degradation(0.0, 0.0, 1.5, 0.0, 0.0))   # wide enough to join a dining set
    assert merged.boxes < base.boxes                 # fewer boxes, a larger share of what they find shares one
    assert merged.covered_by_one_box / merged.found > base.covered_by_one_box / base.found
    noisy = _score(dataset, truth, errors=Degradation(0.0, 0.0, 0.0, 0.3, 0.5))
    assert noisy.correct < base.correct


def test_seeded(dataset):
    a, b = (run_mapper(dataset, "degraded", 7) for _ in range(2))
    assert a.boxes == b.boxes
    assert run_mapper(dataset, "degraded", 8).boxes != a.boxes


def test_unknown_mapper(dataset):
    with pytest.raises(UserError, match="oracle, degraded"):
        run_mapper(dataset, "magic")
