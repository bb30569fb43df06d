"""The house files: complete, consistent with the upstream source, and validated with clear errors."""
from __future__ import annotations

import json
from collections import Counter

import pytest
from conftest import UPSTREAM

from ravh_sim.errors import FileFieldError, UnknownNameError
from ravh_sim.importers.houses import convert_house, dump_house, import_houses
from ravh_sim.paths import HOUSES_DIR
from ravh_sim.world.house import HOUSE_FORMAT, house_from_dict, load_house

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


def _upstream_house() -> dict:
    """A 4 m x 3 m one-room house in the upstream extraction's format (what ../shared/upstream-houses holds):
    a bed with two model variants, a ceiling light and a keyboard with no geometry, a door, a window."""
    def obj(id_, tag, position, size=None, models=(), yaw=0.0):
        return {"id": id_, "tags": [tag], "room": "Bedroom_1", "prefab": f"{tag}_prefab", "yaw": yaw, "size": size,
                "position": position, "models": list(models), "inherits_model_from": None}
    floor = [[0, 0], [4, 0], [4, 3], [0, 3]]
    return {
        "house": 7, "source": {"repo": "upstream", "commit": "abc", "prefab": "House7", "license": "MIT", "x": 1},
        "station": {"position": [1.0, 1.0, 0.0], "yaw": 1.5707963, "object_id": "Station_0"},
        "rooms": [{"id": "Bedroom_1", "type": "Bedroom", "name": "Bedroom", "floor_z": -0.03, "ceiling_z": 2.5,
                   "floor_polygon": floor, "pivot": [9, 9, 9]}],
        "walls": [{"room": "Bedroom_1", "kind": "wall", "a": a, "b": b, "thickness": 0.1, "z0": -0.03, "z1": 2.5}
                  for a, b in zip(floor, floor[1:] + floor[:1])],
        "doors": [{"id": "Door_0", "rooms": ["Bedroom_1"], "position": [2.0, 0.0, 1.0], "yaw": 0.0, "width": 0.9,
                   "height": 2.0, "thickness": 0.05, "leaf_size": [0.85, 0.04, 1.98], "default_open": True}],
        "windows": [{"id": "Window_0", "room": "Bedroom_1", "position": [4.0, 1.5, 1.4], "yaw": 1.5707963,
                     "width": 1.0, "height": 1.0, "thickness": 0.1}],
        "lights": [{"id": "Light_0", "kind": "ceiling", "room": "Bedroom_1", "position": [2.0, 1.5, 2.45],
                    "intensity": 1.0, "range": 5.0, "color_rgb": [1.0, 0.9, 0.8]}],
        "objects": [
            obj("Bed_0", "Bed", [1.0, 2.0, 0.0], [1.2, 2.0, 0.5], yaw=0.123456789, models=[
                {"default": False, "position": [1.0, 2.0, 0.25], "size": [1.2, 2.0, 0.5]},
                {"default": True, "position": [1.0, 2.0, 0.3], "size": [1.4, 2.1, 0.6]}]),
            obj("Light_0", "Light", [2.0, 1.5, 2.45]),
            obj("Keyboard_0", "Keyboard", [3.0, 1.0, 0.7]),
            obj("Station_0", "Station", [1.0, 1.0, 0.0]),
            obj("Door_0", "Door", [2.0, 0.0, 1.0], [0.9, 0.05, 2.0]),
            obj("Window_0", "Window", [4.0, 1.5, 1.4], [1.0, 0.1, 1.0]),
        ],
    }


def test_importer_converts_an_upstream_house(tmp_path):
    """The importer on a house built here (runs on a clean clone): Unity fields dropped, the default
    variant found, sizes estimated where upstream has none (a light hangs from the ceiling, a keyboard
    rests where its origin is), numbers rounded to 0.1 mm, and a file the loader accepts."""
    src, out = tmp_path / "upstream", tmp_path / "houses"
    src.mkdir()
    (src / "house07.json").write_text(json.dumps(_upstream_house()))
    assert import_houses(src, out) == [out / "house07.json"]
    text = (out / "house07.json").read_text()
    data = json.loads(text)
    assert data["format"] == HOUSE_FORMAT and "Fernández" in data["attribution"] and "x" not in data["source"]
    assert "pivot" not in data["rooms"][0] and data["rooms"][0]["floor"] == [[0, 0], [4, 0], [4, 3], [0, 3]]
    objects = {o["id"]: o for o in data["objects"]}
    bed, light, keyboard = objects["Bed_0"], objects["Light_0"], objects["Keyboard_0"]
    assert bed["default_model"] == 1 and bed["yaw"] == 0.1235 and not bed["size_estimated"]
    assert bed["models"][1] == {"position": [1.0, 2.0, 0.3], "size": [1.4, 2.1, 0.6]}
    assert light["size_estimated"] and light["models"] == [{"position": [2.0, 1.5, 2.46], "size": [0.36, 0.36, 0.08]}]
    assert keyboard["models"][0]["position"] == [3.0, 1.0, 0.715]           # 0.7 + half of 0.03
    assert data["lights"][0]["color"] == [1.0, 0.9, 0.8] and data["doors"][0]["leaf"] == [0.85, 0.04, 1.98]
    rows = [line.strip().rstrip(",") for line in text.splitlines() if line.startswith("    ")]   # one per line
    assert [json.loads(row) for row in rows] == [item for v in data.values() if isinstance(v, list) for item in v]
    house = load_house(out / "house07.json")
    assert house.number == 7 and house.object("Bed_0").size == (1.4, 2.1, 0.6)


def test_importer_names_a_missing_upstream_field(tmp_path):
    src = _upstream_house()
    del src["doors"][0]["leaf_size"]
    with pytest.raises(FileFieldError, match="leaf_size"):
        convert_house(src, "house07.json")


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
