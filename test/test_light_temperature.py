"""The light colour temperature knob (issue 22): one field of the appearance model that settings
files, requests, the live state, the footprint and both renderers take from there; at its default
the house's light colours (and so every image) are as before."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from test_sensors import PROFILE, _box_house, _world

from ravh_msgs_py.appearance import parse
from ravh_msgs_py.query import QueryError
from ravh_sim.errors import FileFieldError
from ravh_sim.look.lighting import HOUSE_KELVIN, lamps_at
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
    with _world(_box_house()) as gl, _world(_box_house(), renderer="tiny") as tiny:
        assert gl.renderer == "gl", "the GL renderer must start on this machine (EGL + llvmpipe)"
        yield {"gl": gl, "tiny": tiny}


@pytest.mark.parametrize("renderer", ["gl", "tiny"])
def test_cooler_lights_make_a_bluer_room_and_the_footprint_records_them(worlds, renderer):
    world = worlds[renderer]
    appearance = Appearance(world)
    appearance.change({"sun_angle": "night", "lights": {"all": "off", "Light_0": "on"}})
    camera = SmartCamera(world, replace(PROFILE.camera, quality="realistic"), CameraOptions(manual_exposure=3.0))
    blue_over_red = {}
    for kelvin in (WARM, COOL, WARM):        # back again: the renderer follows every change
        reply = appearance.change({"light_temperature": kelvin})
        assert reply["settings"]["light_temperature"] == kelvin
        rgb = camera.capture(*NIGHT_VIEW).rgb.reshape(-1, 3).astype(np.float64)
        blue_over_red.setdefault(kelvin, []).append(rgb[:, 2].sum() / rgb[:, 0].sum())
    assert blue_over_red[COOL][0] > 1.2 * blue_over_red[WARM][0]
    assert blue_over_red[WARM][0] == pytest.approx(blue_over_red[WARM][1], rel=1e-3)
    assert make_footprint(world.house, world.state.settings())["settings"]["light_temperature"] == WARM
