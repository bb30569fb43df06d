"""The GL renderer develops a frame through the camera sensor where it draws it: the sensor model's
decisions (exposure, white balance, motion sweep) and the statistics of its image (level, noise,
clipping, blur) are those of the numpy reference, SensorModel.expose, on the same radiance.

Radiance is written into the renderer's HDR target directly, so every case is a known scene: flat
walls from daylight down to a few electrons a pixel (the Poisson branch of the noise), a clipped
window, a warm cast, a sharp edge for the blur.
"""
from __future__ import annotations

import cv2
import numpy as np
import pytest
from conftest import resolved

from ravh_sim.render.backend import resolve_backend
from ravh_sim.render.gl_renderer import GLRenderer
from ravh_sim.render.views import Development
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.camera import PORT
from ravh_sim.sensors.imaging import DAYLIT_LUMINANCE, SensorModel
from ravh_sim.world.scene import World

W, H = 160, 120                    # not a multiple of the meter's 16-pixel blocks: partial blocks count too
K = np.array([[548.0, 0.0, W / 2], [0.0, 548.0, H / 2], [0.0, 0.0, 1.0]])
DEPTH_M = 2.0


@pytest.fixture(scope="module")
def renderer(houses):
    if resolve_backend("auto") != "gl":
        pytest.fail("the GL renderer must start on this machine (EGL + llvmpipe)")
    with World(houses[20], resolved(houses[20])) as world:
        gl = GLRenderer(world, K, W, H, 0.15, 20.0)
        yield gl
        gl.release()


def scene(luminance: float, tint=(1.0, 1.0, 1.0), window: bool = True) -> np.ndarray:
    """Two flat walls (the right one twice as bright), a clipped window in the top left corner."""
    image = np.full((H, W, 3), luminance, np.float32) * np.asarray(tint, np.float32)
    image[:, W // 2:] *= 2
    if window:
        image[:20, :20] = 500.0 * luminance
    return image.astype(np.float16).astype(np.float32)       # what the HDR target holds


def develop(renderer: GLRenderer, radiance: np.ndarray, sensor: SensorModel, seed: int,
            velocity: tuple[float, float] = (0.0, 0.0)):
    """The frame developed on the device, for ``radiance`` (rows top first) at DEPTH_M everywhere."""
    hdr = np.concatenate([radiance, np.zeros((H, W, 1), np.float32)], axis=2)[::-1]
    renderer.hdr.write(np.ascontiguousarray(hdr, np.float16).tobytes())
    renderer.depth.write(np.full((H, W), DEPTH_M, np.float32).tobytes())
    renderer.instance.write(np.ones((H, W), np.int32).tobytes())
    views = renderer.developer.develop(None, development=Development(sensor, np.random.default_rng(seed), velocity))
    assert views.exposure is not None
    return views.rgb, views.exposure


def walls(rgb: np.ndarray) -> list[np.ndarray]:
    """The two walls' pixels, away from the window and the edge between them."""
    return [rgb[30:, 5:W // 2 - 5].astype(float), rgb[30:, W // 2 + 5:-5].astype(float)]


@pytest.mark.parametrize("light", [2.0, 0.5, 0.1, 0.02, 0.002])
def test_the_device_develops_as_the_reference_does(renderer, light):
    sensor = SensorModel()
    radiance = scene(DAYLIT_LUMINANCE * light, (1.3, 1.0, 0.7))
    device, chosen = develop(renderer, radiance, sensor, seed=1)
    reference, expected = sensor.expose(radiance, np.random.default_rng(1))
    assert chosen.time == pytest.approx(expected.time, rel=1e-5)
    assert chosen.gain == pytest.approx(expected.gain, rel=1e-5)
    assert chosen.white_balance == pytest.approx(expected.white_balance, abs=0.01)
    assert chosen.signal == pytest.approx(expected.signal, rel=0.01)
    for ours, theirs in zip(walls(device), walls(reference)):
        for channel in range(3):
            assert ours[..., channel].mean() == pytest.approx(theirs[..., channel].mean(), abs=1.0)
            assert ours[..., channel].std() == pytest.approx(theirs[..., channel].std(), rel=0.15, abs=0.3)
    window = device[:20, :20].reshape(-1, 3).astype(int)                # clipped alike: flat, no noise
    assert (window == window[0]).all() and np.abs(window[0] - reference[0, 0]).max() <= 1


def test_a_few_electrons_are_counted_as_photons_come(renderer):
    """At about two electrons a pixel the charge is a Poisson count (16 % of the pixels catch none),
    not a Gaussian spread around the mean: the dim wall's histogram over its first few codes is the
    reference's."""
    sensor = SensorModel(read_noise=0.0, white_balance=False)
    radiance = scene(DAYLIT_LUMINANCE * 0.0005)
    device, chosen = develop(renderer, radiance, sensor, seed=2)
    reference, _ = sensor.expose(radiance, np.random.default_rng(2))
    assert chosen.gain == sensor.gain_max                               # past its limits: a dark frame
    ours, theirs = walls(device)[0][..., 1], walls(reference)[0][..., 1]
    codes = np.unique(theirs)[:4]
    assert len(codes) == 4 and (theirs == codes[0]).mean() > 0.1
    for code in codes:
        assert (ours == code).mean() == pytest.approx((theirs == code).mean(), abs=0.03)


def test_the_same_seed_gives_the_same_frame_and_another_seed_another(renderer):
    sensor, radiance = SensorModel(), scene(DAYLIT_LUMINANCE * 0.02)
    a, _ = develop(renderer, radiance, sensor, seed=3)
    b, _ = develop(renderer, radiance, sensor, seed=3)
    c, _ = develop(renderer, radiance, sensor, seed=4)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def edge(rgb: np.ndarray) -> tuple[int, float]:
    """The edge between the walls: how many columns are neither wall's level (the blur's width), and
    where it stands (the column a sharp step of the same area would be at)."""
    row = np.median(rgb[40:, :, 1].astype(float), axis=0)
    lo, hi = np.median(row[10:40]), np.median(row[-40:-10])
    width = int(np.sum((row > lo + 0.2 * (hi - lo)) & (row < hi - 0.2 * (hi - lo))))
    return width, 40 + float(np.clip((hi - row[40:120]) / (hi - lo), 0, 1).sum())


def test_turning_blurs_the_frame_as_much_as_the_reference_does(renderer):
    sensor = SensorModel(read_noise=0.0)
    radiance = scene(DAYLIT_LUMINANCE * 0.05, window=False)
    turning = (0.0, np.radians(25))
    sharp, _ = develop(renderer, radiance, sensor, seed=5)
    blurred, chosen = develop(renderer, radiance, sensor, seed=5, velocity=turning)
    reference, _ = sensor.expose(radiance, np.random.default_rng(5), K, turning, DEPTH_M)
    (sharp_width, _), (width, at), (reference_width, reference_at) = edge(sharp), edge(blurred), edge(reference)
    assert sharp_width <= 1
    assert abs(width - reference_width) <= 1 and abs(at - reference_at) <= 0.5
    assert width >= 5                                                    # 548 px/rad * 0.44 rad/s * 1/30 s = 8 px
    assert chosen.time == pytest.approx(sensor.exposure_max)


def test_the_robots_camera_develops_on_the_device_and_blurs_when_it_turns(houses):
    """The giraff camera as the sim builds it: its frames come developed by the renderer (no numpy
    sensor), and its sensor blurs them whenever the robot moves (no profile switch needed)."""
    house = houses[15]
    with World(house, resolved(house)) as world:
        camera = PORT.build(world, load_profile().camera, "robot")
        x, y, yaw = house.station.position[0], house.station.position[1], house.station.yaw
        still = camera.capture(x, y, yaw, index=0)
        turning = camera.capture(x, y, yaw, velocity=(0.0, np.radians(25)), index=0)
        frame = camera.render(x, y, yaw, development=Development(camera.sensor, np.random.default_rng(0)))
        camera.close()
    assert frame.exposure is not None and frame.exposure.time > 0
    sharpness = [cv2.Laplacian(cv2.cvtColor(c.rgb, cv2.COLOR_RGB2GRAY), cv2.CV_64F).var() for c in (still, turning)]
    assert sharpness[1] < 0.7 * sharpness[0]
    assert np.array_equal(still.depth, turning.depth, equal_nan=True)      # the blur is the image's alone
