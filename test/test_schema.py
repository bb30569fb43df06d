"""Every bad data file gets one line naming the file and the field (issue 13, item 8).

One table per file kind (settings, robot profiles, houses): each row breaks one field of a valid
file and says which field the error must name. The schemas are pydantic models (ravh_sim.schema).
"""
from __future__ import annotations

import copy
import dataclasses
import json
import math

import pytest
import yaml

from ravh_sim.errors import FileFieldError, UserError
from ravh_sim.paths import HOUSES_DIR, ROBOTS_DIR
from ravh_sim.robot.profile import load_profile
from ravh_sim.schema import SHOWN_INPUT, field_path
from ravh_sim.sensors.camera import CameraEffects, CameraOptions
from ravh_sim.world.house import load_house
from ravh_sim.world.settings import SEED_MAX, load_settings, resolve

NOT_UTF8 = b"seed: \xff\xfe\n"
# a "billion laughs": nine levels of ten aliases each, 4 KB that a YAML loader would expand to 10^9 nodes
LAUGHS = 'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n' + "".join(
    f"{b}: &{b} [{', '.join(['*' + a] * 10)}]\n" for a, b in zip("abcdefgh", "bcdefghi"))


def _one_line(err: Exception, path) -> str:
    text = str(err)
    assert "\n" not in text and text.startswith(str(path)), text
    return text


# ------------------------------------------------------------------ settings

@pytest.mark.parametrize("text, field", [
    ('seed: "abc"\n', "seed"),
    ("seed: [1]\n", "seed"),
    ("seed: 1.5\n", "seed"),
    ("seed: true\n", "seed"),
    ("seed: -5\n", "seed"),
    (f"seed: {SEED_MAX + 1}\n", "seed"),
    ("lights: 5\n", "lights"),
    ("doors: 5\n", "doors"),
    ("paint: 5\n", "paint"),
    ("models: 5\n", "models"),
    ("lights: {ceiling: dim}\n", "lights.ceiling"),
    ("models: {inherit: 'yes'}\n", "models.inherit"),
    ("paint: {rooms: {Bedroom_1: {roof: brick}}}\n", "paint.rooms.Bedroom_1.roof"),
    ("paint: {rooms: {Bedroom_1: {walls: plaid}}}\n", "paint.rooms.Bedroom_1.walls"),
    ("agents: [{start: [1, nan, 0]}]\n", "agents[0].start"),
    ("agents: 3\n", "agents"),
    ("lihgts: {}\n", "lihgts"),
    (LAUGHS + "seed: *i\n", "line 2 column 8"),             # billion laughs: refused at the first alias
    (LAUGHS + "agents: [{start: *i}]\n", "line 2 column 8"),
    (LAUGHS + "lights: {set: *i}\n", "line 2 column 8"),
    ("agents: [" + "{}, " * 33 + "]\n", "agents"),
    ("seed: 1\n" + "#" * (1 << 20) + "\n", "(file)"),                   # over 1 MiB
])
def test_bad_settings_file_fields(tmp_path, text, field):
    path = tmp_path / "s.yaml"
    path.write_text(text)
    with pytest.raises(FileFieldError) as err:
        load_settings(path)
    assert err.value.field == field
    _one_line(err.value, path)


@pytest.mark.parametrize("text, field", [
    ("models: {all: 99}\n", "models.all"),                    # no object has 99 models (used to wrap)
    ("agents: [{start: [1000, 1000, 0]}]\n", "agents[0].start"),
    ("agents: [{name: a}, {name: b}]\n", "agents[1].start"),  # both on the station
    ("agents: [{name: robot}, {name: ravh, start: [-1.5, 1.5, 0]}]\n", "agents[1].name"),   # ravh/... is the sim's
])
def test_settings_that_need_the_house(houses, tmp_path, text, field):
    path = tmp_path / "s.yaml"
    path.write_text(text)
    with pytest.raises(FileFieldError) as err:
        resolve(load_settings(path), houses[15], None, str(path))
    assert err.value.field == field
    _one_line(err.value, path)


def test_outside_start_names_the_nearest_room(houses, tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text("agents: [{start: [1000, 1000, 0]}]\n")
    with pytest.raises(FileFieldError, match="nearest room: "):
        resolve(load_settings(path), houses[15], None, str(path))


def test_non_utf8_settings(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_bytes(NOT_UTF8)
    with pytest.raises(FileFieldError, match="not UTF-8"):
        load_settings(path)


@pytest.mark.parametrize("seed", [-5, 1.5, True, SEED_MAX + 1, 10**30])
def test_bad_seed_from_a_flag_is_refused(houses, seed):
    with pytest.raises(UserError, match=f"0..{SEED_MAX}"):
        resolve(load_settings(), houses[15], seed)


# ------------------------------------------------------------------ robot profiles

def _set(d: dict, dotted: str, value) -> None:
    *parents, last = dotted.split(".")
    for key in parents:
        d = d[key]
    d[last] = value


@pytest.mark.parametrize("key, value, field", [
    ("camera.near", 50.0, "camera"),                          # near > far
    ("laser.range_min", 40.0, "laser"),                       # range_min > range_max
    ("camera.effects.jpeg_quality", 500, "camera.effects.jpeg_quality"),
    ("camera.effects.pixel_noise", -3, "camera.effects.pixel_noise"),
    ("footprint_radius", 1e6, "footprint_radius"),
    ("laser.fov", 720, "laser.fov"),
    ("laser.resolution", 1e-7, "laser.resolution"),
    ("camera.width", 0.5, "camera.width"),
    ("camera.width", 0, "camera.width"),
    ("camera.rate", float("nan"), "camera.rate"),
    ("odometry.rate", 0, "odometry.rate"),
    ("camera.effects.jpeg_roundtrip", "yes", "camera.effects.jpeg_roundtrip"),
    ("mass", "heavy", "mass"),
    ("camera.effects.blurr", True, "camera.effects.blurr"),
    ("wheels", 4, "wheels"),
    ("laser", None, "laser"),
    ("laser.resolution", 0.01, "laser"),                      # 36,000 rays: over pybullet's batch of 16,384
    ("camera.near", 1e-300, "camera.near"),                   # a singular projection
])
def test_bad_profile_fields(tmp_path, key, value, field):
    data = yaml.safe_load((ROBOTS_DIR / "giraff.yaml").read_text())
    _set(data, key, value)
    path = tmp_path / "bot.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(FileFieldError) as err:
        load_profile(path)
    assert err.value.field == field
    _one_line(err.value, path)


def test_a_profile_with_aliases_is_refused_at_the_alias(tmp_path):
    path = tmp_path / "bot.yaml"
    path.write_text(LAUGHS + (ROBOTS_DIR / "giraff.yaml").read_text().replace("name: giraff", "name: *i"))
    with pytest.raises(FileFieldError, match="aliases") as err:
        load_profile(path)
    assert err.value.field.startswith("line ")
    _one_line(err.value, path)


def test_non_utf8_profile(tmp_path):
    path = tmp_path / "bot.yaml"
    path.write_bytes(NOT_UTF8)
    with pytest.raises(FileFieldError, match="not UTF-8"):
        load_profile(path)


def test_profile_effects_schema_covers_camera_options():
    assert set(CameraEffects.model_fields) == {f.name for f in dataclasses.fields(CameraOptions)}


# ------------------------------------------------------------------ houses

HOUSE20 = json.loads((HOUSES_DIR / "house20.json").read_text())


def _circle(count: int) -> list[list[float]]:
    """A simple polygon of ``count`` vertices around the middle of house 20."""
    angles = (2 * math.pi * k / count for k in range(count))
    return [[-2.0 + 1.5 * math.cos(t), 1.0 + 1.5 * math.sin(t)] for t in angles]


def _copies(obj: dict, count: int) -> list[dict]:
    return [{**obj, "id": f"{obj['id']}_{k}"} for k in range(count)]


@pytest.mark.parametrize("mutate, field", [
    (lambda d: d["rooms"][0].__setitem__("floor", [[0, 0], [2, 2], [2, 0], [0, 2]]), "rooms[0].floor"),
    (lambda d: d["rooms"][0].__setitem__("floor", [[0, 0], [1, 1], [2, 2]]), "rooms[0].floor"),
    (lambda d: d["walls"][0].__setitem__("b", d["walls"][0]["a"]), "walls[0]"),
    (lambda d: d["rooms"][1].__setitem__("floor_z", 5.0), "rooms[1]"),
    (lambda d: d["walls"][2].update(z0=3.0, z1=0.0), "walls[2]"),
    (lambda d: d["objects"][4]["models"][0].__setitem__("size", [1e30, 1, 1]), "objects[4].models[0].size[0]"),
    (lambda d: d["objects"][4]["models"][0].__setitem__("position", [1e12, 0, 0]),
     "objects[4].models[0].position[0]"),
    (lambda d: d["doors"][0].__setitem__("width", 1e9), "doors[0].width"),
    (lambda d: d["lights"][0].__setitem__("color", [-5, 1e9, 0]), "lights[0].color[0]"),
    (lambda d: d["station"].__setitem__("position", [40.0, 40.0, 0.0]), "station.position"),
    (lambda d: d["doors"][1].__setitem__("colour", "red"), "doors[1].colour"),
    (lambda d: d.__setitem__("house", 21), "house"),                      # the file is house20.json
    (lambda d: d.__setitem__("house", "20"), "house"),
    (lambda d: d["objects"][0].__setitem__("default_open", 1), "objects[0].default_open"),
    (lambda d: d["rooms"][0].__setitem__("floor", _circle(10_000)), "rooms[0].floor"),
    (lambda d: d.__setitem__("objects", _copies(d["objects"][4], 80_000)), "(file)"),          # 30 MB
    (lambda d: d.__setitem__("objects", _copies(d["objects"][4], 2_001)), "objects"),
    (lambda d: d["lights"][1].__setitem__("id", d["lights"][0]["id"]), "lights[1].id"),
    (lambda d: d["doors"][1].__setitem__("id", d["doors"][0]["id"]), "doors[1].id"),
    (lambda d: d["windows"][1].__setitem__("id", d["windows"][0]["id"]), "windows[1].id"),
    (lambda d: d["objects"][4]["models"][0].__setitem__("position", [400.0, 0.0, 0.5]), "objects[4].models[0]"),
    (lambda d: d["doors"][0].__setitem__("position", [-300.0, 0.0, 1.0]), "doors[0].position"),
    (lambda d: d["lights"][0].__setitem__("position", [0.0, 500.0, 2.5]), "lights[0].position"),
    (lambda d: d["objects"][4]["models"][0].__setitem__("size", [99.0, 99.0, 1.0]), "objects[4].models[0]"),
    (lambda d: d["rooms"][0].update(floor_z=-999.0, ceiling_z=999.0), "rooms[0]"),                 # 2 km tall
    (lambda d: d.__setitem__("walls", []), "walls"),
    (lambda d: d["objects"][4].__setitem__("id", "Bed\x00"), "objects[4].id"),
    (lambda d: d["rooms"][0].__setitem__("name", "Kitchen\nroom"), "rooms[0].name"),
    (lambda d: d["lights"][0].__setitem__("id", "\x1b[31mLight"), "lights[0].id"),
    (lambda d: d["rooms"][1].__setitem__("floor", d["rooms"][0]["floor"][::-1]), "rooms[1].floor"),
])
def test_bad_house_fields(tmp_path, mutate, field):
    data = copy.deepcopy(HOUSE20)
    mutate(data)
    path = tmp_path / "house20.json"
    path.write_text(json.dumps(data))
    with pytest.raises(FileFieldError) as err:
        load_house(path)
    assert err.value.field == field
    _one_line(err.value, path)


@pytest.mark.parametrize("content, match", [
    (b'{"house": "\xff"}', "not UTF-8"),
    (b"[" * 100_000 + b"]" * 100_000, "nested too deeply"),
])
def test_unreadable_house_files(tmp_path, content, match):
    path = tmp_path / "house20.json"
    path.write_bytes(content)
    with pytest.raises(FileFieldError, match=match):
        load_house(path)


def test_errors_do_not_echo_huge_values(tmp_path):
    data = copy.deepcopy(HOUSE20)
    data["rooms"][0]["floor_z"] = "x" * 1_000_000
    path = tmp_path / "house20.json"
    path.write_text(json.dumps(data))
    with pytest.raises(FileFieldError) as err:
        load_house(path)
    assert len(str(err.value)) < len(str(path)) + 200 + SHOWN_INPUT


def test_field_paths_read_like_the_files():
    assert field_path(("agents", 0, "start")) == "agents[0].start"
    assert field_path(("rooms", 2, "floor", 1, 0)) == "rooms[2].floor[1][0]"
    assert field_path(()) == "(top level)"


@pytest.mark.parametrize("number", range(1, 31))
def test_every_shipped_house_passes_the_schema(number):
    assert load_house(number).number == number
