"""``ravh eval localization --quick`` end to end on house 20: recordings, table, picture, reuse, the
paper's cells beside ours."""
from __future__ import annotations

import csv
import json
import statistics
from dataclasses import replace

import numpy as np
import pytest

from ravh_sim.cli import main
from ravh_sim.dataset.api import Dataset
from ravh_sim.errors import UserError
from ravh_sim.eval.descriptors import describe, gradient_grid
from ravh_sim.eval.localization import Localizer, errors, noisy_odometry
from ravh_sim.eval.table4 import (
    FULL,
    MAPS,
    QUICK,
    ROUTES,
    RUNS,
    TOP1_DEG,
    TOP1_M,
    beside_paper,
    draw_table4,
    format_table4,
    light_switches,
    retrieval,
    run_table4,
)
from ravh_sim.paper import TABLE4, table4


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("table4") / "h20"
    assert main(["eval", "localization", "--house", "20", "--out", str(out), "--quick"]) == 0
    return out


def test_quick_table(quick_run):
    doc = json.loads((quick_run / "table4.json").read_text())
    assert [[c["route"] for c in row] for row in doc["cells"]] == [[r.label] * len(QUICK.maps) for r in QUICK.routes]
    assert [c["map"] for c in doc["cells"][0]] == [m.label for m in QUICK.maps]
    for row in doc["cells"]:
        for cell in row:
            assert len(cell["runs"]) == RUNS
            run_medians = [r["position_m"] for r in cell["runs"]]
            assert cell["position_m"] == pytest.approx(float(np.median(run_medians)), abs=1e-3)
            assert 0.0 <= cell["position_m"] < 1.5 and 0.0 <= cell["rotation_deg"] < 60.0
    for route in doc["routes"].values():
        assert route["images"] >= 10 and route["length_m"] > 2.0
    assert (quick_run / "table4.png").stat().st_size > 5_000 and (quick_run / "table4.txt").exists()


def test_the_night_recordings_were_lit_as_two_evenings(quick_run, houses):
    """The quick run's night map and night route switched the lights their draws say, and the
    worlds they were recorded in had exactly those lights on."""
    doc = json.loads((quick_run / "table4.json").read_text())
    assert doc["protocol"]["night_lights"] == "evening" and doc["house_lights"] == len(houses[20].lights)
    night_map, night_route = "maps/" + QUICK.maps[1].folder, "routes/" + QUICK.routes[1].folder
    assert set(doc["night_lights_on"]) == {night_map, night_route}
    for recording in (night_map, night_route):
        light = QUICK.maps[1] if recording.startswith("maps") else QUICK.routes[1]
        drawn = light_switches(houses[20], QUICK, light, recording, 0)
        lights = Dataset(quick_run / recording).settings.lights
        assert lights == {k: state == "on" for k, state in drawn.items()}
        assert doc["night_lights_on"][recording] == sum(lights.values())


def test_each_night_is_an_evening_of_its_own(houses):
    house = houses[15]
    day, night_map, night_route = ROUTES[0], MAPS[2], ROUTES[2]
    assert light_switches(house, QUICK, day, "routes/" + day.folder, 0) == {}
    assert light_switches(house, replace(QUICK, night_lights="all"), night_map, "maps/x", 0) == {}
    a = light_switches(house, QUICK, night_map, "maps/" + night_map.folder, 0)
    assert a == light_switches(house, QUICK, night_map, "maps/" + night_map.folder, 0)        # seeded
    assert set(a) == {lt.id for lt in house.lights}
    assert a != light_switches(house, QUICK, night_route, "routes/" + night_route.folder, 0)
    assert a != light_switches(house, QUICK, night_map, "maps/" + night_map.folder, 1)
    evenings = [light_switches(house, QUICK, night_map, f"maps/{i}", 0) for i in range(40)]
    share = np.mean([state == "on" for evening in evenings for state in evening.values()])
    assert 0.4 < share < 0.6                                             # a fair coin per light


def test_route_equal_to_a_map_trajectory_has_near_zero_error(quick_run):
    """The map's own images, in recording order, as a route under the same light."""
    dataset = Dataset(quick_run / "maps" / QUICK.maps[0].folder)
    descriptors = describe((s.rgb for s in dataset), gradient_grid)
    poses = np.array([s.pose for s in dataset])
    estimates = Localizer(descriptors, poses).localize(descriptors, noisy_odometry(poses, np.random.default_rng(0)))
    position, rotation = errors(estimates, poses)
    assert np.median(position) < 0.02 and np.median(rotation) < 1.0


def test_recordings_are_reused_and_descriptors_plug_in(quick_run, capsys):
    constant = run_table4(20, quick_run, QUICK, lambda image: np.ones(4), progress=print)
    assert "recording" not in capsys.readouterr().out
    assert constant["descriptor"] == "<lambda>"
    informed = run_table4(20, quick_run, QUICK)
    blind_error = np.mean([c["position_m"] for row in constant["cells"] for c in row])
    seen_error = np.mean([c["position_m"] for row in informed["cells"] for c in row])
    assert seen_error < blind_error
    blind_top1 = np.mean([c["top1_pct"] for row in constant["cells"] for c in row])
    seen_top1 = np.mean([c["top1_pct"] for row in informed["cells"] for c in row])
    assert seen_top1 > blind_top1 + 20


def _paper_cells() -> dict[tuple[str, str], tuple[str, str]]:
    """config/paper's Table 4 read here on its own (not through ravh_sim.paper): the cells as text."""
    with open(TABLE4, newline="") as f:
        return {(f"{r['route']} {r['route_sun_deg']}", f"{r['map']} {r['map_sun_deg']}"):
                (r["median_position_m"], r["median_rotation_deg"]) for r in csv.DictReader(f, delimiter="\t")}


def test_the_command_prints_the_papers_cells_beside_ours(quick_run, capsys):
    """The text table of a (reused) quick run: each route's row holds our cell from the run's own
    table4.json and the paper's cell as config/paper holds it, then the columns' medians and ratios
    and the top-1 retrieval; --json prints the same document."""
    assert main(["eval", "localization", "--house", "20", "--out", str(quick_run), "--quick"]) == 0
    text = capsys.readouterr().out
    doc = json.loads((quick_run / "table4.json").read_text())
    assert doc["descriptor"] == "gradient_grid" and (quick_run / "table4.txt").read_text() in text + "\n"
    paper, lines = _paper_cells(), text.splitlines()
    for row in doc["cells"]:
        [line] = [line for line in lines if line.startswith(row[0]["route"] + " ") and "/" in line]
        expected = []
        for cell in row:
            p, a = paper[cell["route"], cell["map"]]
            expected += [f"{cell['position_m']:.2f}", "/", f"{cell['rotation_deg']:.1f}",
                         f"{float(p):.2f}", "/", f"{float(a):.1f}"]
        assert line.split()[2:] == expected
    ours_medians = [statistics.median(row[j]["position_m"] for row in doc["cells"]) for j in range(len(QUICK.maps))]
    paper_medians = [statistics.median(float(paper[row[j]["route"], row[j]["map"]][0]) for row in doc["cells"])
                     for j in range(len(QUICK.maps))]

    def numbers(prefix: str, skip: int) -> list[float]:
        [line] = [line for line in lines if line.startswith(prefix)]
        return [float(w.rstrip("x")) for w in line.split()[skip:] if w != "m"]
    assert numbers("median of the column", 4) == pytest.approx(
        [v for pair in zip(ours_medians, paper_medians) for v in pair], abs=0.006)
    assert numbers("ratio to day 170 column", 5) == pytest.approx(
        [1.0, 1.0, ours_medians[1] / ours_medians[0], paper_medians[1] / paper_medians[0]], abs=0.011)
    assert numbers("ours / paper", 3) == pytest.approx([o / p for o, p in zip(ours_medians, paper_medians)],
                                                       abs=0.011)
    heading = lines.index(next(line for line in lines if line.startswith("top-1 retrieval")))
    for line, row in zip(lines[heading + 3:], doc["cells"]):
        assert line.startswith(row[0]["route"]) and line.split()[2:-2] == [w for c in row for w in
                                                                           (f"{c['top1_pct']:.1f}", "%")]
        assert all(0.0 <= c["top1_pct"] <= 100.0 and 0.0 <= c["nearest_map_image_m"] < 0.5 for c in row)
    assert main(["eval", "localization", "--house", "20", "--out", str(quick_run), "--quick", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["paper"]["cells"] == doc["paper"]["cells"] and printed["cells"] == doc["cells"]
    assert [[(c["position_m"], c["rotation_deg"]) for c in row] for row in printed["paper"]["cells"]] == [
        [tuple(float(v) for v in paper[c["route"], c["map"]]) for c in row] for row in doc["cells"]]


def _full_sized_doc(position: float = 0.5) -> dict:
    """A table4.json of the full protocol's shape, every cell ``position`` m (no recordings)."""
    return {"house": 15, "descriptor": "x", "runs": RUNS, "protocol": {"night_lights": "evening"},
            "maps": {m.label: {"images": 10} for m in FULL.maps},
            "routes": {r.label: {"images": 5, "length_m": 2.0} for r in FULL.routes},
            "cells": [[{"route": r.label, "map": m.label, "position_m": position + 0.1 * j, "rotation_deg": 9.0,
                        "top1_pct": 50.0, "nearest_map_image_m": 0.25} for j, m in enumerate(FULL.maps)]
                      for r in FULL.routes]}


def test_the_full_protocol_meets_every_paper_cell():
    """Every one of the paper's 18 cells has its place in the full protocol's table, and the columns'
    medians and the night map's ratio to the day map's are the paper's own (computed here from the TSV)."""
    paper = _paper_cells()
    doc = _full_sized_doc()
    side = beside_paper(doc, table4())
    assert {(c["route"], c["map"]) for row in side["cells"] for c in row} == set(paper)
    for j, column in enumerate(side["columns"]):
        theirs = [float(p) for (_, m), (p, _) in paper.items() if m == FULL.maps[j].label]
        assert column["paper_median_m"] == pytest.approx(statistics.median(theirs), abs=1e-3)
        assert column["paper_routes"] == len(FULL.routes) == len(theirs)
    day, night = side["columns"][0]["paper_median_m"], side["columns"][2]["paper_median_m"]
    assert side["columns"][2]["paper_over_first_map"] == round(night / day, 2)
    assert side["columns"][2]["ours_over_first_map"] == round(0.7 / 0.5, 2)
    worst = max(paper.items(), key=lambda kv: float(kv[1][0]))
    assert (side["worst"]["paper"]["route"], side["worst"]["paper"]["map"]) == worst[0]


def test_the_papers_cells_come_from_the_tsv_it_is_given(tmp_path):
    """Another TSV (a cell changed, one missing) changes the printed table: nothing is a copy in code."""
    rows = TABLE4.read_text().splitlines()
    changed = [rows[0], rows[1].rsplit("\t", 2)[0] + "\t9.87\t65.43"] + [
        r for r in rows[2:] if not r.startswith("day\t25\tnight")]
    (tmp_path / "t4.tsv").write_text("\n".join(changed) + "\n")
    doc = _full_sized_doc()
    doc["paper"] = beside_paper(doc, table4(tmp_path / "t4.tsv"), tmp_path / "t4.tsv")
    text = format_table4(doc)
    assert "9.87 / 65.4" in text and "t4.tsv" in text
    day25 = next(line for line in text.splitlines() if line.startswith("day 25 "))
    assert day25.split()[-1] == "-"                                   # the paper's cell it lacks
    assert "night 200: 5 of 6 routes" in text
    assert "paper day 90 on day 170 (9.87 m)" in text


def test_top1_retrieval_counts_the_most_similar_map_image_near_the_true_pose():
    poses = np.array([[x, y, yaw] for x in (0.0, 0.5, 3.0) for y in (0.0, 2.0) for yaw in (0.0, np.pi)])
    descriptors = np.eye(len(poses))
    assert retrieval(descriptors, poses, descriptors, poses) == (100.0, 0.0)
    # every route image most like the map image one place back in x: 0.5 m (right), 2.5 m, 3 m (wrong)
    shifted = np.roll(descriptors, 4, axis=0)
    top1, nearest = retrieval(shifted, poses, descriptors, poses)
    assert top1 == pytest.approx(100 * 4 / 12) and nearest == 0.0
    turned = poses + [0.2, 0.0, np.radians(TOP1_DEG + 1)]            # 0.2 m off, just too far turned
    assert retrieval(descriptors, turned, descriptors, poses) == (0.0, pytest.approx(0.2))
    moved = poses + [TOP1_M - 0.01, 0.0, 0.0]
    assert retrieval(descriptors, moved, descriptors, poses)[0] == 100.0


def test_a_folder_of_other_recordings_is_refused(quick_run):
    with pytest.raises(UserError, match="other settings"):
        run_table4(20, quick_run, QUICK, seed=1)


def test_heat_map_runs_from_dark_to_yellow_per_panel():
    maps, routes = ["day 170", "night 200"], ["day 90", "night 185", "sunset 175"]
    values = [[(0.3, 4.0), (1.8, 22.0)], [(2.4, 35.0), (0.5, 6.0)], [(0.9, 11.0), (1.2, 15.0)]]
    doc = {"house": 15, "descriptor": "hog", "runs": 5, "maps": dict.fromkeys(maps, {}),
           "cells": [[{"route": r, "map": m, "position_m": p, "rotation_deg": a} for m, (p, a) in zip(maps, row)]
                     for r, row in zip(routes, values)]}
    image = draw_table4(doc)
    assert image.dtype == np.uint8 and image.shape[1] > image.shape[0]
    top = (image == (36, 231, 253)).all(axis=2)          # viridis' top (BGR): the panel's largest value
    half = image.shape[1] // 2
    assert top[:, :half].sum() > 2000 and top[:, half:].sum() > 2000   # one whole cell in each panel
