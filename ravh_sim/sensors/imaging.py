"""What a real camera does to a perfect image: exposure, sensor noise, motion blur, lens distortion and JPEG.

Each effect is a plain function (or, for distortion, a precomputed remap) over numpy images, applied
by the smart camera in the physical order: blur during the exposure, then the lens, then sensor
noise, then compression. Randomness comes from the caller's generator, so images are reproducible.

:class:`SensorModel` is the camera's sensor as a whole (the realistic profile's; off in the ideal
camera): it takes linear scene radiance and makes the 8-bit image a real camera would, so a dim room
costs what it costs a real one (longer exposure and its motion blur, gain and its noise, or a dark
image when both are at their limits) instead of being lifted to daylight for free.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from ravh_sim.render.views import Exposure

MAX_BLUR_SAMPLES = 9
DEPTH_SCALE = 1000.0                   # depth PNG units per metre (16-bit millimetres)
DEPTH_MAX_M = 65.535                   # deepest representable depth; farther is stored as 0


def encode_jpeg(rgb: np.ndarray, quality: int) -> bytes:
    """JPEG bytes of an RGB image (what a compressed image topic carries)."""
    bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)
    ok, data = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:
        raise RuntimeError("JPEG encoding failed")
    return data.tobytes()


def jpeg_roundtrip(rgb: np.ndarray, quality: int) -> np.ndarray:
    """The RGB image after JPEG compression at ``quality`` (its block artefacts included)."""
    bgr = cv2.imdecode(np.frombuffer(encode_jpeg(rgb, quality), np.uint8), cv2.IMREAD_COLOR)
    if bgr is None:
        raise RuntimeError("JPEG decoding failed")
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)


def pixel_noise(rgb: np.ndarray, sigma: float, rng: np.random.Generator) -> np.ndarray:
    """Additive Gaussian sensor noise of ``sigma`` 8-bit levels."""
    noisy = rgb.astype(np.float32) + rng.standard_normal(rgb.shape, dtype=np.float32) * sigma
    return np.clip(noisy + 0.5, 0, 255).astype(np.uint8)


def depth_noise(depth: np.ndarray, coeff: float, rng: np.random.Generator) -> np.ndarray:
    """Gaussian depth noise growing with distance squared, sigma = coeff * z^2 (structured light, ToF)."""
    return depth + rng.standard_normal(depth.shape, dtype=np.float32) * (coeff * depth * depth)


def motion_blur(rgb: np.ndarray, K: np.ndarray, linear: float, angular: float, exposure: float,
                distance: float) -> np.ndarray:
    """Blur from the robot moving during the exposure (the ideal camera's fixed ``exposure``; a
    sensor model blurs over the exposure its auto-exposure chose). See :func:`sweep`."""
    blurred = _swept(rgb, sweep(K, (linear, angular), exposure, distance), K)
    return rgb if blurred is None else np.clip(blurred + 0.5, 0, 255).astype(np.uint8)


def sweep(K: np.ndarray, velocity: tuple[float, float], exposure: float, distance: float
          ) -> tuple[float, float, int]:
    """(sideways shift px, zoom, samples) of the motion blur over ``exposure`` s.

    Turning at ``velocity[1]`` rad/s sweeps the image sideways by fx * w * exposure pixels; driving at
    ``velocity[0]`` m/s zooms it about the principal point by v * exposure / ``distance`` (the
    scene's typical depth). The image is the mean of ``samples`` copies along that sweep, centred on
    the pose, one a pixel of the sweep's reach (at most MAX_BLUR_SAMPLES; under 2: no blur).
    """
    fx, cx, cy = K[0, 0], K[0, 2], K[1, 2]
    shift = float(fx * velocity[1] * exposure)
    zoom = float(velocity[0] * exposure / max(distance, 0.1))
    reach = max(abs(shift), abs(zoom) * math.hypot(cx, cy))
    return shift, zoom, min(MAX_BLUR_SAMPLES, int(math.ceil(reach)) + 1)


def _swept(image: np.ndarray, swept: tuple[float, float, int], K: np.ndarray) -> np.ndarray | None:
    """float32 mean of ``image`` along a :func:`sweep` (None: under a pixel, no blur)."""
    shift, zoom, samples = swept
    if samples < 2:
        return None
    cx, cy = K[0, 2], K[1, 2]
    acc = np.zeros(image.shape, np.float32)
    h, w = image.shape[:2]
    for t in np.linspace(-0.5, 0.5, samples):
        scale = 1.0 + zoom * t
        warp = np.array([[scale, 0.0, (1 - scale) * cx + shift * t],
                         [0.0, scale, (1 - scale) * cy]], np.float32)
        acc += cv2.warpAffine(image, warp, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return acc / samples


# ---------------------------------------------------------------------------- the sensor

DAYLIT_LUMINANCE = 1.45       # mean linear luminance of a daylit room in the renderer's light units (house 20
                              # at its station by day; windows as area lights of the bright outdoors)
LUMA = np.array([0.2126, 0.7152, 0.0722], np.float32)       # Rec. 709 luminance of linear RGB


@dataclass(frozen=True)
class SensorModel:
    """A camera sensor and its image pipeline. Units: radiance in the renderer's linear light units,
    charge in electrons (e-).

    Auto-exposure meters the mean luminance and asks for ``target`` of full scale: it lengthens the
    exposure up to ``exposure_max`` first (longer frames blur), then raises the gain up to ``gain_max``;
    past both the image stays dark. The robot's motion blurs the image over the exposure time. The
    pixel collects radiance * sensitivity * time electrons, with photon shot noise (Poisson, sqrt of
    the charge) and ``read_noise``, clips at ``full_well``; the gain amplifies signal and noise alike
    and the ADC clips and quantises to ``adc_bits``. So noise relative to signal grows as light falls
    (fewer electrons, more gain). White balance is grey-world, limited to ``white_balance_limit``; the
    output is the renderer's ACES curve and sRGB encoding. The default sensitivity makes a daylit room
    a 1/100 s exposure at gain 1.

    :meth:`expose` is the reference in numpy; the GL renderer runs the same steps in its shaders
    (render/shaders/sensor_*.frag) with this model's decisions (:meth:`exposure_for`,
    :meth:`balance_gains`, :meth:`sweep`), so a frame never leaves the device before it is an image.
    """
    exposure_min: float = 1e-4
    exposure_max: float = 1 / 30
    gain_max: float = 16.0
    full_well: float = 6000.0
    read_noise: float = 3.0
    sensitivity: float = 0.18 * 6000.0 / (DAYLIT_LUMINANCE * 0.01)     # e- per second per unit radiance
    target: float = 0.18
    adc_bits: int = 10
    white_balance: bool = True
    white_balance_limit: float = 2.0
    reference_exposure: float = 1.0     # the renderer's fixed exposure of the frames fed to from_rendered

    @property
    def levels(self) -> float:
        """The ADC's largest code."""
        return float(2 ** self.adc_bits - 1)

    @property
    def output_gain(self) -> float:
        """Full-scale signal to the tone curve's input: the AE's target lands on the renderer's mid-grey."""
        return 0.2 / self.target

    def exposure_for(self, metered: float) -> tuple[float, float]:
        """(exposure time s, gain) for a frame whose mean linear luminance is ``metered``."""
        wanted = self.target * self.full_well / (max(metered, 1e-9) * self.sensitivity)     # time * gain
        time = float(np.clip(wanted, self.exposure_min, self.exposure_max))
        return time, float(np.clip(wanted / time, 1.0, self.gain_max))

    def auto_exposure(self, radiance: np.ndarray) -> tuple[float, float]:
        """(exposure time s, gain) for a (H, W, 3) linear radiance image."""
        return self.exposure_for(float(np.mean(radiance @ LUMA)))

    def balance_gains(self, means: np.ndarray) -> tuple[float, float, float]:
        """Grey-world gains for an image of per-channel means ``means`` (ones when balance is off)."""
        if not self.white_balance:
            return 1.0, 1.0, 1.0
        means = np.maximum(np.asarray(means, np.float64), 1e-6)
        red, green, blue = np.clip(means[1] / means, 1 / self.white_balance_limit, self.white_balance_limit)
        return float(red), float(green), float(blue)

    def sweep(self, K: np.ndarray, velocity: tuple[float, float], time: float, distance: float
              ) -> tuple[float, float, int]:
        """The motion blur over an exposure of ``time`` s (module :func:`sweep`)."""
        return sweep(K, velocity, time, distance)

    def expose(self, radiance: np.ndarray, rng: np.random.Generator, K: np.ndarray | None = None,
               velocity: tuple[float, float] = (0.0, 0.0), distance: float = 2.0) -> tuple[np.ndarray, Exposure]:
        """The 8-bit RGB image of linear ``radiance`` (H, W, 3), and the exposure chosen; ``velocity``
        (v m/s, w rad/s) blurs over the exposure time (needs ``K``, the scene at ``distance`` m)."""
        radiance = np.asarray(radiance, np.float32)
        time, gain = self.auto_exposure(radiance)
        if K is not None and any(velocity):
            blurred = _swept(radiance, self.sweep(K, velocity, time, distance), K)
            radiance = radiance if blurred is None else blurred
        electrons = np.maximum(radiance, 0) * np.float32(self.sensitivity * time)
        electrons = rng.poisson(electrons).astype(np.float32)                      # photon shot noise
        electrons += rng.standard_normal(electrons.shape, dtype=np.float32) * np.float32(self.read_noise)
        signal = np.clip(electrons, 0, self.full_well) * np.float32(gain / self.full_well)
        signal = np.round(np.clip(signal, 0, 1) * self.levels) / np.float32(self.levels)
        means = signal.reshape(-1, 3).mean(axis=0)
        balance = self.balance_gains(means)
        balanced = np.minimum(signal * np.asarray(balance, np.float32), 1.0)
        out = srgb_encode(aces(balanced * np.float32(self.output_gain)))
        rgb = np.clip(out * 255 + 0.5, 0, 255).astype(np.uint8)
        return rgb, Exposure(time, gain, float(np.mean(means)), balance)

    def from_rendered(self, rgb: np.ndarray, rng: np.random.Generator, K: np.ndarray | None = None,
                      velocity: tuple[float, float] = (0.0, 0.0), distance: float = 2.0
                      ) -> tuple[np.ndarray, Exposure]:
        """:meth:`expose` for an 8-bit frame the renderer tone-mapped at ``reference_exposure`` (its
        curve undone first); an HDR frame from the renderer would skip that step and its 8-bit steps."""
        return self.expose(radiance_from_rendered(rgb, self.reference_exposure), rng, K, velocity, distance)


def aces(x: np.ndarray) -> np.ndarray:
    """The renderer's filmic curve (Narkowicz's ACES fit), linear in, display-linear [0, 1] out."""
    return np.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)


def aces_inverse(y: np.ndarray) -> np.ndarray:
    """The linear value :func:`aces` maps to ``y`` (the curve's positive root; y capped below its top)."""
    y = np.clip(np.asarray(y, np.float64), 0.0, 0.99)
    a, b, c = 2.43 * y - 2.51, 0.59 * y - 0.03, 0.14 * y
    return ((-b - np.sqrt(b * b - 4 * a * c)) / (2 * a)).astype(np.float32)


def srgb_encode(c: np.ndarray) -> np.ndarray:
    c = np.clip(c, 0.0, 1.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1 / 2.4) - 0.055)


def srgb_decode(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, np.float32)
    return np.where(v <= 0.04045, v / 12.92, np.power((v + 0.055) / 1.055, 2.4)).astype(np.float32)


def radiance_from_rendered(rgb: np.ndarray, exposure: float) -> np.ndarray:
    """Linear radiance (H, W, 3) float32 of an 8-bit frame tone-mapped by the renderer at ``exposure``."""
    return aces_inverse(srgb_decode(rgb.astype(np.float32) / 255.0)) / np.float32(exposure)


class LensDistortion:
    """Plumb-bob (Brown-Conrady) distortion k1 k2 p1 p2 k3 applied to undistorted renders.

    For each pixel of the distorted image, cv2.undistortPoints gives where that ray lands in the
    ideal pinhole image; the maps are computed once and each frame is one cv2.remap.
    """

    def __init__(self, K: np.ndarray, coefficients: tuple[float, ...], width: int, height: int) -> None:
        self.coefficients = tuple(float(c) for c in coefficients)
        us, vs = np.meshgrid(np.arange(width, dtype=np.float32), np.arange(height, dtype=np.float32))
        pixels = np.stack([us.ravel(), vs.ravel()], axis=1)[:, None, :]
        ideal = cv2.undistortPoints(pixels, K, np.asarray(self.coefficients), P=K).reshape(height, width, 2)
        self.map_x = np.ascontiguousarray(ideal[..., 0])
        self.map_y = np.ascontiguousarray(ideal[..., 1])

    def apply(self, image: np.ndarray, nearest: bool = False, fill: float = 0) -> np.ndarray:
        """Distort one image; ``nearest`` for depth and ids, which must not be blended across edges."""
        interpolation = cv2.INTER_NEAREST if nearest else cv2.INTER_LINEAR
        return cv2.remap(image, self.map_x, self.map_y, interpolation, borderMode=cv2.BORDER_CONSTANT,
                         borderValue=fill)


def depth_to_png(metres: np.ndarray) -> np.ndarray:
    """Float metres (NaN/inf/<=0 invalid) -> uint16 millimetres, 0 = invalid (±0.5 mm rounding)."""
    mm = np.round(np.asarray(metres, np.float64) * DEPTH_SCALE)
    valid = np.isfinite(mm) & (mm > 0) & (mm <= DEPTH_MAX_M * DEPTH_SCALE)
    return np.where(valid, mm, 0).astype(np.uint16)


def depth_from_png(mm: np.ndarray) -> np.ndarray:
    """uint16 millimetres -> float32 metres, NaN where 0 (the REP 118 convention of the topic)."""
    metres = mm.astype(np.float32) / np.float32(DEPTH_SCALE)
    metres[mm == 0] = np.nan
    return metres
