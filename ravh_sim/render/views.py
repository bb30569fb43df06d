"""What every renderer gives a camera, and the one method a renderer has.

A renderer draws RGB, depth and instance ids of one World from one optical pose (rotation columns:
x right, y down, z forward, in the house frame). The camera (ravh_sim.sensors.camera) only sees
this protocol, so a new renderer is a new module behind :func:`ravh_sim.render.renderers.make_renderer`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

DEPTH_SAMPLE_STRIDE = 4               # typical_depth looks at every 4th pixel of every 4th row


@dataclass(frozen=True)
class Exposure:
    """What a camera sensor's auto-exposure chose for one frame, and what came of it."""
    time: float               # s
    gain: float               # analogue gain (1 = base ISO)
    signal: float             # mean raw signal (before white balance) in full-scale units: the AE's
                              # target when reachable, less past its limits
    white_balance: tuple[float, float, float]    # per-channel gains applied


class Sensor(Protocol):
    """What a renderer needs of a camera sensor (ravh_sim.sensors.imaging.SensorModel, which holds the
    model and its numpy reference) to develop a frame where the frame is drawn: the per-pixel steps run
    there, every decision (exposure, white balance, blur) is the sensor's own."""

    @property
    def full_well(self) -> float: ...
    @property
    def read_noise(self) -> float: ...
    @property
    def sensitivity(self) -> float: ...
    @property
    def levels(self) -> float: ...
    @property
    def output_gain(self) -> float: ...

    def exposure_for(self, metered: float) -> tuple[float, float]:
        """(exposure time s, gain) for a frame of mean linear luminance ``metered``."""
        ...

    def balance_gains(self, means: np.ndarray) -> tuple[float, float, float]:
        """Per-channel white-balance gains for an image of per-channel means ``means``."""
        ...

    def sweep(self, K: np.ndarray, velocity: tuple[float, float], time: float, distance: float
              ) -> tuple[float, float, int]:
        """(sideways shift px, zoom, samples) of the motion blur over an exposure of ``time`` s."""
        ...


@dataclass(frozen=True)
class Development:
    """A request to develop a frame through a camera sensor: the sensor, the generator its noise
    comes from (the camera's seeded stream for this frame) and the camera's motion (v m/s, w rad/s)."""
    sensor: Sensor
    rng: np.random.Generator
    velocity: tuple[float, float] = (0.0, 0.0)


@dataclass
class RenderedViews:
    rgb: np.ndarray                   # (H, W, 3) uint8, lit and tone-mapped sRGB (developed, with ``exposure``)
    depth: np.ndarray                 # (H, W) float32 z-depth in metres, NaN = nothing
    instance: np.ndarray              # (H, W) uint16, 0 = nothing
    background: np.ndarray            # (H, W) bool: the outdoors (sky, ground), no body
    radiance: np.ndarray | None = None  # (H, W, 3) float32 linear light before exposure, when asked for
    exposure: Exposure | None = None  # the sensor's choice where the renderer developed the frame


def typical_depth(depth: np.ndarray, default: float) -> float:
    """How far a view's scene is, what a forward motion's blur scales with: the median depth over a
    regular sample of the pixels (``default`` where nothing was hit)."""
    sample = depth[::DEPTH_SAMPLE_STRIDE, ::DEPTH_SAMPLE_STRIDE]
    finite = sample[np.isfinite(sample)]
    return float(np.median(finite)) if finite.size else default


class Renderer(Protocol):
    def render(self, position: np.ndarray, rotation: np.ndarray, exposure: float | None = None,
               radiance: bool = False, development: Development | None = None) -> RenderedViews:
        """The views from an optical pose; ``exposure`` fixes the exposure where the renderer meters;
        ``radiance``: also the linear light a camera sensor integrates, where the renderer has it;
        ``development``: develop the colour image through that sensor where the renderer can (then
        ``RenderedViews.exposure`` says what it chose; else it is None and the camera develops it)."""
        ...

    def release(self) -> None:
        """Free what the renderer holds (GPU objects); it is not used afterwards."""
        ...
