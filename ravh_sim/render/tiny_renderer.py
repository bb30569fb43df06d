"""pybullet's TinyRenderer, the fallback where no GL context can be made (and the speed baseline).

pybullet draws the house's visual mirror (:mod:`tiny_scene`) with one directional light (the sun's
direction) and fixed shading; :mod:`tiny_lighting` then adds daylight colour and the switched-on lamps
per room, and the sky fills the background; what shines is the scene's light model's
(:func:`ravh_sim.look.lighting.scene_lights`).
TinyRenderer samples pixel corners and flips rows one pixel off, so its projection is built from K with
that sample offset and its pixels still match K exactly.
"""
from __future__ import annotations

import cv2
import numpy as np
import pybullet as pb

from ravh_sim.look.lighting import scene_lights
from ravh_sim.render.projection import projection_from_K, view_matrix
from ravh_sim.render.tiny_lighting import SUN_AMBIENT, SUN_DIFFUSE, Lighting
from ravh_sim.render.tiny_scene import TinyScene
from ravh_sim.render.views import Development, RenderedViews
from ravh_sim.world.scene import World

SAMPLE_OFFSET = (0.0, 1.0)        # where TinyRenderer samples pixel (u, v), measured against K


class TinyRenderer:
    """Renders one World for one camera model (K, size, clip planes) with pybullet's TinyRenderer."""

    def __init__(self, world: World, K: np.ndarray, width: int, height: int, near: float, far: float
                 ) -> None:
        self.world, self.width, self.height, self.near, self.far = world, width, height, near, far
        projection = projection_from_K(K, width, height, near, far, SAMPLE_OFFSET)
        self._projection = projection.T.ravel().tolist()          # column-major for pybullet
        self.lighting = Lighting(world, K, width, height)
        u, v = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
        self._rays = np.stack([u, v, np.ones_like(u)], axis=-1) @ np.linalg.inv(K).T   # optical frame
        self._rays /= np.linalg.norm(self._rays, axis=-1, keepdims=True)
        self.scene = TinyScene.of(world)

    def render(self, position: np.ndarray, rotation: np.ndarray, exposure: float | None = None,
               radiance: bool = False, development: Development | None = None) -> RenderedViews:
        """Views from an optical pose; ``exposure`` is ignored (the lighting pass sets the level), and
        so are ``radiance`` and ``development`` (no linear light: the camera develops the 8-bit image
        through its sensor model)."""
        self.scene.sync()
        scene = scene_lights(self.world.house, self.world.state)
        sun = scene.sun
        view = view_matrix(position, rotation)
        _, _, rgba, buffer, seg = pb.getCameraImage(
            self.width, self.height, view.T.ravel().tolist(), self._projection,
            physicsClientId=self.world.client, lightDirection=list(sun.direction),
            renderer=pb.ER_TINY_RENDERER, shadow=0, lightColor=[1.0, 1.0, 1.0],
            lightAmbientCoeff=SUN_AMBIENT, lightDiffuseCoeff=SUN_DIFFUSE, lightSpecularCoeff=0.0)
        rgba = np.asarray(rgba, np.uint8).reshape(self.height, self.width, 4)
        buffer = np.asarray(buffer, np.float32).reshape(self.height, self.width)
        seg = np.asarray(seg, np.int32).reshape(self.height, self.width)
        background = seg < 0
        depth = (self.far * self.near) / (self.far - (self.far - self.near) * buffer)
        depth[background | (buffer >= 1.0)] = np.nan
        instance = np.take(self.scene.lut, seg, mode="wrap")           # seg -1 -> the last entry, 0
        rgb = self.lighting.apply(cv2.cvtColor(rgba, cv2.COLOR_RGBA2RGB), depth, instance, rotation,
                                  position, sun, list(scene.lamps))
        if background.any():
            rgb[background] = self._outdoors(background, rotation, np.asarray(sun.sky, np.float32))
        return RenderedViews(rgb, depth, instance, background)

    def _outdoors(self, background: np.ndarray, rotation: np.ndarray, sky: np.ndarray) -> np.ndarray:
        """A cheap stand-in for the GL renderer's outdoors: the sky deepening from the horizon up and
        a darker lawn below it, hazing into the horizon (a window is not one flat colour)."""
        up = self._rays[background] @ np.asarray(rotation, np.float32)[2]      # sine of the elevation
        zenith = sky * np.array([0.7, 0.82, 1.0], np.float32)
        lawn = np.array([0.42, 0.55, 0.3], np.float32) * float(sky.mean())
        above = np.clip(up, 0.0, 1.0)[:, None] ** 0.5
        haze = np.exp(np.minimum(up, 0.0) * 12.0)[:, None]
        colour = np.where(up[:, None] >= 0.0, sky + (zenith - sky) * above, lawn + (sky - lawn) * 0.6 * haze)
        return np.clip(colour, 0.0, 255.0).astype(np.uint8)

    def release(self) -> None:
        """Nothing to free: the mirror's bodies live in the World's client and go with it."""
