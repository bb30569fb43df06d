"""The renderer a camera gets: the World's backend (``gl`` or ``tiny``, chosen once per process by
:mod:`backend`) built for one camera model. A new renderer is registered here."""
from __future__ import annotations

import numpy as np

from ravh_sim.render.gl_renderer import GLRenderer
from ravh_sim.render.tiny_renderer import TinyRenderer
from ravh_sim.render.views import Renderer
from ravh_sim.world.scene import World


def make_renderer(world: World, K: np.ndarray, width: int, height: int, near: float, far: float,
                  quality: str) -> Renderer:
    """A renderer of ``world`` for the pinhole camera K (``quality``: realistic | fast, GL only)."""
    if world.renderer == "gl":
        return GLRenderer(world, K, width, height, near, far, quality)
    return TinyRenderer(world, K, width, height, near, far)
