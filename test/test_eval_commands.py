"""``ravh semantic-map`` and ``ravh eval semantic-map`` end to end on a recorded dataset."""
from __future__ import annotations

import json
import shutil

import pytest
from evaldata import small_dataset

from ravh_sim.cli import main
from ravh_sim.eval.semantic_map import read_map
from ravh_sim.paper import TABLE3, read_tsv


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
    paper = next(r for r in read_tsv(TABLE3) if r["house"] == "20")                 # config/paper's Table 3
    theirs = [paper[k] for k in ("cnn_detections", "detection_boxes", "detected_objects", "precision_pct",
                                 "recall_pct")]
    assert _columns(lines[2]) == ["paper"] + theirs
    mine = _columns(lines[1])[2:]
    assert _columns(_line(lines, "mean paper")) == ["mean", "paper"] + [f"{float(v):.1f}" for v in theirs]
    assert _columns(_line(lines, "mean ours")) == ["mean", "ours"] + [f"{float(v):.1f}" for v in mine]
    assert _columns(_line(lines, "ratio ours / paper"))[4:] == [
        f"{round(float(a), 1) / round(float(b), 1):.2f}x" for a, b in zip(mine, theirs)]
    assert _columns(_line(lines, "range paper")) == ["range", "paper"] + [f"{v}-{v}" for v in theirs]
    assert _columns(_line(lines, "range ours")) == ["range", "ours"] + [f"{v}-{v}" for v in mine]


def _line(lines: list[str], start: str) -> str:
    [line] = [line for line in lines if " ".join(line.split()).startswith(start)]
    return line


def test_several_houses_beside_the_paper_give_means_ratios_and_ranges():
    from ravh_sim.eval.semantic_eval import format_beside_paper
    paper = {int(r["house"]): r for r in read_tsv(TABLE3)}
    houses = [{"house": h, "detections": 100 * h, "boxes": 10 + h, "found": 8 + h, "precision": 0.5 + h / 100,
               "recall": 0.2 + h / 100} for h in (1, 2, 3)]
    lines = format_beside_paper({"houses": houses}, paper, "oracle").splitlines()
    theirs = [[float(paper[h][k]) for h in (1, 2, 3)] for k in ("cnn_detections", "detection_boxes",
                                                                 "detected_objects", "precision_pct", "recall_pct")]
    means = [round(sum(col) / 3, 1) for col in theirs]
    assert _columns(_line(lines, "mean paper"))[2:] == [f"{m:.1f}" for m in means]
    assert _columns(_line(lines, "mean oracle"))[2:] == ["200.0", "12.0", "10.0", "52.0", "22.0"]
    assert _columns(_line(lines, "ratio oracle / paper"))[4:] == [
        f"{a / b:.2f}x" for a, b in zip((200.0, 12.0, 10.0, 52.0, 22.0), means)]
    spans = [(f"{min(c):.1f}-{max(c):.1f}" if k >= 3 else f"{int(min(c))}-{int(max(c))}") for k, c in enumerate(theirs)]
    assert _columns(_line(lines, "range paper"))[2:] == spans
    assert _columns(_line(lines, "range oracle"))[2:] == ["100-300", "11-13", "9-11", "51.0-53.0", "21.0-23.0"]


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
    for mapper, doc in (("oracle", oracle), ("degraded", degraded)):
        [row] = [line.split() for line in (out / f"table3_{mapper}.txt").read_text().splitlines()
                 if line.startswith("house 20")]
        assert row[2:5] == [str(doc["boxes"]), str(doc["correct"]), f"{doc['precision']:.3f}"]


@pytest.mark.parametrize("argv, needle", [
    (["eval", "semantic-map", "--dataset", "a", "b", "--map", "m.json"], "one --map per --dataset"),
    (["eval", "semantic-map", "--dataset", "a", "--map", "m.json", "--iou", "1.5"], "--iou"),
    (["eval", "semantic-map", "--dataset", "nowhere", "--map", "m.json"], "not a ravh_sim dataset"),
    (["semantic-map", "--dataset", "nowhere", "-o", "m.json"], "not a ravh_sim dataset"),
    (["eval", "semantic-map"], "or --paper-protocol"),
    (["eval", "semantic-map", "--paper-protocol"], "needs --out"),
    (["eval", "semantic-map", "--paper-protocol", "--out", "o", "--mappers", "cnn"], "--mappers"),
    (["eval", "localization", "--out", "o", "--paper", "nowhere.tsv"], "--paper: no such file"),
    (["eval", "localization", "--out", "o", "--paper", "bad.tsv"], "not Table 4's columns"),
    (["eval", "localization", "--out", "o", "--descriptor", "nothing"], "expected gradient_grid or constant"),
    (["eval", "localization", "--out", "o", "--house", "99"], "99"),
])
def test_user_errors(capsys, tmp_path, monkeypatch, argv, needle):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bad.tsv").write_text("route\tmap\nday\tday\n")
    assert main(argv) == 2
    assert needle in capsys.readouterr().err
