"""Named material colours laid out on one small palette texture.

Why: pybullet renders at most one texture per body, and per-vertex colours
are not available for meshes loaded from OBJ files.  So every procedural
model is coloured by pointing each face's UV coordinates at the centre of a
uniformly coloured cell in one shared texture.  All faces of a triangle share
the same UV, so the sampled colour is exactly the cell colour whatever the
filtering or mip level.

The cells form a single row: a UV cell centre then has ``v = 0.5``, which
samples the same colour whether a renderer flips the image vertically or not
(OBJ measures ``v`` from the bottom, image files store the top row first).
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

RGB = tuple[float, float, float]

CELL_TEXELS = 16
"""Edge length of one colour cell in texels (>= 8 so filtering cannot bleed)."""

CELL_COUNT = 64
"""Cells in the texture row; a power of two keeps the texture GPU-friendly."""

COLOURS: tuple[tuple[str, RGB], ...] = (
    # woods
    ('wood_light', (0.80, 0.66, 0.47)),
    ('wood_medium', (0.60, 0.42, 0.26)),
    ('wood_dark', (0.36, 0.23, 0.14)),
    ('wood_red', (0.55, 0.28, 0.18)),
    ('wood_grey', (0.62, 0.58, 0.52)),
    # neutrals
    ('white', (0.95, 0.95, 0.94)),
    ('off_white', (0.91, 0.89, 0.83)),
    ('cream', (0.93, 0.86, 0.70)),
    ('grey_light', (0.78, 0.78, 0.77)),
    ('grey', (0.55, 0.55, 0.55)),
    ('grey_dark', (0.32, 0.32, 0.33)),
    ('charcoal', (0.18, 0.18, 0.19)),
    ('black', (0.06, 0.06, 0.06)),
    # metals and glass
    ('metal', (0.58, 0.59, 0.61)),
    ('chrome', (0.83, 0.85, 0.88)),
    ('steel', (0.70, 0.72, 0.74)),
    ('brass', (0.78, 0.62, 0.30)),
    ('glass', (0.66, 0.80, 0.86)),
    ('glass_dark', (0.16, 0.20, 0.24)),
    ('mirror', (0.82, 0.88, 0.92)),
    ('screen', (0.04, 0.05, 0.07)),
    # upholstery and textiles
    ('fabric_beige', (0.78, 0.70, 0.58)),
    ('fabric_grey', (0.50, 0.51, 0.53)),
    ('fabric_blue', (0.30, 0.42, 0.62)),
    ('fabric_navy', (0.15, 0.20, 0.35)),
    ('fabric_red', (0.62, 0.16, 0.15)),
    ('fabric_green', (0.33, 0.47, 0.30)),
    ('fabric_mustard', (0.80, 0.62, 0.20)),
    ('fabric_teal', (0.17, 0.47, 0.48)),
    ('fabric_pink', (0.86, 0.62, 0.64)),
    ('leather_brown', (0.42, 0.24, 0.13)),
    ('leather_black', (0.12, 0.11, 0.11)),
    ('mattress', (0.94, 0.93, 0.89)),
    ('pillow', (0.98, 0.98, 0.96)),
    # hard finishes
    ('ceramic', (0.97, 0.97, 0.96)),
    ('ceramic_shade', (0.80, 0.83, 0.85)),
    ('marble', (0.88, 0.87, 0.84)),
    ('granite', (0.24, 0.23, 0.23)),
    ('terracotta', (0.72, 0.38, 0.24)),
    ('ceramic_blue', (0.22, 0.38, 0.66)),
    # plants and food
    ('plant_green', (0.24, 0.52, 0.20)),
    ('plant_dark', (0.11, 0.34, 0.14)),
    ('soil', (0.28, 0.19, 0.11)),
    ('fruit_orange', (0.95, 0.55, 0.10)),
    ('fruit_red', (0.78, 0.10, 0.10)),
    ('fruit_green', (0.55, 0.75, 0.20)),
    ('coffee', (0.25, 0.14, 0.07)),
    # lighting
    ('lamp_shade', (0.96, 0.91, 0.78)),
    ('bulb', (1.00, 0.95, 0.62)),
    ('led', (0.20, 0.85, 0.35)),
    # art
    ('art_red', (0.85, 0.15, 0.12)),
    ('art_yellow', (0.97, 0.82, 0.15)),
    ('art_blue', (0.12, 0.30, 0.75)),
    ('art_green', (0.25, 0.60, 0.30)),
    ('sky', (0.56, 0.76, 0.93)),
    ('sea', (0.10, 0.40, 0.60)),
    ('sand', (0.90, 0.80, 0.58)),
    ('sun', (0.98, 0.70, 0.20)),
)

PADDING: RGB = (1.0, 0.0, 1.0)
"""Magenta for unused cells, so a wrong UV is obvious in a render."""


class Palette:
    """An ordered list of named colours and its texture layout."""

    def __init__(self, colours: tuple[tuple[str, RGB], ...] = COLOURS,
                 cell_count: int = CELL_COUNT, cell_texels: int = CELL_TEXELS) -> None:
        if len(colours) > cell_count:
            raise ValueError(f'{len(colours)} colours do not fit {cell_count} cells')
        self.names = tuple(name for name, _ in colours)
        self.rgb = np.array([rgb for _, rgb in colours], dtype=np.float64)
        self._index = {name: i for i, name in enumerate(self.names)}
        self.cell_count = cell_count
        self.cell_texels = cell_texels

    def __len__(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        """Palette index of a colour name (KeyError for unknown names)."""
        return self._index[name]

    def uv(self, index: int) -> tuple[float, float]:
        """Texture coordinate of the centre of a colour's cell (v from the bottom)."""
        if not 0 <= index < len(self):
            raise IndexError(f'palette index {index} out of range')
        return (index + 0.5) / self.cell_count, 0.5

    def image_rgb(self) -> np.ndarray:
        """The texture as an (H, W, 3) uint8 RGB array."""
        cells = np.tile(np.array(PADDING), (self.cell_count, 1))
        cells[:len(self)] = self.rgb
        row = np.repeat(np.round(cells * 255).astype(np.uint8), self.cell_texels, axis=0)
        return np.repeat(row[np.newaxis], self.cell_texels, axis=0)

    def write_texture(self, path: str | Path) -> None:
        """Write the palette texture as a PNG file."""
        bgr = np.ascontiguousarray(self.image_rgb()[:, :, ::-1])
        if not cv2.imwrite(str(path), bgr):
            raise OSError(f'could not write palette texture {path}')


PALETTE = Palette()
