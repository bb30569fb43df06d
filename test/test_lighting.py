"""The realistic renderer's light transport against computations a reader can check: a lamp's
inverse-square fall-off, lamp light through an open door (and not through a closed one), ambient
occlusion beside furniture, auto-exposure against a fixed one, and light maps that follow a door or
a model change (issue 23).

Radiance is read back linear (before exposure) from a camera looking straight down from under the
ceiling, so a floor point's pixel is a projection and its value is light, not a camera's response.
The box house (test_sensors) has room A (0..6 x 0..4 m, its lamp Light_0 at (3, 2, 2.65), a window
in its west wall) and room B (6.2..9 x 0..4 m, no window, its lamp Light_1, a closet against its
east wall), joined by Door_0 (x = 6.1, y = 1..2, 2.1 m high).
"""
from __future__ import annotations

import math
from dataclasses import replace

import cv2
import numpy as np
import pytest
from test_sensors import PROFILE, gl_box_world, restored_appearance

from ravh_sim.sensors.camera import CameraOptions, SmartCamera
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.scene import World

GREY = "#d0d0d0"                          # a plain floor paint: one albedo everywhere
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
LOOK_DOWN = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])  # optical x east, y south, z down
CAMERA_HEIGHT = 2.7


world = pytest.fixture(scope="module")(gl_box_world)
appearance = pytest.fixture()(restored_appearance)


def _camera_over(world: World) -> SmartCamera:
    """A realistic camera with a fixed exposure (TopDown reads its renderer's linear light)."""
    return SmartCamera(world, replace(PROFILE.camera, quality="realistic"), CameraOptions(manual_exposure=1.0))


@pytest.fixture(scope="module")
def camera(world):
    camera = _camera_over(world)
    yield camera
    camera.close()


class TopDown:
    """One linear-light frame from a camera looking straight down from (x, y, CAMERA_HEIGHT)."""

    def __init__(self, camera: SmartCamera, x: float, y: float) -> None:
        assert camera.renderer is not None
        self.K, self.position = camera.K, np.array([x, y, CAMERA_HEIGHT])
        self.views = camera.renderer.render(self.position, LOOK_DOWN, 1.0, radiance=True)
        assert self.views.radiance is not None
        self.luminance = self.views.radiance @ LUMINANCE

    def pixel(self, x: float, y: float) -> tuple[int, int]:
        cam = (np.array([x, y, 0.0]) - self.position) @ LOOK_DOWN
        u, v, w = self.K @ cam
        return int(round(u / w)), int(round(v / w))

    def floor(self, world: World, room: str, x: float, y: float, half: int = 6) -> float:
        """Mean luminance of a small floor patch around (x, y) (checked to be ``room``'s floor)."""
        u, v = self.pixel(x, y)
        window = np.s_[v - half:v + half + 1, u - half:u + half + 1]
        assert (self.views.instance[window] == world.instance(f"{room}/floor").id).all(), (x, y)
        return float(self.luminance[window].mean())


def _linear(hex_paint: str) -> float:
    """The linear albedo of a grey sRGB paint."""
    c = int(hex_paint[1:3], 16) / 255
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def _lamp_irradiance(world: World, light: str, x: float, y: float) -> float:
    """Luminance of the irradiance a point lamp gives a floor point: intensity x cos(incidence) / d^2
    (an intensity-1 lamp gives 1 at 1 m), faded to nothing at the light's range as
    (1 - (d / range)^4)^2 so that a light ends somewhere."""
    lamp = world.house.light_by_id[light]
    offset = np.asarray(lamp.position) - np.array([x, y, 0.0])
    d = float(np.linalg.norm(offset))
    fade = max(0.0, 1.0 - (d / lamp.range) ** 4) ** 2
    return float(np.dot(lamp.color, LUMINANCE)) * lamp.intensity * (offset[2] / d) / d ** 2 * fade


def _lamp_alone(world, appearance, camera, light: str, x: float, y: float) -> tuple[TopDown, TopDown]:
    """Night, every light off but ``light``: frames with it on and off, looking down at (x, y)."""
    appearance.set_knob("sun_angle", "night")
    appearance.set_lights("all", "off")
    off = TopDown(camera, x, y)
    appearance.set_light(light, True)
    return TopDown(camera, x, y), off


def test_a_lamps_light_on_the_floor_falls_off_with_the_square_of_distance(world, appearance, camera):
    """What Light_0 adds to the floor (frame with it on minus off) drops from under it to 2.5 m
    away by what Lambert's law says a matte floor of the paint's albedo reflects of the drop in a
    point source's irradiance: rho / pi x (E(0) - E(2.5)). The room's bounce light (the same
    everywhere) cancels in the drop. No fall-off would make the drop three times larger, 1/d twice."""
    appearance.set_paint("A", "floor", GREY)
    on, off = _lamp_alone(world, appearance, camera, "Light_0", 4.0, 2.0)
    near, far = (3.0, 2.0), (5.5, 2.0)
    added = [on.floor(world, "A", *p) - off.floor(world, "A", *p) for p in (near, far)]
    lambert = _linear(GREY) / math.pi * (_lamp_irradiance(world, "Light_0", *near)
                                         - _lamp_irradiance(world, "Light_0", *far))
    assert added[0] > added[1] > 0
    assert added[0] - added[1] == pytest.approx(lambert, rel=0.15)


def test_a_lamps_light_reaches_the_next_room_through_an_open_door_only(world, appearance, camera):
    """Light_0 in room A, seen from above room B: with Door_0 open its light lands on B's floor
    where the straight line from the lamp passes through the doorway, as much as Lambert's law
    gives there; a point of B whose line meets the wall gets none, and with the door closed no
    point of B gets any (what the lamp adds: the frame with it on minus off)."""
    appearance.set_paint("B", "floor", GREY)
    through, behind = (7.2, 1.5), (7.2, 3.0)      # lamp-to-point lines cross x = 6..6.2 at y = 1.6, 2.8
    added = {}
    for is_open in (True, False):
        appearance.set_door("Door_0", is_open)
        on, off = _lamp_alone(world, appearance, camera, "Light_0", 7.4, 2.3)
        added[is_open] = [on.floor(world, "B", *p) - off.floor(world, "B", *p) for p in (through, behind)]
    lambert = _linear(GREY) / math.pi * _lamp_irradiance(world, "Light_0", *through)
    assert added[True][0] == pytest.approx(lambert, rel=0.25)
    assert abs(added[True][1]) < 0.05 * lambert
    assert max(abs(a) for a in added[False]) < 0.05 * lambert


def test_floor_beside_furniture_is_darker_by_ambient_occlusion(world, appearance, camera):
    """Room B by day with its door closed and its lamp off has no direct light (no window, no
    lamp, the sun cannot reach it): its uniform sky-and-bounce light is all that lights the floor,
    so without ambient occlusion the floor would be equally bright everywhere. It is beside the
    closet (front face at x = 8.3) that the floor darkens, and only there."""
    appearance.set_paint("B", "floor", GREY)
    appearance.set_knob("sun_angle", "day")
    appearance.set_lights("all", "off")
    appearance.set_door("Door_0", False)
    view = TopDown(camera, 7.6, 2.6)
    front = world.house.object("Closet_0").position[0] - world.house.object("Closet_0").size[0] / 2
    beside, near, open_floor = (view.floor(world, "B", front - gap, 3.0, half=3) for gap in (0.05, 0.4, 0.8))
    assert beside < 0.9 * open_floor
    assert near == pytest.approx(open_floor, rel=0.03)


def test_auto_exposure_narrows_the_brightness_gap_a_fixed_exposure_keeps(world, appearance):
    """Room A by day, at dusk and at night under its lamp: through a fixed exposure the frames'
    mean brightness spreads as the light does; auto-exposure gives the darker scenes a longer
    exposure, so the spread shrinks, yet keeps their order (a camera's night stays darker than its
    day)."""
    pose = (5.5, 3.0, math.radians(-150))
    cameras = {mode: SmartCamera(world, replace(PROFILE.camera, quality="realistic"), CameraOptions(manual_exposure=e))
               for mode, e in (("fixed", 1.0), ("auto", None))}
    brightness: dict[str, list[float]] = {"fixed": [], "auto": []}
    try:
        for sun, lights in (("day", "off"), (170.0, "off"), ("night", "on")):
            appearance.set_knob("sun_angle", sun)
            appearance.set_lights("all", lights)
            for mode, camera in cameras.items():
                grey = cv2.cvtColor(camera.capture(*pose).rgb, cv2.COLOR_RGB2GRAY)
                brightness[mode].append(float(grey.mean()))
    finally:
        for camera in cameras.values():
            camera.close()
    for mode in cameras:
        assert brightness[mode] == sorted(brightness[mode], reverse=True), mode
    spread = {mode: math.log(values[0] / values[-1]) for mode, values in brightness.items()}
    assert spread["fixed"] > math.log(1.8)
    assert spread["auto"] < 0.7 * spread["fixed"]


def _open_the_door(appearance):
    appearance.set_door("Door_0", True)


def _swap_the_closet(appearance):
    appearance.set_object_model("Closet_0", 2)


@pytest.mark.parametrize("change, door_open, lit", [
    (_open_the_door, False, "Light_0"),
    (_swap_the_closet, True, "Light_1")])
def test_light_maps_follow_a_door_or_model_change(world, appearance, change, door_open, lit):
    """Looking down at room B at night under one lamp, after a change of geometry that moves a
    shadow (Door_0 opens and lets room A's light in; the closet becomes another model): B's floor
    changes, and the frame equals the one a World built afresh in the new state renders (the
    renderer's light maps were redrawn, not kept from before the change). The change is made on
    a World of its own, whose light maps were first drawn in the state before it."""
    appearance.set_paint("B", "floor", GREY)
    appearance.set_door("Door_0", door_open)
    appearance.set_knob("sun_angle", "night")
    appearance.set_lights("all", "off")
    appearance.set_light(lit, True)
    with World(world.house, world.state.settings()) as changing:
        camera = _camera_over(changing)                  # one renderer, before and after the change
        try:
            first = TopDown(camera, 7.6, 2.6)
            change(Appearance(changing))
            second = TopDown(camera, 7.6, 2.6)
        finally:
            camera.close()
        after = changing.state.settings()
    with World(world.house, after) as fresh:
        camera = _camera_over(fresh)
        try:
            expected = TopDown(camera, 7.6, 2.6)
        finally:
            camera.close()
    floor = (first.views.instance == world.instance("B/floor").id) & \
        (second.views.instance == world.instance("B/floor").id)
    moved = floor & (np.abs(second.luminance - first.luminance) > 0.1 * first.luminance + 1e-4)
    assert moved.sum() > 500
    assert (second.views.instance == expected.views.instance).all()
    assert np.abs(second.views.rgb.astype(int) - expected.views.rgb.astype(int)).max() <= 1
