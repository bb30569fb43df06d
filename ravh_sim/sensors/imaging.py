"""What a real camera does to a perfect image: motion blur, lens distortion, noise and JPEG.

Each effect is a plain function (or, for distortion, a precomputed remap) over numpy images, applied
by the smart camera in the physical order: blur during the exposure, then the lens, then sensor
noise, then compression. Randomness comes from the caller's generator, so images are reproducible.
"""
from __future__ import annotations

import math

import cv2
import numpy as np

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
    """Blur from the robot moving during the exposure.

    Turning at ``angular`` rad/s sweeps the image sideways by fx * angular * exposure pixels; driving
    at ``linear`` m/s zooms it about the principal point by linear * exposure / ``distance`` (the
    scene's typical depth). The image is the mean of copies along that sweep, centred on the pose.
    """
    fx, cx, cy = K[0, 0], K[0, 2], K[1, 2]
    shift = fx * angular * exposure
    zoom = linear * exposure / max(distance, 0.1)
    reach = max(abs(shift), abs(zoom) * math.hypot(cx, cy))
    samples = min(MAX_BLUR_SAMPLES, int(math.ceil(reach)) + 1)
    if samples < 2:
        return rgb
    acc = np.zeros(rgb.shape, np.float32)
    h, w = rgb.shape[:2]
    for t in np.linspace(-0.5, 0.5, samples):
        scale = 1.0 + zoom * t
        warp = np.array([[scale, 0.0, (1 - scale) * cx + shift * t],
                         [0.0, scale, (1 - scale) * cy]], np.float32)
        acc += cv2.warpAffine(rgb, warp, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return np.clip(acc / samples + 0.5, 0, 255).astype(np.uint8)


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
