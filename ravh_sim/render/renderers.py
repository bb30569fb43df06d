"""The renderer a camera gets: a backend (``auto``, ``gl`` or ``tiny``, resolved by :mod:`backend`) built
for one World and one camera model. A new renderer is registered here.

Each backend's module (and its GL context or pybullet client) is imported when a camera first asks for
it, so what only describes a camera (a robot profile, the sensor suite) loads no renderer.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ravh_sim.render.views import Renderer

if TYPE_CHECKING:
    from ravh_sim.world.scene import World


def make_renderer(world: World, backend: str, K: np.ndarray, width: int, height: int, near: float, far: float,
                  quality: str) -> Renderer:
    """A renderer of ``world`` for the pinhole camera K: ``backend`` a resolved one (gl | tiny, see
    :func:`ravh_sim.render.backend.resolve_backend`), ``quality`` realistic | fast (GL only)."""
    if backend == "gl":
        from ravh_sim.render.gl_renderer import GLRenderer
        return GLRenderer(world, K, width, height, near, far, quality)
    from ravh_sim.render.tiny_renderer import TinyRenderer
    return TinyRenderer(world, K, width, height, near, far)
