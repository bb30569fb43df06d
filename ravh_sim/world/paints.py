"""Wall and floor paints: named plain colours and procedurally generated textures.

A paint is a string: a plain colour name (``"white"``), a hex colour (``"#a0b0c0"``) or a texture name
(``"wood"``). Textures are generated here from a fixed seed (no image files to ship) and tile every
:data:`TEXTURE_TILE_M` metres on walls and floors.
"""
from __future__ import annotations

import re
from functools import cache

import numpy as np

PLAIN_COLOURS: dict[str, tuple[int, int, int]] = {
    "white": (240, 238, 232), "cream": (238, 228, 200), "light_grey": (200, 200, 198),
    "grey": (150, 150, 150), "beige": (214, 196, 166), "sand": (226, 205, 160),
    "sky": (170, 200, 226), "mint": (180, 220, 196), "sage": (160, 182, 150),
    "peach": (240, 196, 170), "rose": (222, 170, 176), "lavender": (196, 184, 220),
    "terracotta": (190, 110, 80), "navy": (50, 62, 100), "olive": (128, 128, 80),
    "charcoal": (64, 64, 68), "oak": (176, 132, 84), "walnut": (110, 74, 48),
}
TEXTURES = ("wood", "parquet", "tiles", "marble", "brick", "fabric", "concrete", "carpet")
TEXTURE_TILE_M = 1.0
TEXTURE_PX = 128

# What "default" paint means, by room type: walls are off-white, floors follow the room's use.
_DEFAULT_FLOOR = {"Bathroom": "tiles", "Kitchen": "tiles", "UtilityRoom": "concrete",
                  "Balcony": "concrete", "KitchenLivingRoom": "parquet"}
DEFAULT_WALL = "white"
DEFAULT_FLOOR = "wood"

_HEX = re.compile(r"^#[0-9a-fA-F]{6}$")


def default_paint(room_type: str, surface: str) -> str:
    return DEFAULT_WALL if surface == "walls" else _DEFAULT_FLOOR.get(room_type, DEFAULT_FLOOR)


def all_paints() -> list[str]:
    """Every named paint, the set ``random`` draws from."""
    return list(PLAIN_COLOURS) + list(TEXTURES)


def is_paint(value: str) -> bool:
    return value in PLAIN_COLOURS or value in TEXTURES or bool(_HEX.match(value))


def is_texture(paint: str) -> bool:
    return paint in TEXTURES


def plain_rgb(paint: str) -> tuple[int, int, int]:
    """The RGB of a plain paint (named or hex)."""
    if paint in PLAIN_COLOURS:
        return PLAIN_COLOURS[paint]
    return (int(paint[1:3], 16), int(paint[3:5], 16), int(paint[5:7], 16))


@cache
def texture_rgb(name: str) -> np.ndarray:
    """A seamless (TEXTURE_PX, TEXTURE_PX, 3) uint8 RGB image of texture ``name``."""
    rng = np.random.default_rng(TEXTURES.index(name) + 1)
    n = TEXTURE_PX
    y, x = np.mgrid[0:n, 0:n] / n
    noise = _smooth_noise(rng, n)
    if name == "wood":
        grain = 0.5 + 0.5 * np.sin(2 * np.pi * (8 * y + 1.5 * noise))
        img = _mix((150, 104, 62), (196, 150, 100), grain)
    elif name == "parquet":
        plank = ((np.floor(x * 8) + np.floor(y * 2) * 3) % 4) / 3
        img = _mix((128, 86, 50), (186, 140, 92), 0.6 * plank + 0.4 * noise)
        img[(np.mod(x * 8, 1) < 0.04) | (np.mod(y * 2, 1) < 0.02)] = (90, 60, 36)
    elif name == "tiles":
        img = _mix((226, 226, 222), (244, 244, 240), noise)
        img[(np.mod(x * 4, 1) < 0.04) | (np.mod(y * 4, 1) < 0.04)] = (150, 150, 150)
    elif name == "marble":
        vein = np.abs(np.sin(2 * np.pi * (x + 2 * y + 2.5 * noise)))
        img = _mix((170, 170, 176), (240, 240, 238), vein ** 0.3)
    elif name == "brick":
        row = np.floor(y * 8)
        offset = (row % 2) * 0.125
        img = _mix((150, 66, 48), (184, 92, 66), noise)
        img[(np.mod(y * 8, 1) < 0.1) | (np.mod((x + offset) * 4, 1) < 0.05)] = (200, 196, 186)
    elif name == "fabric":
        weave = (np.sin(2 * np.pi * x * 32) * np.sin(2 * np.pi * y * 32) > 0)
        img = _mix((90, 110, 140), (120, 140, 170), 0.5 * weave + 0.5 * noise)
    elif name == "concrete":
        img = _mix((140, 140, 136), (176, 176, 170), 0.7 * noise + 0.3 * rng.random((n, n)))
    else:  # carpet
        img = _mix((120, 60, 60), (150, 84, 80), 0.5 * noise + 0.5 * rng.random((n, n)))
    return img


def _smooth_noise(rng: np.random.Generator, n: int, cells: int = 8) -> np.ndarray:
    """Tileable value noise in [0, 1]: a coarse random lattice upsampled with wrap-around."""
    coarse = rng.random((cells, cells))
    t = np.arange(n) * cells / n
    i0 = np.floor(t).astype(int)
    f = t - i0
    i1 = (i0 + 1) % cells
    rows = coarse[i0][:, i0] * (1 - f)[None, :] + coarse[i0][:, i1] * f[None, :]
    rows1 = coarse[i1][:, i0] * (1 - f)[None, :] + coarse[i1][:, i1] * f[None, :]
    return rows * (1 - f)[:, None] + rows1 * f[:, None]


def _mix(a: tuple[int, int, int], b: tuple[int, int, int], t: np.ndarray) -> np.ndarray:
    t = np.clip(t, 0, 1)[..., None]
    return (np.array(a) * (1 - t) + np.array(b) * t).astype(np.uint8)
