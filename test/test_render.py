"""The realistic renderer on fixed scenes: sun shadows and window light, sunset colour, lamps without
halos, textures, RGB/depth/instance edges that line up (issue: images that look like photos), and the
outdoors a window shows: a lit neighbourhood that follows the sun, seeded per house (issue 32).

Every comparison of brightness uses a fixed exposure (the camera in manual mode), so it measures
the light in the scene, not the auto-exposure's reaction to it.
"""
from __future__ import annotations

import math
from dataclasses import replace

import cv2
import numpy as np
import pytest
from test_sensors import PROFILE, _world, gl_box_world, restored_appearance

from ravh_sim.look.geometry import corner_normals
from ravh_sim.look.lighting import outdoors, sun_light
from ravh_sim.look.materials import noise_volume
from ravh_sim.sensors.camera import CameraOptions, SmartCamera
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.house import load_house

EXPOSURE = CameraOptions(manual_exposure=1.0)


world = pytest.fixture(scope="module")(gl_box_world)
appearance = pytest.fixture()(restored_appearance)


def _camera(world, quality="realistic", options=EXPOSURE):
    return SmartCamera(world, replace(PROFILE.camera, quality=quality), options)


def _luminance(rgb: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY).astype(np.float64)


def _patch(image: np.ndarray, uv: np.ndarray, half: int = 4) -> float:
    u, v = (int(round(c)) for c in uv)
    return float(image[v - half:v + half + 1, u - half:u + half + 1].mean())


def _floor_hit(sun_angle: float, through: tuple[float, float, float]) -> np.ndarray:
    """Where the sun's ray through a point lands on the floor (z = 0)."""
    d = np.asarray(sun_light(sun_angle).direction)
    p = np.asarray(through)
    return p - d * (p[2] / d[2])


AFTERNOON = 150.0                       # the sun low in the west: it shines through room A's west window
VIEW_WEST = (5.8, 2.3, math.pi)


def test_sunlight_through_the_window_makes_a_bright_floor_patch(world, appearance):
    appearance.set_knob("sun_angle", AFTERNOON)
    appearance.set_lights("all", "off")
    camera = _camera(world)
    patch = _floor_hit(AFTERNOON, (-0.05, 2.0, 1.5))                 # the window's centre
    elsewhere = patch + np.array([0.0, -1.6, 0.0])                   # same distance, not in the sun
    assert 0.5 < patch[0] < 5.5 and 0.2 < elsewhere[1]               # both on room A's floor
    cap = camera.capture(*VIEW_WEST)
    lum = _luminance(cap.rgb)
    uv = camera.project(np.array([patch, elsewhere]), *VIEW_WEST)
    floor = world.instance("A/floor").id
    assert all(cap.instance[int(round(v)), int(round(u))] == floor for u, v in uv)
    assert _patch(lum, uv[0]) > 1.6 * _patch(lum, uv[1])


def test_walls_and_ceiling_shadow_the_sun(world, appearance):
    """The same floor point under the afternoon sun: lit when shadows are off (fast quality),
    dark when the walls and ceiling are allowed to block the sun (realistic)."""
    appearance.set_knob("sun_angle", AFTERNOON)
    appearance.set_lights("all", "off")
    point = _floor_hit(AFTERNOON, (-0.05, 2.0, 1.5)) + np.array([0.0, -1.6, 0.0])
    seen = {}
    for quality in ("realistic", "fast"):
        camera = _camera(world, quality)
        cap = camera.capture(*VIEW_WEST)
        seen[quality] = _patch(_luminance(cap.rgb), camera.project(point[None], *VIEW_WEST)[0])
    assert seen["realistic"] < 0.7 * seen["fast"]


def test_sunset_moves_the_sun_and_colours_its_light_not_every_surface(world, appearance):
    noon, sunset = sun_light(100.0), sun_light(180.0)
    assert math.degrees(math.acos(np.dot(noon.direction, sunset.direction))) > 45
    appearance.set_knob("sun_angle", "sunset")
    appearance.set_lights("all", "off")
    appearance.set_paint("A", "walls", "white")
    appearance.set_paint("A", "floor", "walnut")
    cap = _camera(world, options=CameraOptions()).capture(4.5, 2.0, math.pi)
    hsv = cv2.cvtColor(cap.rgb, cv2.COLOR_RGB2HSV).astype(np.float64)
    wall = cap.instance == world.instance("A/walls").id
    floor = cap.instance == world.instance("A/floor").id
    assert wall.mean() > 0.2 and floor.mean() > 0.1
    # A white wall stays far less saturated than a brown floor: the sunset is not a global tint.
    assert hsv[..., 1][wall].mean() < 0.6 * hsv[..., 1][floor].mean()
    assert abs(hsv[..., 0][wall].mean() - hsv[..., 0][floor].mean()) > 3 or \
        hsv[..., 2][wall].mean() > 1.3 * hsv[..., 2][floor].mean()


def test_one_lamp_at_night_lights_near_more_than_far_without_halos(world, appearance):
    appearance.set_knob("sun_angle", "night")
    appearance.set_lights("all", "off")
    appearance.set_light("Light_0", True)                            # over (3, 2)
    camera = _camera(world, options=CameraOptions(manual_exposure=3.0))
    pose = (5.5, 3.5, math.radians(-150))
    cap = camera.capture(*pose)
    lum = _luminance(cap.rgb)
    near, far = camera.project(np.array([[3.0, 2.0, 0.0], [1.0, 0.4, 0.0]]), *pose)
    assert _patch(lum, near) > 1.8 * _patch(lum, far) > 0
    # No bright ring: just outside the window's silhouette the wall is no brighter than a bit further out.
    window = (cap.instance == world.instance("Wall_0").id).astype(np.uint8)
    assert window.sum() > 2000                                       # the pose shows the window
    wall = cap.instance == world.instance("A/walls").id
    ring = (cv2.dilate(window, np.ones((5, 5), np.uint8)) > 0) & ~window.astype(bool) & wall
    outer = (cv2.dilate(window, np.ones((15, 15), np.uint8)) > 0) & \
        ~(cv2.dilate(window, np.ones((9, 9), np.uint8)) > 0) & wall
    assert ring.sum() > 200 and outer.sum() > 200
    assert lum[ring].mean() < 1.1 * lum[outer].mean() + 2


def test_surfaces_carry_texture(world, appearance):
    appearance.set_knob("sun_angle", "day")
    appearance.set_paint("A", "floor", "parquet")
    cap = _camera(world, options=CameraOptions()).capture(5.0, 2.0, math.pi)
    lum = _luminance(cap.rgb)
    detail = np.abs(lum - cv2.GaussianBlur(lum, (0, 0), 6))          # texture, not shading
    floor = cv2.erode((cap.instance == world.instance("A/floor").id).astype(np.uint8), np.ones((9, 9))) > 0
    assert floor.mean() > 0.1
    assert detail[floor].std() > 2.5
    assert noise_volume().std() > 30                                  # the noise behind the patterns


def test_rgb_depth_and_instance_edges_line_up(world, appearance):
    appearance.set_knob("sun_angle", "day")
    cap = _camera(world, options=CameraOptions()).capture(2.0, 1.0, 0.25)      # the doorway to B
    inst = cap.instance.astype(np.int32)
    boundary = np.zeros(inst.shape, bool)
    boundary[:, 1:] |= inst[:, 1:] != inst[:, :-1]
    boundary[1:, :] |= inst[1:, :] != inst[:-1, :]
    depth = np.nan_to_num(cap.depth, nan=100.0)
    jump = np.zeros(inst.shape, bool)
    jump[:, 1:] |= np.abs(depth[:, 1:] - depth[:, :-1]) > 0.1
    jump[1:, :] |= np.abs(depth[1:, :] - depth[:-1, :]) > 0.1
    occlusion = jump & boundary                                       # one thing in front of another
    assert occlusion.sum() > 100
    lum = _luminance(cap.rgb)
    gradient = np.hypot(cv2.Sobel(lum, cv2.CV_64F, 1, 0), cv2.Sobel(lum, cv2.CV_64F, 0, 1))
    strong = cv2.dilate(gradient, np.ones((3, 3), np.uint8))          # within 1 px
    assert (strong[occlusion] > 20).mean() > 0.8                      # colour edges sit on mask edges


# ----------------------------------------------------------------------------- the outdoors

VIEW_WINDOW = (3.0, 2.0, math.pi)       # room A's west window, 3 m ahead


def _pane(world, cap) -> np.ndarray:
    """The window's glass pixels of a capture, (N, 3) float."""
    pane = cap.instance == world.instance("Wall_0").id
    assert pane.mean() > 0.05
    return cap.rgb[pane].astype(np.float64)


def _ideal(world):
    """A fixed exposure and no sensor model: no noise, so two captures can be compared byte for byte."""
    return SmartCamera(world, replace(PROFILE.camera, sensor=None), EXPOSURE)


def test_the_window_shows_a_sunlit_neighbourhood_not_a_flat_picture(world, appearance):
    """By day the glass shows garden and sky with structure (not one colour, not clipped white); the
    same view is warmer at sunset and dark at night, where a few of the neighbours' windows are lit."""
    seen = {}
    for preset in ("day", "sunset", "night"):
        appearance.set_knob("sun_angle", preset)
        seen[preset] = _pane(world, _camera(world).capture(*VIEW_WINDOW))
    day, sunset, night = seen["day"], seen["sunset"], seen["night"]
    luminance = day @ [0.299, 0.587, 0.114]
    assert luminance.std() > 25                                       # a picture, not a flat colour
    assert (day.min(axis=1) >= 250).mean() < 0.05                     # not a white hole either
    green = (day[:, 1] > day[:, 0] + 10) & (day[:, 1] > day[:, 2] + 10)
    bluish = day[:, 2] > day[:, 0] + 8
    assert green.mean() > 0.1 and bluish.mean() > 0.05                # lawn and leaves, sky and shade
    warmth = lambda px: px[:, 0].mean() / px[:, 2].mean()             # noqa: E731
    assert warmth(sunset) > 1.3 * warmth(day)
    assert night.mean() < day.mean() / 4
    assert np.median(night.mean(axis=1)) < 20
    lit = (night[:, 0] > 120) & (night[:, 0] > night[:, 2] + 30)     # warm, bright: a lit window
    assert 0.0 < lit.mean() < 0.2


def test_each_house_looks_out_on_its_own_neighbourhood(world, appearance):
    """The outdoors is seeded by the house: the same house shows the same view byte for byte, another
    house number with the same rooms and pose a different one."""
    appearance.set_knob("sun_angle", "day")
    first = _pane(world, _ideal(world).capture(*VIEW_WINDOW))
    neighbour = replace(world.house, number=world.house.number + 1)
    with _world(neighbour) as other:
        Appearance(other).set_knob("sun_angle", "day")
        elsewhere = _pane(other, _ideal(other).capture(*VIEW_WINDOW))
    again = _pane(world, _ideal(world).capture(*VIEW_WINDOW))
    assert np.array_equal(first, again)
    assert np.abs(first - elsewhere).mean() > 10
    sun = sun_light(100.0)
    assert outdoors(sun, load_house(15)) == outdoors(sun, load_house(15))
    assert outdoors(sun, load_house(15)).seed != outdoors(sun, load_house(23)).seed


def test_the_outdoors_follows_the_sun():
    """Light model: the sky is brighter by day than at dusk and at night, its horizon warmer at sunset
    than at noon while the zenith stays blue, and the neighbours' lamps come on as daylight goes."""
    noon, dusk, night = (outdoors(sun_light(a)) for a in (100.0, 180.0, 200.0))
    brightness = lambda c: float(np.mean(c))                          # noqa: E731
    assert brightness(noon.sky_horizon) > brightness(dusk.sky_horizon) > 10 * brightness(night.sky_horizon)
    assert dusk.sky_horizon[0] / dusk.sky_horizon[2] > 2 * noon.sky_horizon[0] / noon.sky_horizon[2]
    assert dusk.sky_zenith[2] > dusk.sky_zenith[0]
    assert night.sky_zenith[2] > night.sky_zenith[0]                  # a dark blue night, not grey
    assert brightness(noon.light) > 5 * brightness(night.light)
    assert brightness(noon.lit_windows) == 0.0 < brightness(dusk.lit_windows) < brightness(night.lit_windows)


def test_dataset_quality_draws_the_same_instances_at_the_same_pixels():
    """The dataset level of detail (finer washbasins and taps, larger textures) is drawn where the live
    model stands: the same instances in the same pixels but for silhouette detail, depth within mm."""
    with _world(load_house("15")) as world:
        pose = (1.74, -6.7, -math.pi / 2)                # house 15's second washbasin, close up
        live = _camera(world).capture(*pose)
        detailed = _camera(world, "dataset").capture(*pose)
        washbasins = {i.id for i in world.instances if i.type == "Washbasin"}
    assert washbasins & set(np.unique(live.instance).tolist())
    differ = live.instance != detailed.instance
    assert differ.mean() < 0.01, differ.mean()                              # 541 of 307,200 px here
    assert set(np.unique(live.instance).tolist()) == set(np.unique(detailed.instance).tolist())
    same = ~differ & np.isfinite(live.depth) & np.isfinite(detailed.depth)
    assert np.percentile(np.abs(live.depth[same] - detailed.depth[same]), 95) < 0.01
    assert not np.array_equal(live.rgb, detailed.rgb)


def test_shading_normals_smooth_split_vertices_and_keep_creases():
    """A sphere whose every triangle has its own vertices (as a library model's upholstery, split at
    its seams) shades as smooth as the sphere with shared vertices where its faces are welded (soft
    models), as facets where not (a split is a hard edge); a welded cube keeps its flat faces however
    its sides are cut into triangles."""
    import trimesh
    sphere = trimesh.creation.icosphere(subdivisions=2)
    split = sphere.vertices[sphere.faces].reshape(-1, 3), np.arange(3 * len(sphere.faces)).reshape(-1, 3)
    smooth = corner_normals(*split, welded=True)
    assert np.allclose(smooth, corner_normals(sphere.vertices, sphere.faces, welded=True), atol=1e-9)
    radial = split[0] / np.linalg.norm(split[0], axis=1, keepdims=True)
    assert np.einsum("ij,ij->i", smooth, radial).min() > 0.999
    assert np.allclose(corner_normals(*split), np.repeat(sphere.face_normals, 3, axis=0), atol=1e-9)
    cube = trimesh.creation.box((1.0, 1.0, 1.0))
    cube_n = corner_normals(cube.vertices, cube.faces, welded=True)
    assert np.allclose(cube_n, np.repeat(cube.face_normals, 3, axis=0), atol=1e-9)
