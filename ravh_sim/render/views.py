"""What every renderer gives a camera, and the one method a renderer has.

A renderer draws RGB, depth and instance ids of one World from one optical pose (rotation columns:
x right, y down, z forward, in the house frame). The camera (ravh_sim.sensors.camera) only sees
this protocol, so a new renderer is a new module behind :func:`ravh_sim.render.renderers.make_renderer`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np


@dataclass
class RenderedViews:
    rgb: np.ndarray                   # (H, W, 3) uint8, lit and tone-mapped sRGB
    depth: np.ndarray                 # (H, W) float32 z-depth in metres, NaN = nothing
    instance: np.ndarray              # (H, W) uint16, 0 = nothing
    background: np.ndarray            # (H, W) bool: the outdoors (sky, ground), no body
    radiance: np.ndarray | None = None  # (H, W, 3) float32 linear light before exposure, when asked for


class Renderer(Protocol):
    def render(self, position: np.ndarray, rotation: np.ndarray, exposure: float | None = None,
               radiance: bool = False) -> RenderedViews:
        """The views from an optical pose; ``exposure`` fixes the exposure where the renderer meters;
        ``radiance``: also the linear light a camera sensor integrates, where the renderer has it."""
        ...

    def release(self) -> None:
        """Free what the renderer holds (GPU objects); it is not used afterwards."""
        ...
