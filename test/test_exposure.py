"""Every frame has a plausible exposure (issue 19: no black frames).

One pixel whose radiance was NaN (Schlick's Fresnel of a dot product a rounding above 1) made the
metered average NaN and the whole frame black. Here: many random poses in the free space of several
houses, by day, at sunset and at night, must all give frames with a sane brightness; and a NaN put
into the HDR target on purpose must neither decide the exposure nor be stored.
"""
from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from test_sensors import PROFILE

from ravh_sim.nav.grid import FREE
from ravh_sim.nav.navigation import Navigation
from ravh_sim.render.backend import resolve_backend
from ravh_sim.render.gl_develop import RenderError
from ravh_sim.render.gl_renderer import GLRenderer
from ravh_sim.sensors.camera import SmartCamera
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.house import load_house
from ravh_sim.world.scene import World
from ravh_sim.world.settings import load_settings, resolve

HOUSES = (3, 5, 10, 21, 23)
POSES_PER_HOUSE = 100                       # 500 in all, as the issue asks
SUNS = (("day", 0.6), ("sunset", 0.2), ("night", 0.2))   # share of each house's poses
MEAN_LUMA = (6.0, 200.0)                    # 8-bit mean luma of a frame a camera would keep
WAS_BLACK = (5, (-1.225, 2.825, 4.733534526121307))      # one pixel of NaN blacked this view out


def _gl_camera(world: World) -> SmartCamera:
    if resolve_backend("auto") != "gl":
        pytest.fail("the GL renderer must start on this machine (EGL + llvmpipe)")
    return SmartCamera(world, PROFILE.camera)


def _luma(rgb: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY).astype(np.float64)


def _free_poses(world: World, count: int, rng: np.random.Generator) -> list[tuple[float, float, float]]:
    """Random poses where the robot fits (the navigation map's free cells), random headings."""
    grid = Navigation(world.house, world.state, PROFILE).map()
    rows, cols = np.nonzero(grid.data == FREE)
    picks = rng.choice(len(rows), size=count, replace=False)
    return [(*grid.center_of(int(rows[i]), int(cols[i])), float(rng.uniform(0.0, 2.0 * math.pi)))
            for i in picks]


@pytest.mark.parametrize("number", HOUSES)
def test_random_views_are_exposed_plausibly(number):
    house = load_house(number)
    rng = np.random.default_rng(number)
    bad = []
    with World(house, resolve(load_settings(), house, 0)) as world:
        camera, appearance = _gl_camera(world), Appearance(world)
        poses = _free_poses(world, POSES_PER_HOUSE, rng)
        start = 0
        for sun, share in SUNS:
            appearance.set_knob("sun_angle", sun)
            end = start + round(share * POSES_PER_HOUSE)
            for pose in poses[start:end]:
                luma = _luma(camera.render(*pose).rgb)       # a NaN pixel raises RenderError
                if not MEAN_LUMA[0] < luma.mean() < MEAN_LUMA[1]:
                    bad.append((sun, pose, round(float(luma.mean()), 1)))
            start = end
        assert start == POSES_PER_HOUSE
    assert not bad, f"house {number}: frames exposed implausibly (sun, pose, mean luma): {bad}"


@pytest.fixture(scope="module")
def black_view_world():
    number, _ = WAS_BLACK
    house = load_house(number)
    with World(house, resolve(load_settings(), house, 0)) as world:
        Appearance(world).set_knob("sun_angle", "day")
        yield world


def test_the_view_that_was_black_is_exposed(black_view_world):
    rgb = _gl_camera(black_view_world).render(*WAS_BLACK[1]).rgb
    assert MEAN_LUMA[0] < _luma(rgb).mean() < MEAN_LUMA[1]


def test_a_nan_pixel_neither_meters_nor_is_stored(black_view_world):
    """A NaN written into the HDR target on purpose, on a pixel the meter samples: the exposure stays
    what the clean frame gets, and developing the frame raises instead of returning it."""
    camera = _gl_camera(black_view_world)
    renderer = camera.renderer
    assert isinstance(renderer, GLRenderer)
    clean = camera.render(*WAS_BLACK[1]).rgb
    exposure = renderer.developer.auto_exposure(renderer.developer.meter_blocks())
    hdr = np.frombuffer(renderer.hdr.read(), np.float16).reshape(renderer.height, renderer.width, 4).copy()
    hdr[100, 200] = np.nan
    renderer.hdr.write(hdr.tobytes())
    with pytest.raises(RenderError, match="1 pixels of non-finite radiance"):
        renderer.developer.develop(None)
    assert math.isfinite(renderer.developer.auto_exposure(renderer.developer.meter_blocks()))
    assert renderer.developer.auto_exposure(renderer.developer.meter_blocks()) == pytest.approx(exposure, rel=0.01)
    assert clean.mean() > MEAN_LUMA[0]
