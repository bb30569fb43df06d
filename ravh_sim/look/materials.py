"""Physically based materials for every palette colour and paint, as the GPU reads them.

Why: procedural models colour each face with a named palette colour ("wood_dark", "fabric_blue",
"chrome"...) and rooms are painted with named paints ("parquet", "tiles", "#a0b0c0"). The name already
says what the surface is made of, so the material follows from it: base colour, roughness, metalness
and a procedural pattern (wood grain, weave, grout...) that the fragment shader evaluates in the
surface's own coordinates. No image files for those: every pattern is a function of position and a
seed. Furniture-library models bring their own MTL materials: textured ones sample their texture,
the others get the procedural material their name says they are (:func:`library_material`).

The table is uploaded as a small float texture: one row of :data:`TEXELS` texels per material.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import cv2
import numpy as np

from ravh_sim.world import library, paints
from ravh_sim.world.library import Detail, LibraryMaterial, is_glass
from ravh_sim.world.palette import PALETTE

RGB = tuple[float, float, float]

# Pattern ids, mirrored by the PATTERN_* constants in shaders/scene.frag.
PATTERNS = ("plain", "plaster", "wood", "parquet", "tiles", "marble", "fabric", "leather", "carpet",
            "brick", "concrete", "metal", "glass", "mirror", "screen", "ceramic", "foliage", "emissive",
            "textured")
PATTERN = {name: i for i, name in enumerate(PATTERNS)}
TEXELS = 4                                   # texels per material row (see pack)
LIBRARY_TEXELS = 256                         # side of every library texture in the texture array
DATASET_TEXELS = 512
"""Largest side of the texture array at the dataset level of detail: the largest texture in use,
rounded up to a power of two, at most this. The library's dataset textures go up to 1024 texels
(``textures/full``), but one layer costs its side squared in every copy (a house draws ~30 textures:
512 is 24 MB an array, 1024 would be 94 MB, over what the 600 MB a node may use leaves); of the
catalogues' textures 1 is larger than 600 texels, 86 are 512."""
METAL_REFLECTANCE = 0.6                      # linear reflectance of a library model's steel and chrome


@dataclass(frozen=True)
class Material:
    colour: RGB                              # linear base colour
    pattern: str = "plain"
    roughness: float = 0.6
    metalness: float = 0.0
    scale: float = 1.0                       # pattern repeats per metre (wood: rings per metre)
    variation: float = 0.15                  # how much the pattern varies the base colour
    accent: RGB = (0.0, 0.0, 0.0)            # second colour: grout, veins, dark grain, mortar
    bump: float = 0.3                        # strength of the pattern's normal detail
    layer: int = -1                          # the texture array layer of a textured material


def srgb_to_linear(rgb: RGB) -> RGB:
    c = np.asarray(rgb, np.float64)
    r, g, b = (float(v) for v in np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4))
    return r, g, b


def srgb8_to_linear(rgb: tuple[int, int, int]) -> RGB:
    """An 8-bit sRGB colour (a paint, the sky) as a linear colour."""
    r, g, b = rgb
    return srgb_to_linear((r / 255, g / 255, b / 255))


def _scaled(rgb: RGB, k: float) -> RGB:
    r, g, b = rgb
    return min(1.0, r * k), min(1.0, g * k), min(1.0, b * k)


def palette_material(name: str, srgb: RGB) -> Material:
    """The material a palette colour stands for, from its name."""
    c = srgb_to_linear(srgb)
    if name.startswith("wood"):
        return Material(c, "wood", 0.55, scale=9.0, variation=0.35, accent=_scaled(c, 0.55), bump=0.25)
    if name.startswith("fabric") or name in ("mattress", "pillow"):
        return Material(c, "fabric", 0.92, scale=260.0, variation=0.18, accent=_scaled(c, 0.7), bump=0.5)
    if name.startswith("leather"):
        return Material(c, "leather", 0.42, scale=120.0, variation=0.2, accent=_scaled(c, 0.6), bump=0.35)
    if name in ("metal", "steel", "chrome", "brass"):
        rough = {"chrome": 0.12, "brass": 0.3}.get(name, 0.32)
        return Material(c, "metal", rough, metalness=1.0, scale=400.0, variation=0.08, bump=0.1)
    if name in ("glass", "glass_dark"):
        return Material(c, "glass", 0.05, scale=1.0, variation=0.0)
    if name == "mirror":
        return Material(c, "mirror", 0.03, metalness=1.0, variation=0.0)
    if name == "screen":
        return Material(c, "screen", 0.12, variation=0.0)
    if name.startswith("ceramic") or name in ("white",):
        return Material(c, "ceramic", 0.18 if name.startswith("ceramic") else 0.45, variation=0.03,
                        scale=3.0)
    if name in ("marble", "granite"):
        return Material(c, "marble", 0.2, scale=2.5, variation=0.3, accent=_scaled(c, 0.45))
    if name.startswith("plant") or name.startswith("fruit"):
        return Material(c, "foliage", 0.6, scale=25.0, variation=0.35, accent=_scaled(c, 0.5), bump=0.4)
    if name in ("bulb", "lamp_shade", "led"):
        return Material(c, "emissive", 0.7, variation=0.05, scale=40.0)
    if name.startswith("black") or name.startswith("charcoal") or name.startswith("grey"):
        return Material(c, "plain", 0.5, variation=0.06, scale=6.0)      # plastics and paints
    return Material(c, "plain", 0.6, variation=0.08, scale=5.0)


def paint_material(paint: str, surface: str) -> Material:
    """A wall, floor or ceiling paint: a plain colour is plaster on walls and ceilings and a matt
    finish on floors; texture paints are the material they name."""
    if paints.is_texture(paint):
        return _TEXTURE_PAINTS[paint]
    c = srgb8_to_linear(paints.plain_rgb(paint))
    if surface == "floor":
        return Material(c, "concrete", 0.7, scale=1.5, variation=0.12, accent=_scaled(c, 0.8), bump=0.2)
    return Material(c, "plaster", 0.85, scale=3.0, variation=0.05, accent=_scaled(c, 0.9), bump=0.1)


_TEXTURE_PAINTS: dict[str, Material] = {
    "wood": Material(srgb_to_linear((0.62, 0.44, 0.27)), "parquet", 0.45, scale=1.0, variation=0.3,
                     accent=srgb_to_linear((0.36, 0.23, 0.13)), bump=0.12),
    "parquet": Material(srgb_to_linear((0.72, 0.54, 0.34)), "parquet", 0.4, scale=2.0, variation=0.35,
                        accent=srgb_to_linear((0.45, 0.30, 0.17)), bump=0.12),
    "tiles": Material(srgb_to_linear((0.88, 0.87, 0.84)), "tiles", 0.2, scale=3.333, variation=0.06,
                      accent=srgb_to_linear((0.62, 0.6, 0.56)), bump=0.6),
    "marble": Material(srgb_to_linear((0.9, 0.89, 0.86)), "marble", 0.15, scale=1.2, variation=0.3,
                       accent=srgb_to_linear((0.45, 0.45, 0.47))),
    "brick": Material(srgb_to_linear((0.66, 0.34, 0.24)), "brick", 0.85, scale=1.0, variation=0.25,
                      accent=srgb_to_linear((0.78, 0.75, 0.7)), bump=0.8),
    "fabric": Material(srgb_to_linear((0.62, 0.6, 0.66)), "fabric", 0.9, scale=200.0, variation=0.15,
                       accent=srgb_to_linear((0.45, 0.43, 0.5)), bump=0.5),
    "concrete": Material(srgb_to_linear((0.62, 0.61, 0.58)), "concrete", 0.8, scale=1.5, variation=0.2,
                         accent=srgb_to_linear((0.48, 0.47, 0.45)), bump=0.3),
    "carpet": Material(srgb_to_linear((0.55, 0.5, 0.44)), "carpet", 0.97, scale=400.0, variation=0.2,
                       accent=srgb_to_linear((0.4, 0.36, 0.31)), bump=0.5),
}


NOISE_TEXELS = 64
NOISE_LATTICES = (8, 16, 32, 64)            # lattice cells per tile of each channel (octave)
NOISE_SEED = 20240611


def noise_volume() -> np.ndarray:
    """(N, N, N, 4) uint8 tiling value noise, one octave per channel: random lattice values
    smoothly interpolated (smoothstep), periodic so the texture repeats without seams."""
    rng = np.random.default_rng(NOISE_SEED)
    n = NOISE_TEXELS
    out = np.empty((n, n, n, 4), np.uint8)
    for channel, cells in enumerate(NOISE_LATTICES):
        lattice = rng.random((cells, cells, cells))
        t = np.arange(n) * cells / n
        i0 = np.floor(t).astype(int)
        f = t - i0
        f = f * f * (3 - 2 * f)
        i1 = (i0 + 1) % cells
        # separable periodic interpolation along z, y, x
        v = lattice[i0] * (1 - f)[:, None, None] + lattice[i1] * f[:, None, None]
        v = v[:, i0] * (1 - f)[None, :, None] + v[:, i1] * f[None, :, None]
        v = v[:, :, i0] * (1 - f)[None, None, :] + v[:, :, i1] * f[None, None, :]
        out[..., channel] = np.round(v * 255).astype(np.uint8)
    return out


# What a library material's kind (ravh_sim.world.library.material_kind) is drawn as: the palette
# colour name whose material family it belongs to.
_LIBRARY_FAMILY = {"wood": "wood", "fabric": "fabric", "leather": "leather", "metal": "metal",
                   "mirror": "mirror", "screen": "screen", "ceramic": "ceramic", "marble": "marble",
                   "plant": "plant", "emissive": "lamp_shade", "plain": "plain"}


def library_material(material: LibraryMaterial, layer: int) -> Material:
    """A library model's MTL material: textured ones sample their texture (layer of the texture
    array); the others are the procedural material of their kind in their MTL colour. Furniture
    glass (:func:`ravh_sim.world.library.is_glass`) is drawn as dark, glossy glass with nothing seen
    through it: opaque in the depth and instance images, as it is to the laser (the library's one
    decision about glass; clear panes are not in the library)."""
    colour = srgb_to_linear(material.colour)
    if material.kind == "textured":
        return Material((1.0, 1.0, 1.0), "textured", material.roughness, variation=0.0, bump=0.35, layer=layer)
    if is_glass(material):
        return Material(_scaled(colour, 0.3), "ceramic", 0.05, variation=0.0)
    family = palette_material(_LIBRARY_FAMILY[material.kind], material.colour)
    if material.kind == "metal":          # MTL greys of steel are dark; polished steel reflects ~60 %
        lightest = max(family.colour)
        return replace(family, colour=_scaled(family.colour, max(1.0, METAL_REFLECTANCE / max(lightest, 1e-3))),
                       roughness=max(family.roughness, 0.4))
    roughness = family.roughness if material.kind != "plain" else material.roughness
    return replace(family, roughness=roughness)


class MaterialTable:
    """Palette materials at fixed indices, then one slot per distinct (paint, surface) and library
    material in use; library textures get a layer each of one texture array."""

    def __init__(self, detail: Detail = "live") -> None:
        self.detail = detail                        # which level of the library's textures (library.DETAILS)
        self.materials: list[Material] = [palette_material(n, tuple(PALETTE.rgb[i]))
                                          for i, n in enumerate(PALETTE.names)]
        self._paint_slots: dict[tuple[str, str], int] = {}
        self._library_slots: dict[tuple[str, int], int] = {}
        self.textures: list[str] = []                # library texture files, by layer

    def library(self, model_id: str, index: int, material: LibraryMaterial) -> int:
        """Material index of a library model's material ``index``."""
        key = (model_id, index)
        if key not in self._library_slots:
            layer = -1
            if material.texture is not None:
                if material.texture not in self.textures:
                    self.textures.append(material.texture)
                layer = self.textures.index(material.texture)
            self._library_slots[key] = len(self.materials)
            self.materials.append(library_material(material, layer))
        return self._library_slots[key]

    def paint(self, paint: str, surface: str) -> int:
        """Material index of a paint on a surface ('walls', 'floor' or 'ceiling')."""
        key = (paint, surface)
        if key not in self._paint_slots:
            self._paint_slots[key] = len(self.materials)
            self.materials.append(paint_material(paint, "floor" if surface == "floor" else "walls"))
        return self._paint_slots[key]

    def pack(self) -> np.ndarray:
        """(len, TEXELS, 4) float32: [colour, pattern], [roughness, metalness, scale, variation],
        [accent, bump], [texture layer, 0, 0, 0]."""
        rows = [[(*m.colour, PATTERN[m.pattern]), (m.roughness, m.metalness, m.scale, m.variation),
                 (*m.accent, m.bump), (m.layer, 0.0, 0.0, 0.0)] for m in self.materials]
        return np.asarray(rows, np.float32)

    def texture_layers(self) -> np.ndarray:
        """(layers, LIBRARY_TEXELS, LIBRARY_TEXELS, 3) uint8 RGB of the library textures in use (one
        white layer when there are none), each resized to the array's size, bottom row first (GL's
        and OBJ's texture coordinates count v from the bottom). The array's side is LIBRARY_TEXELS, or
        at the dataset level the largest texture's side rounded up to a power of two (at most
        DATASET_TEXELS)."""
        if not self.textures:
            return np.full((1, LIBRARY_TEXELS, LIBRARY_TEXELS, 3), 255, np.uint8)
        side = LIBRARY_TEXELS
        if self.detail == "dataset":
            largest = max(max(_texture_bgr(name, self.detail).shape[:2]) for name in self.textures)
            side = int(min(DATASET_TEXELS, max(LIBRARY_TEXELS, 2 ** int(np.ceil(np.log2(largest))))))
        out = np.empty((len(self.textures), side, side, 3), np.uint8)      # filled in place: no stacked copies
        for layer, name in enumerate(self.textures):
            out[layer] = _layer(_texture_bgr(name, self.detail), side)[::-1]
        return out


def _texture_bgr(name: str, detail: Detail) -> np.ndarray:
    path = library.texture_file(name, detail)
    bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if bgr is None:
        raise FileNotFoundError(f"furniture texture {path} is missing or unreadable")
    return bgr


def _layer(bgr: np.ndarray, side: int) -> np.ndarray:
    interpolation = cv2.INTER_AREA if max(bgr.shape[:2]) >= side else cv2.INTER_CUBIC
    return cv2.cvtColor(cv2.resize(bgr, (side, side), interpolation=interpolation), cv2.COLOR_BGR2RGB)
