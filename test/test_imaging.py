"""The camera sensor model: auto-exposure within limits, noise that grows as light falls, blur over the
exposure time, white balance, clipping, seeded; on in the realistic profile, off in the ideal one."""
from __future__ import annotations

import numpy as np
import pytest

from ravh_sim.errors import FileFieldError
from ravh_sim.paths import ROBOTS_DIR
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.imaging import (
    DAYLIT_LUMINANCE,
    SensorModel,
    aces,
    radiance_from_rendered,
    srgb_encode,
)

H, W = 60, 80
K = np.array([[548.6, 0.0, W / 2], [0.0, 548.6, H / 2], [0.0, 0.0, 1.0]])


def room(luminance: float) -> np.ndarray:
    """A flat grey wall at ``luminance`` (left half) beside one twice as bright (right half)."""
    image = np.full((H, W, 3), luminance, np.float32)
    image[:, W // 2:] *= 2
    return image


def rng(seed: int = 0) -> np.random.Generator:
    return np.random.default_rng(seed)


def test_auto_exposure_lengthens_the_frame_then_raises_the_gain_then_gives_up():
    sensor = SensorModel()
    day = sensor.auto_exposure(np.full((H, W, 3), DAYLIT_LUMINANCE, np.float32))
    assert day == pytest.approx((0.01, 1.0))                         # a daylit room: 1/100 s at base gain
    bright = sensor.auto_exposure(np.full((H, W, 3), 20 * DAYLIT_LUMINANCE, np.float32))
    assert bright[0] < day[0] and bright[1] == 1.0
    dusk = sensor.auto_exposure(np.full((H, W, 3), DAYLIT_LUMINANCE / 8, np.float32))
    assert dusk[0] == pytest.approx(sensor.exposure_max) and 1.0 < dusk[1] < sensor.gain_max
    night = sensor.auto_exposure(np.full((H, W, 3), DAYLIT_LUMINANCE / 500, np.float32))
    assert night == pytest.approx((sensor.exposure_max, sensor.gain_max))


def test_noise_grows_as_light_falls_and_the_darkest_room_stays_dark():
    sensor = SensorModel()
    noise, brightness = [], []
    for luminance in DAYLIT_LUMINANCE * np.array([2.0, 0.5, 0.1, 0.02, 0.002]):
        rgb, exposure = sensor.expose(room(luminance), rng())
        flat = rgb[:, 5:W // 2 - 5].astype(float)                    # one flat wall
        noise.append(flat.std())
        brightness.append(flat.mean())
    assert all(a < b for a, b in zip(noise[1:], noise[2:]))          # more gain, fewer electrons: noisier
    assert noise[-1] > 3 * noise[0]
    assert max(brightness[:4]) - min(brightness[:4]) < 10            # the AE holds the level while it can
    assert brightness[-1] < brightness[0] - 40                       # past its limits the room is dark


def test_the_same_seed_gives_the_same_image_and_another_seed_another():
    sensor, scene = SensorModel(), room(0.02)
    a, _ = sensor.expose(scene, rng(3))
    b, _ = sensor.expose(scene, rng(3))
    c, _ = sensor.expose(scene, rng(4))
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def edge_width(rgb: np.ndarray) -> int:
    """Columns of a row that are neither the dark nor the bright side's level (the blur's width)."""
    row = rgb[H // 2, :, 1].astype(float)
    lo, hi = np.median(row[:10]), np.median(row[-10:])
    return int(np.sum((row > lo + 0.2 * (hi - lo)) & (row < hi - 0.2 * (hi - lo))))


def test_turning_blurs_more_in_the_long_exposures_of_dim_light():
    sensor = SensorModel(read_noise=0.0, full_well=1e7, sensitivity=0.18 * 1e7 / (DAYLIT_LUMINANCE * 0.01))
    turning = (0.0, np.radians(25))
    widths = {}
    for name, luminance in (("day", 2.0), ("night", 0.05)):
        sharp, still = sensor.expose(room(luminance), rng(), K, (0.0, 0.0))
        blurred, exposure = sensor.expose(room(luminance), rng(), K, turning)
        assert edge_width(sharp) <= 1
        widths[name] = edge_width(blurred)
        assert exposure.time == still.time
    assert widths["night"] >= 5 > widths["day"]                      # 548 px/rad * 0.44 rad/s * 1/30 s = 8 px


def test_white_balance_neutralises_a_warm_lamp_within_its_limits():
    warm = room(0.3) * np.array([1.6, 1.0, 0.55], np.float32)
    balanced, exposure = SensorModel().expose(warm, rng())
    raw, _ = SensorModel(white_balance=False).expose(warm, rng())
    assert exposure.white_balance[0] < 1 < exposure.white_balance[2]
    means, raw_means = balanced.reshape(-1, 3).mean(0), raw.reshape(-1, 3).mean(0)
    assert abs(means[0] - means[2]) < 4 < raw_means[0] - raw_means[2]
    extreme = room(0.3) * np.array([1.0, 1.0, 0.05], np.float32)
    _, limited = SensorModel().expose(extreme, rng())
    assert limited.white_balance[2] == pytest.approx(2.0)            # a gain never beyond the limit


def test_highlights_clip_flat_at_full_well():
    scene = room(0.2)
    scene[:, :10] = 100.0                                            # a window in the sun
    rgb, _ = SensorModel().expose(scene, rng())
    window = rgb[:, :10]
    assert window.std() == 0 and window.min() > 200                  # clipped: no noise, no detail


def test_frames_tone_mapped_by_the_renderer_give_back_their_radiance():
    radiance = np.linspace(0.001, 3.0, H * W * 3, dtype=np.float32).reshape(H, W, 3)
    exposure = 1.0
    rgb = np.clip(srgb_encode(aces(radiance * exposure)) * 255 + 0.5, 0, 255).astype(np.uint8)
    back = radiance_from_rendered(rgb, exposure)
    mid = (radiance > 0.05) & (radiance < 2.0)
    assert np.allclose(back[mid], radiance[mid], rtol=0.05)


def test_the_realistic_profile_has_the_sensor_and_the_ideal_one_does_not(tmp_path):
    assert load_profile("giraff").camera.sensor == SensorModel(exposure_max=0.0333)
    assert load_profile("giraff_ideal").camera.sensor is None
    bad = tmp_path / "bad.yaml"
    bad.write_text((ROBOTS_DIR / "giraff.yaml").read_text().replace("exposure_min: 0.0001", "exposure_min: 0.5"))
    with pytest.raises(FileFieldError, match="camera.sensor"):
        load_profile(bad)
