"""``ravh semantic-map`` and ``ravh eval semantic-map`` end to end on a recorded dataset."""
from __future__ import annotations

import json
import shutil

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
    assert oracle["detections"] == read_map(tmp_path / "m.json").detections > len(read_map(tmp_path / "m.json").boxes)


def _columns(line: str) -> list[str]:
    return line.split()


def test_the_paper_row_stands_beside_ours(capsys, tmp_path_factory, tmp_path):
    dataset = small_dataset(tmp_path_factory)
    main(["semantic-map", "--dataset", str(dataset), "--mapper", "oracle", "-o", str(tmp_path / "m.json")])
    capsys.readouterr()
    assert main(["eval", "semantic-map", "--dataset", str(dataset), "--map", str(tmp_path / "m.json"),
                 "--paper"]) == 0
    text = capsys.readouterr().out
    lines = text[text.index("CNN detections"):].splitlines()
    ours = read_map(tmp_path / "m.json")
    assert _columns(lines[1])[:4] == ["20", "ours", str(ours.detections), str(len(ours.boxes))]
    assert _columns(lines[2]) == ["paper", "54", "6", "7", "83.3", "43.8"]           # Table 3, house 20
    assert _columns(lines[-1]) == ["mean", "paper", "54.0", "6.0", "7.0", "83.3", "43.8"]


def test_paper_protocol_maps_each_houses_raid_with_both_mappers(capsys, tmp_path_factory, tmp_path):
    out = tmp_path / "t3"
    shutil.copytree(small_dataset(tmp_path_factory), out / "house20")     # a finished raid is reused
    assert main(["eval", "semantic-map", "--paper-protocol", "--houses", "20", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert text.count("paper") >= 4 and "oracle" in text and "degraded" in text
    oracle = json.loads((out / "table3_oracle.json").read_text())["houses"][0]
    degraded = json.loads((out / "table3_degraded.json").read_text())["houses"][0]
    assert oracle["house"] == degraded["house"] == 20 and oracle["recall"] > degraded["recall"]
    assert (out / "table3_paper.txt").read_text().strip() == text.strip()


@pytest.mark.parametrize("argv, needle", [
    (["eval", "semantic-map", "--dataset", "a", "b", "--map", "m.json"], "one --map per --dataset"),
    (["eval", "semantic-map", "--dataset", "a", "--map", "m.json", "--iou", "1.5"], "--iou"),
    (["eval", "semantic-map", "--dataset", "nowhere", "--map", "m.json"], "not a ravh_sim dataset"),
    (["semantic-map", "--dataset", "nowhere", "-o", "m.json"], "not a ravh_sim dataset"),
    (["eval", "semantic-map"], "or --paper-protocol"),
    (["eval", "semantic-map", "--paper-protocol"], "needs --out"),
    (["eval", "semantic-map", "--paper-protocol", "--out", "o", "--mappers", "cnn"], "--mappers"),
])
def test_user_errors(capsys, tmp_path, monkeypatch, argv, needle):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    assert needle in capsys.readouterr().err
