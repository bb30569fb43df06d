"""The house files: complete, consistent with the upstream source, and validated with clear errors."""
from __future__ import annotations

import json
from collections import Counter

import pytest
from conftest import UPSTREAM

from ravh_sim.errors import FileFieldError, UnknownNameError
from ravh_sim.paths import HOUSES_DIR
from ravh_sim.world.house import HOUSE_FORMAT, house_from_dict, load_house
from ravh_sim.world.importer import convert_house, dump_house, import_houses

NOT_IN_FLOOR = {"Door", "Wall"}            # doors and windows sit inside the walls


def test_thirty_houses_with_source_totals(houses):
    assert sorted(houses) == list(range(1, 31))
    assert sum(len(h.rooms) for h in houses.values()) == 239
    assert sum(len(h.objects) for h in houses.values()) == 3108


@pytest.mark.skipif(not UPSTREAM.is_dir(), reason="needs ../shared/upstream-houses")
def test_counts_per_house_equal_source(houses):
    for n, house in houses.items():
        src = json.loads((UPSTREAM / f"house{n:02d}.json").read_text())
        assert len(house.rooms) == len(src["rooms"]), n
        assert len(house.objects) == len(src["objects"]), n
        assert len(house.doors) == len(src["doors"]) and len(house.windows) == len(src["windows"]), n
        assert len(house.lights) == len(src["lights"]) and len(house.walls) == len(src["walls"]), n
        assert Counter(o.type for o in house.objects) == Counter(o["tags"][0] for o in src["objects"]), n


@pytest.mark.skipif(not UPSTREAM.is_dir(), reason="needs ../shared/upstream-houses")
def test_importer_reproduces_committed_files(tmp_path):
    import_houses(UPSTREAM, tmp_path)
    for path in sorted(HOUSES_DIR.glob("house*.json")):
        assert (tmp_path / path.name).read_text() == path.read_text(), path.name


def test_objects_lie_inside_their_room(houses):
    outside = [(n, o.id) for n, h in houses.items() for o in h.objects
               if o.type not in NOT_IN_FLOOR and not h.room(o.room).contains(*o.position[:2])]
    assert outside == []


def test_doors_join_existing_rooms_and_lights_are_objects(houses):
    for house in houses.values():
        for door in house.doors:
            assert door.id in house.object_by_id and all(r in house.room_by_id for r in door.rooms)
        assert {lt.id for lt in house.lights} <= set(house.object_by_id)
        assert house.station.object_id in house.object_by_id
        assert sum(1 for d in house.doors if len(d.rooms) == 1) == 1        # one entrance door


def test_model_boxes_and_inheritance_are_consistent(houses):
    for house in houses.values():
        for obj in house.objects:
            assert obj.models and 0 <= obj.default_model < len(obj.models)
            assert all(s > 0 for m in obj.models for s in m.size)
            if obj.inherits_model_from:
                assert obj.inherits_model_from in house.object_by_id


def _house_dict(n: int = 20) -> dict:
    return json.loads((HOUSES_DIR / f"house{n:02d}.json").read_text())


@pytest.mark.parametrize("mutate, field", [
    (lambda d: d["rooms"][1].pop("floor"), "rooms[1].floor"),
    (lambda d: d["objects"][3].__setitem__("yaw", "north"), "objects[3].yaw"),
    (lambda d: d["objects"][2]["models"][0].__setitem__("size", [1, -2, 3]), "objects[2].models[0].size[1]"),
    (lambda d: d["walls"][0].__setitem__("room", "Attic_9"), "walls[0].room"),
    (lambda d: d["doors"][0].__setitem__("rooms", []), "doors[0].rooms"),
    (lambda d: d["lights"][0].__setitem__("kind", "laser"), "lights[0].kind"),
    (lambda d: d.__setitem__("format", "other"), "format"),
])
def test_malformed_house_names_file_and_field(mutate, field):
    data = _house_dict()
    mutate(data)
    with pytest.raises(FileFieldError) as err:
        house_from_dict(data, "houses/house20.json")
    assert err.value.field == field
    assert str(err.value).startswith(f"houses/house20.json: {field}: ")


def test_invalid_json_names_file_and_line(tmp_path):
    bad = tmp_path / "house99.json"
    bad.write_text('{"format": "ravh_sim/house@1",\n "house": }')
    with pytest.raises(FileFieldError) as err:
        load_house(bad)
    assert "house99.json" in str(err.value) and "line 2" in str(err.value)


def test_unknown_house_lists_valid_ones():
    with pytest.raises(UnknownNameError) as err:
        load_house(31)
    assert err.value.valid == list(range(1, 31))
    assert "unknown house 31" in str(err.value) and "30" in str(err.value)


def test_format_round_trip_is_stable():
    data = _house_dict(15)
    assert data["format"] == HOUSE_FORMAT
    assert json.loads(dump_house(data)) == data


@pytest.mark.skipif(not UPSTREAM.is_dir(), reason="needs ../shared/upstream-houses")
def test_estimated_sizes_only_where_upstream_has_no_geometry():
    src = json.loads((UPSTREAM / "house01.json").read_text())
    converted = convert_house(src, "house01.json")
    for o_src, o in zip(src["objects"], converted["objects"]):
        assert o["size_estimated"] == (o_src["size"] is None)
