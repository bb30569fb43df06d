"""Environment Manager: settings resolution, determinism, footprint and ground-truth queries."""
from __future__ import annotations

import json

import pytest
from conftest import resolved

from ravh_msgs_py.appearance import SUN_PRESETS
from ravh_sim.errors import FileFieldError
from ravh_sim.world.footprint import (
    build_instances,
    dump_footprint,
    load_footprint,
    make_footprint,
    mask_color,
    write_footprint,
)
from ravh_sim.world.ground_truth import GroundTruth
from ravh_sim.world.settings import load_settings, resolve
from ravh_sim.world.solids import model_count
from ravh_sim.world.state import WorldState


def _settings(tmp_path, text: str) -> dict:
    path = tmp_path / "s.yaml"
    path.write_text(text)
    return load_settings(path)


def test_same_seed_same_footprint_bytes(houses, tmp_path):
    settings = _settings(tmp_path, "models: {all: random}\npaint: {walls: random, floors: random}\n"
                                   "doors: {all: random}\nlights: {ceiling: random, lamps: random}\n")
    a = dump_footprint(make_footprint(houses[15], resolve(settings, houses[15], 7)))
    b = dump_footprint(make_footprint(houses[15], resolve(settings, houses[15], 7)))
    c = dump_footprint(make_footprint(houses[15], resolve(settings, houses[15], 8)))
    assert a == b
    assert a != c
    models_7 = resolve(settings, houses[15], 7).models
    models_8 = resolve(settings, houses[15], 8).models
    assert sum(models_7[k] != models_8[k] for k in models_7) > 10


def test_random_choice_per_item_is_independent_of_other_overrides(houses, tmp_path):
    base = _settings(tmp_path, "models: {all: random}\n")
    pinned = _settings(tmp_path, "models: {all: random, set: {Bed_0: 1}}\n")
    a, b = resolve(base, houses[15], 3).models, resolve(pinned, houses[15], 3).models
    assert b["Bed_0"] == 1
    assert {k: v for k, v in a.items() if k != "Bed_0"} == {k: v for k, v in b.items() if k != "Bed_0"}


def test_inherited_models_follow_their_source(houses, tmp_path):
    settings = _settings(tmp_path, "models: {all: random}\n")
    house = next(h for h in houses.values() if sum(o.inherits_model_from is not None for o in h.objects) > 3)
    models = resolve(settings, house, 11).models
    for obj in house.objects:
        if obj.inherits_model_from and not house.object(obj.inherits_model_from).inherits_model_from:
            # the same model, wrapped round when the source's type has more models than this one
            assert models[obj.id] == models[obj.inherits_model_from] % model_count(obj)


def test_footprint_round_trip_rebuilds_same_settings(houses, tmp_path):
    settings = _settings(tmp_path, "models: {all: random}\ndoors: {all: random}\n")
    fp = make_footprint(houses[20], resolve(settings, houses[20], 5))
    write_footprint(fp, tmp_path / "fp.json")
    number, again = load_footprint(tmp_path / "fp.json")
    assert number == 20
    assert dump_footprint(make_footprint(houses[number], again)) == dump_footprint(fp)


def test_footprint_lists_every_object_with_unique_ids_and_colours(houses):
    fp = make_footprint(houses[23], resolved(houses[23]))
    rows = fp["instances"]
    names = {r["name"] for r in rows}
    assert {o.id for o in houses[23].objects} <= names
    assert len({r["id"] for r in rows}) == len(rows)
    assert len({tuple(r["mask_color"]) for r in rows}) == len(rows)
    for r in rows:
        assert {"room", "room_type", "type", "position", "orientation", "model"} <= set(r)


def test_mask_colours_are_unique_and_never_black():
    colours = [mask_color(i) for i in range(1, 5000)]
    assert len(set(colours)) == len(colours) and (0, 0, 0) not in colours


def test_presets_and_switches(houses, tmp_path):
    settings = _settings(tmp_path, "lights: {sun_angle: sunset, ceiling: off, lamps: on}\n"
                                   "doors: {all: closed}\n")
    r = resolve(settings, houses[15], 0)
    assert r.sun_angle == SUN_PRESETS["sunset"]
    assert all(r.lights[lt.id] == (lt.kind != "ceiling") for lt in houses[15].lights)
    assert not any(r.doors.values())


@pytest.mark.parametrize("text, field", [
    ("lights: {sun_angle: noon}\n", "lights.sun_angle"),
    ("doors: {set: {Door_99: open}}\n", "doors.set.Door_99"),
    ("paint: {walls: plaid}\n", "paint.walls"),
    ("models: {set: {Bed_0: 17}}\n", "models.set.Bed_0"),
    ("agents: [{profile: roomba}]\n", "agents[0].profile"),
    ("lihgts: {}\n", "lihgts"),
])
def test_bad_settings_name_file_and_field(houses, tmp_path, text, field):
    with pytest.raises(FileFieldError) as err:
        resolve(_settings(tmp_path, text), houses[15], 0, source=str(tmp_path / "s.yaml"))
    assert err.value.field == field and "s.yaml" in str(err.value)


def test_unknown_door_error_lists_valid_doors(houses, tmp_path):
    with pytest.raises(FileFieldError) as err:
        resolve(_settings(tmp_path, "doors: {set: {Door_99: open}}\n"), houses[15], 0)
    assert "Door_0" in str(err.value)


# ------------------------------------------------------------------ ground truth

@pytest.fixture(scope="module")
def gt15(houses):
    return GroundTruth(houses[15], WorldState(resolved(houses[15])))


def test_objects_in_room_match_house(gt15, houses):
    reply = gt15.answer('{"query": "objects_in_room", "room": "Bathroom_1"}')
    assert reply["ok"]
    own = {o["id"] for o in reply["result"] if not o.get("dressing")}       # and the dressing, marked
    assert own == {o.id for o in houses[15].objects if o.room == "Bathroom_1"}


@pytest.mark.parametrize("model", [0, 1])
def test_object_pose_matches_chosen_model_box(houses, model):
    """The reply for the model the settings chose is that model's box as house15.json writes it (read
    here with json, not through the house loader); Bed_0's two models differ in height and size."""
    from ravh_sim.paths import HOUSES_DIR
    raw = next(o for o in json.loads((HOUSES_DIR / "house15.json").read_text())["objects"] if o["id"] == "Bed_0")
    settings = resolved(houses[15])
    gt = GroundTruth(houses[15], WorldState(settings.changed(models={**settings.models, "Bed_0": model})))
    result = gt.answer({"query": "object", "id": "Bed_0"})["result"]
    assert result["model"] == model
    assert result["position"] == pytest.approx(raw["models"][model]["position"], abs=1e-4)
    assert result["size"] == pytest.approx(raw["models"][model]["size"], abs=1e-4)
    assert result["room"] == raw["room"] == "Bedroom_1"


def test_room_at_points_inside_each_room(gt15, houses):
    for obj in houses[15].objects:
        if obj.type in ("Door", "Wall"):
            continue
        reply = gt15.answer({"query": "room_at", "x": obj.position[0], "y": obj.position[1]})
        assert reply["result"]["id"] == obj.room
    assert gt15.answer({"query": "room_at", "x": 500.0, "y": 500.0})["result"] is None


def test_connectivity_joins_every_room_with_doors_open(houses):
    for n in (15, 20, 23):
        settings = resolved(houses[n])
        gt = GroundTruth(houses[n], WorldState(settings.changed(doors=dict.fromkeys(settings.doors, True))))
        comps = gt.answer({"query": "connectivity"})["result"]["components"]
        assert len(comps) == 1, (n, comps)


def test_counts_match_house(gt15, houses):
    result = gt15.answer({"query": "counts"})["result"]
    assert result["objects"] == len(houses[15].objects) and result["rooms"] == len(houses[15].rooms)
    assert sum(result["objects_by_type"].values()) == len(houses[15].objects)


@pytest.mark.parametrize("request_text, code", [
    ("not json", "bad_json"),
    ("[1, 2]", "bad_request"),
    ('{"query": "teleport"}', "unknown_query"),
    ('{"query": "object"}', "bad_request"),
    ('{"query": "object", "id": 3}', "bad_request"),
    ('{"query": "object", "id": "Unicorn_0"}', "unknown_id"),
    ('{"query": "objects_with_tag", "tag": "Unicorn"}', "unknown_id"),
    ('{"query": "room_at", "x": "a", "y": 1}', "bad_request"),
    ('{"query": "rooms", "type": "Dungeon"}', "unknown_id"),
])
def test_bad_queries_get_structured_errors(gt15, request_text, code):
    reply = gt15.answer(request_text)
    assert reply["ok"] is False and reply["error"]["code"] == code
    assert reply["error"]["message"]


def test_unknown_id_error_lists_what_exists(gt15):
    reply = gt15.answer('{"query": "object", "id": "Unicorn_0"}')
    assert "Bed_0" in reply["error"]["valid"]


def test_instances_are_in_fixed_order(houses):
    a = [(i.id, i.name) for i in build_instances(houses[15])]
    assert a == [(i.id, i.name) for i in build_instances(houses[15])]
    assert json.dumps(a)


def test_closing_every_door_splits_the_connectivity_graph(houses):
    settings = resolved(houses[15])
    gt = GroundTruth(houses[15], WorldState(settings.changed(doors=dict.fromkeys(settings.doors, False))))
    comps = gt.answer({"query": "connectivity", "open_only": True})["result"]["components"]
    assert len(comps) == len(houses[15].rooms)        # house 15 has no door-less passages


def test_archway_links_rooms_without_a_door(houses):
    from ravh_sim.world.topology import room_links
    links = room_links(houses[23])
    arch = [lk for lk in links if lk.door is None]
    assert [lk.rooms for lk in arch] == [("LivingRoom_1", "LivingRoom_2")] and arch[0].width > 1.0
    assert {lk.door for lk in links if lk.door} == {d.id for d in houses[23].doors if len(d.rooms) == 2}
