"""The lamps' knobs: the light colour temperature (issue 22) and the dimmer (issue 34, the scene
description's worked example: one field of the appearance model and one function of the light model).
Settings files, requests, the live state, the change report, the footprint and both renderers take
each from there; at its default the house's lights (and so every image) are as before."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from test_sensors import PROFILE, _box_house, _world

from ravh_msgs_py.appearance import parse
from ravh_msgs_py.query import QueryError
from ravh_sim.errors import FileFieldError
from ravh_sim.look.changes import ChangeWatch
from ravh_sim.look.lighting import HOUSE_KELVIN, dimmed, lamps_at, scene_lights
from ravh_sim.render.backend import resolve_backend
from ravh_sim.sensors.camera import CameraOptions, SmartCamera
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.footprint import make_footprint
from ravh_sim.world.settings import Resolved, load_settings, resolve

WARM, COOL = 2000.0, 8000.0
NIGHT_VIEW = (5.5, 3.5, math.radians(-150))         # room A with its ceiling light Light_0


def test_the_default_is_the_house_files_light_colours(houses):
    lights = houses[15].lights
    settings = resolve(load_settings(), houses[15])
    assert settings.light_temperature == HOUSE_KELVIN
    assert lamps_at(lights, HOUSE_KELVIN) == list(lights)
    record = settings.model_dump(mode="json")
    del record["light_temperature"]                           # a footprint written before the knob
    assert Resolved.model_validate(record) == settings
    warm, cool = (lamps_at(lights[:1], k)[0].color for k in (WARM, COOL))
    assert warm[2] / warm[0] < lights[0].color[2] / lights[0].color[0] < cool[2] / cool[0]


def test_settings_files_and_requests_take_the_knob_with_its_bounds(houses, tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text("lights: {light_temperature: 5000}\n")
    assert resolve(load_settings(path), houses[15]).light_temperature == 5000.0
    path.write_text("lights: {light_temperature: 20}\n")
    with pytest.raises(FileFieldError) as err:
        load_settings(path)
    assert err.value.field == "lights.light_temperature"
    assert parse({"light_temperature": COOL}) == {"light_temperature": COOL}
    with pytest.raises(QueryError, match=r"^light_temperature: expected kelvin in \[1000, 10000\], got 100000.0$"):
        parse({"light_temperature": 1e5})


@pytest.fixture(scope="module")
def worlds():
    assert resolve_backend("auto") == "gl", "the GL renderer must start on this machine (EGL + llvmpipe)"
    with _world(_box_house()) as gl, _world(_box_house()) as tiny:
        yield {"gl": gl, "tiny": tiny}


def _night_room(world, backend):
    """Room A at night lit by its ceiling light alone, and a ``backend`` camera at a fixed exposure."""
    appearance = Appearance(world)
    appearance.change({"sun_angle": "night", "lights": {"all": "off", "Light_0": "on"}})
    camera = SmartCamera(world, replace(PROFILE.camera, quality="realistic"), CameraOptions(manual_exposure=3.0),
                         backend=backend)
    return appearance, camera


@pytest.mark.parametrize("renderer", ["gl", "tiny"])
def test_cooler_lights_make_a_bluer_room_and_the_footprint_records_them(worlds, renderer):
    world = worlds[renderer]
    appearance, camera = _night_room(world, renderer)
    blue_over_red = {}
    for kelvin in (WARM, COOL, WARM):        # back again: the renderer follows every change
        reply = appearance.change({"light_temperature": kelvin})
        assert reply["settings"]["light_temperature"] == kelvin
        rgb = camera.capture(*NIGHT_VIEW).rgb.reshape(-1, 3).astype(np.float64)
        blue_over_red.setdefault(kelvin, []).append(rgb[:, 2].sum() / rgb[:, 0].sum())
    assert blue_over_red[COOL][0] > 1.2 * blue_over_red[WARM][0]
    assert blue_over_red[WARM][0] == pytest.approx(blue_over_red[WARM][1], rel=1e-3)
    assert make_footprint(world.house, world.state.settings())["settings"]["light_temperature"] == WARM


def test_the_dimmer_default_is_full_power_and_old_footprints_still_load(houses):
    settings = resolve(load_settings(), houses[15])
    assert settings.lamp_dimmer == 1.0
    assert dimmed(houses[15].lights, 1.0) == list(houses[15].lights)
    record = settings.model_dump(mode="json")
    del record["lamp_dimmer"]                                  # a footprint written before the knob
    assert Resolved.model_validate(record) == settings
    assert parse({"lamp_dimmer": 0.5}) == {"lamp_dimmer": 0.5}
    with pytest.raises(QueryError, match=r"^lamp_dimmer: expected share of full power in \[0.1, 1\], got 2.0$"):
        parse({"lamp_dimmer": 2.0})


def test_the_light_model_scales_every_lamp_and_the_change_report_relights_them(worlds):
    world = worlds["gl"]
    appearance = Appearance(world)
    appearance.change({"sun_angle": "night", "lights": {"all": "on"}, "lamp_dimmer": 1.0})
    watch = ChangeWatch(world.state)
    watch.poll()
    full = scene_lights(world.house, world.state)
    appearance.change({"lamp_dimmer": 0.25})
    change = watch.poll()
    assert change.every_lamp and change.lamps and not change.sun and not change.geometry
    low = scene_lights(world.house, world.state)
    assert [lt.id for lt in low.lamps] == [lt.id for lt in full.lamps] and low.lamps
    for a, b in zip(full.lamps, low.lamps):
        assert b.intensity == pytest.approx(0.25 * a.intensity) and b.color == a.color
    for room in world.house.rooms:                # the lamps' share of the ambient scales, the sky's does not
        lamp_share = full.room_ambient[room.id] - low.room_ambient[room.id]
        assert np.all(lamp_share >= 0)
        if any(lt.room == room.id for lt in full.lamps):
            assert lamp_share.sum() > 0


@pytest.mark.parametrize("renderer", ["gl", "tiny"])
def test_a_dimmed_room_is_darker_and_the_footprint_records_it(worlds, renderer):
    world = worlds[renderer]
    appearance, camera = _night_room(world, renderer)
    brightness = {}
    for level in (1.0, 0.3, 1.0):            # back again: the renderer follows every change
        assert appearance.change({"lamp_dimmer": level})["settings"]["lamp_dimmer"] == level
        brightness.setdefault(level, []).append(float(camera.capture(*NIGHT_VIEW).rgb.mean()))
    assert brightness[0.3][0] < 0.8 * brightness[1.0][0]
    assert brightness[1.0][0] == pytest.approx(brightness[1.0][1], rel=1e-3)
    appearance.change({"lamp_dimmer": 0.3})
    assert make_footprint(world.house, world.state.settings())["settings"]["lamp_dimmer"] == 0.3
