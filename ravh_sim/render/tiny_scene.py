"""The house as pybullet's TinyRenderer draws it: visual-only bodies in the World's client.

The World's bodies collide and carry no visual shape; this mirror gives each of them one (a palette-
coloured OBJ for objects, library models as their palette stand-ins, textured OBJs for the structure
in its paint), made from :attr:`World.visuals` and kept in step with the world when the change report
says its geometry moved (doors, model swaps, paint). A visual-only body has no collision shape, so
rays and contacts never meet it; its segmentation id maps to the instance it mirrors. pybullet draws a
body that has no visual shape as its collision shapes, so the world's own bodies (and the ground) are
made fully transparent here, which its renderer skips. A World has one mirror (:meth:`TinyScene.of`),
shared by all its TinyRenderers: a second copy of the house would fight the first for every pixel.
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass

import cv2
import numpy as np
import pybullet as pb

from ravh_sim.files import cached_asset
from ravh_sim.look.changes import ChangeWatch
from ravh_sim.world import paints
from ravh_sim.world.library import palette_stand_in
from ravh_sim.world.mesh import colours, write_palette_obj
from ravh_sim.world.palette import PALETTE
from ravh_sim.world.scene import Visual, World
from ravh_sim.world.structure import write_textured_obj


@dataclass
class _Mirror:
    body: int                         # the visual-only body
    instance: int                     # the instance id it shows
    look: tuple[str, tuple[float, ...]] | None = None    # (texture name, rgba) applied


class TinyScene:
    """Visual bodies mirroring one World's bodies, for pybullet's renderer."""

    _of_world: weakref.WeakKeyDictionary[World, TinyScene] = weakref.WeakKeyDictionary()

    @classmethod
    def of(cls, world: World) -> TinyScene:
        """The mirror of ``world``, made by the first TinyRenderer that asks."""
        if world not in cls._of_world:
            cls._of_world[world] = cls(world)
        return cls._of_world[world]

    def __init__(self, world: World) -> None:
        self.world, self.client = world, world.client
        self._textures: dict[str, int] = {}
        for name in ("palette", "white", *paints.TEXTURES):    # once, up front: repaints cost no file I/O
            self._texture(name)
        self._mirrors: dict[int, _Mirror] = {}                   # world body -> its mirror
        self._changes = ChangeWatch(world.state)
        self.lut = np.zeros(1, np.uint16)
        self._hide(world.ground)
        self.sync()

    def sync(self) -> None:
        """Bring the mirror up to date with the world (cheap when nothing moved)."""
        if not self._changes.poll().geometry:
            return
        c = self.client
        looks = []
        for inst in self.world.instances:
            visual = self.world.visuals.get(inst.body)
            if visual is None:
                continue
            mirror = self._mirrors.get(inst.body)
            if mirror is None:
                mirror = self._mirrors[inst.body] = _Mirror(self._visual_body(visual, inst.body), inst.id)
                self._hide(inst.body)
            look = self._look(visual)
            if look != mirror.look:
                looks.append((mirror, look))
        for world_body, mirror in self._mirrors.items():      # parked and open leaves follow the world
            position, orientation = pb.getBasePositionAndOrientation(world_body, physicsClientId=c)
            pb.resetBasePositionAndOrientation(mirror.body, position, orientation, physicsClientId=c)
        # The EGL plugin drops visual changes made while later bodies are still being created, so
        # looks are applied once every body exists.
        for mirror, (texture, rgba) in looks:
            pb.changeVisualShape(mirror.body, -1, textureUniqueId=self._texture(texture), rgbaColor=list(rgba),
                                 physicsClientId=c)
            mirror.look = (texture, rgba)
        top = max(pb.getBodyUniqueId(i, physicsClientId=c) for i in range(pb.getNumBodies(physicsClientId=c)))
        self.lut = np.zeros(top + 2, np.uint16)                 # the last entry: segmentation -1 (nothing)
        for mirror in self._mirrors.values():
            self.lut[mirror.body] = mirror.instance

    def _visual_body(self, visual: Visual, world_body: int) -> int:
        """A visual-only body showing ``visual`` where ``world_body`` stands."""
        if visual.structure is not None:
            mesh = visual.structure
            key = np.concatenate([mesh.vertices.ravel(), mesh.visual.uv.ravel()]).round(4).tobytes()
            path = cached_asset(key, ".obj", lambda p: write_textured_obj(mesh, p))
        else:
            drawn = visual.mesh if visual.model is None else palette_stand_in(visual.model)
            path = cached_asset(_palette_key(drawn), ".obj", lambda p: write_palette_obj(drawn, p, PALETTE))
        shape = pb.createVisualShape(pb.GEOM_MESH, fileName=str(path), physicsClientId=self.client)
        position, orientation = pb.getBasePositionAndOrientation(world_body, physicsClientId=self.client)
        return pb.createMultiBody(0, -1, shape, basePosition=position, baseOrientation=orientation,
                                  physicsClientId=self.client)

    def _hide(self, body: int) -> None:
        """Leave ``body`` out of pybullet's images (the stand-in visuals it made of its collision shapes)."""
        for shape in pb.getVisualShapeData(body, physicsClientId=self.client):
            pb.changeVisualShape(body, shape[1], rgbaColor=[1.0, 1.0, 1.0, 0.0], physicsClientId=self.client)

    @staticmethod
    def _look(visual: Visual) -> tuple[str, tuple[float, ...]]:
        """(texture name, rgba) of a body: the palette for objects, its paint for structure."""
        if visual.structure is None:
            return "palette", (1.0, 1.0, 1.0, 1.0)
        if paints.is_texture(visual.paint):
            return visual.paint, (1.0, 1.0, 1.0, 1.0)
        return "white", (*(c / 255 for c in paints.plain_rgb(visual.paint)), 1.0)

    def _texture(self, name: str) -> int:
        """pybullet texture id for 'palette', 'white' or a paint texture name (loaded once)."""
        if name not in self._textures:
            if name == "palette":
                path = cached_asset(PALETTE.image_rgb().tobytes(), ".png", PALETTE.write_texture)
            elif name == "white":
                path = cached_asset(b"white", ".png",
                                    lambda p: cv2.imwrite(str(p), np.full((4, 4, 3), 255, np.uint8)))
            else:
                rgb = paints.texture_rgb(name)
                path = cached_asset(rgb.tobytes(), ".png",
                                    lambda p: cv2.imwrite(str(p), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)))
            self._textures[name] = pb.loadTexture(str(path), physicsClientId=self.client)
        return self._textures[name]


def _palette_key(mesh) -> bytes:
    """A content key for a palette mesh."""
    return (np.asarray(mesh.vertices).round(4).tobytes() + np.asarray(mesh.faces).tobytes()
            + np.asarray(colours(mesh)).tobytes())
