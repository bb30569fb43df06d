"""``ravh eval localization --quick`` end to end on house 20: recordings, table, picture, reuse."""
from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from ravh_sim.cli import main
from ravh_sim.dataset.api import Dataset
from ravh_sim.errors import UserError
from ravh_sim.eval.descriptors import describe, gradient_grid
from ravh_sim.eval.localization import Localizer, errors, noisy_odometry
from ravh_sim.eval.table4 import MAPS, QUICK, ROUTES, RUNS, draw_table4, light_switches, run_table4


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
