"""``ravh semantic-map`` and ``ravh eval semantic-map`` end to end on a recorded dataset."""
from __future__ import annotations

import json

import pytest
from evaldata import small_dataset

from ravh_sim.cli import main
from ravh_sim.eval.semantic_map import read_map


def test_oracle_map_then_evaluation(capsys, tmp_path_factory, tmp_path):
    dataset = small_dataset(tmp_path_factory)
    assert main(["semantic-map", "--dataset", str(dataset), "--mapper", "oracle", "-o", str(tmp_path / "m.json")]) == 0
    assert read_map(tmp_path / "m.json").boxes
    assert main(["semantic-map", "--dataset", str(dataset), "--mapper", "degraded", "--seed", "2",
                 "-o", str(tmp_path / "d.json")]) == 0
    capsys.readouterr()
    out = tmp_path / "report"
    assert main(["eval", "semantic-map", "--dataset", str(dataset), str(dataset),
                 "--map", str(tmp_path / "m.json"), str(tmp_path / "d.json"), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "house 20" in text and "mean of houses" in text
    doc = json.loads((out / "table3.json").read_text())
    oracle, degraded = doc["houses"]
    assert oracle["precision"] >= 0.95 and oracle["recall"] >= 0.9
    assert degraded["recall"] < oracle["recall"]
    assert (out / "m_house20.png").exists() and (out / "d_house20.png").exists() and (out / "table3.txt").exists()


@pytest.mark.parametrize("argv, needle", [
    (["eval", "semantic-map", "--dataset", "a", "b", "--map", "m.json"], "one --map per --dataset"),
    (["eval", "semantic-map", "--dataset", "a", "--map", "m.json", "--iou", "1.5"], "--iou"),
    (["eval", "semantic-map", "--dataset", "nowhere", "--map", "m.json"], "not a ravh_sim dataset"),
    (["semantic-map", "--dataset", "nowhere", "-o", "m.json"], "not a ravh_sim dataset"),
])
def test_user_errors(capsys, tmp_path, monkeypatch, argv, needle):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    assert needle in capsys.readouterr().err
