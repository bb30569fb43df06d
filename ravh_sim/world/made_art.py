"""Wall art made here: framed paintings, prints and photographs, their pictures painted by code (the
catalogues have no wall art, and a picture a detector has seen on the web would be a copy of someone's).

Like :mod:`ravh_sim.world.made_objects` (same interface: :func:`records`, :func:`is_made`,
:func:`model`), each is a library-style model built to the box it hangs in: its back on the wall at
-x, its front along +x, up +z. Model ids are ``made/art/<variant>``; the variant seeds the picture
(style, palette, composition) and its presentation, so a footprint's ``asset`` rebuilds the same model.

- **Pictures** (:func:`painting`): a landscape or a seascape in layers of hills under a sky with
  clouds (a painting, or a black-and-white photograph), a colour-field painting (soft-edged blocks on
  a ground), a geometric print (flat circles, arches and bars on paper), a botanical print (a stem
  with leaves on cream paper). Brush and paper grain are painted in; each is a PNG of
  :data:`ART_TEXELS` px in the asset cache (:func:`ravh_sim.files.cached_asset`), its path absolute,
  as a house model's textures are, and drawn by the renderers like any library texture.
- **Presentations**: a canvas on a stretcher (no frame), a thin black, white or oak frame with a white
  mat around a print or a photograph, a wide gilt frame around a painting.
"""
from __future__ import annotations

import functools
import random
import zlib
from pathlib import Path

import cv2
import numpy as np
import trimesh

from ravh_sim.files import cached_asset
from ravh_sim.world import library
from ravh_sim.world.made_objects import Parts

KIND = "wall_art"
PREFIX = "made/art/"
VARIANTS = 16
SIZE = (0.04, 0.8, 0.6)               # m: front (depth), across, up
ART_TEXELS = (512, 384)               # px: a picture's width and height (4:3, as most wall art is)
STYLES = ("landscape", "colour_field", "geometric", "seascape", "botanical", "photograph")
_SOURCE = Path(__file__).read_bytes()  # the painter's own code keys the cached pictures: a change repaints

# sRGB palettes of the styles
_SKIES = (((0.36, 0.55, 0.80), (0.86, 0.89, 0.90)),        # clear day: zenith, horizon
          ((0.33, 0.30, 0.52), (0.96, 0.64, 0.40)),        # sunset
          ((0.55, 0.60, 0.66), (0.85, 0.85, 0.83)))        # overcast
_HILLS = ((0.27, 0.38, 0.22), (0.40, 0.45, 0.25), (0.46, 0.50, 0.28), (0.50, 0.42, 0.30))    # greens, ochre
_FAR_HILLS = ((0.33, 0.38, 0.48), (0.40, 0.40, 0.46), (0.36, 0.42, 0.40))                     # blue-grey
_FIELDS = ((0.62, 0.16, 0.12), (0.86, 0.55, 0.16), (0.20, 0.28, 0.45), (0.15, 0.38, 0.36), (0.44, 0.20, 0.36),
           (0.90, 0.80, 0.55), (0.55, 0.47, 0.40), (0.70, 0.70, 0.66))          # no near-black: a dark
                                                                                # block in a frame is a TV
_PRINT = ((0.85, 0.62, 0.20), (0.78, 0.40, 0.27), (0.20, 0.40, 0.42), (0.16, 0.22, 0.36), (0.90, 0.72, 0.66),
          (0.55, 0.58, 0.40))
_PAPER = (0.94, 0.92, 0.86)
_FRAMES = {"black": ((0.05, 0.05, 0.05), "plain"), "white": ((0.92, 0.92, 0.90), "plain"),
           "oak": ((0.62, 0.45, 0.28), "wood"), "gilt": ((0.78, 0.60, 0.30), "metal")}
_MAT = (0.95, 0.94, 0.91)


def is_made(model_id: str) -> bool:
    return model_id.startswith(PREFIX)


def _style(variant: int) -> str:
    return STYLES[variant % len(STYLES)]


def _presentation(variant: int) -> tuple[str | None, bool]:
    """(frame colour name or None for a bare canvas, whether a mat surrounds the picture)."""
    rng = random.Random(f"art/{variant}/frame")
    style = _style(variant)
    if style in ("landscape", "seascape", "colour_field"):
        return rng.choice((None, None, "gilt", "oak", "black")), False
    return rng.choice(("black", "white", "oak")), True


def _main_colour(variant: int) -> tuple[float, float, float]:
    """A picture's overall colour, for what draws a model in its materials' colours (stand-ins)."""
    style = _style(variant)
    if style in ("landscape", "seascape"):
        sky, horizon = _SKIES[variant % len(_SKIES)]
        return tuple(float(v) for v in (np.asarray(sky) + np.asarray(horizon) + np.asarray(_HILLS[0])) / 3)  # type: ignore[return-value]
    if style == "photograph":
        return (0.5, 0.5, 0.5)
    if style == "colour_field":
        return _FIELDS[variant % len(_FIELDS)]
    return _PAPER


def _record(variant: int, size: tuple[float, float, float]) -> library.LibraryRecord:
    frame, _ = _presentation(variant)
    colour, kind = _FRAMES[frame] if frame else (_main_colour(variant), "plain")
    materials = [library.LibraryMaterial(name="frame", colour=colour, roughness=0.45, kind=kind),  # type: ignore[arg-type]
                 library.LibraryMaterial(name="mat", colour=_MAT, roughness=0.9, kind="plain"),
                 library.LibraryMaterial(name="picture", colour=_main_colour(variant), roughness=0.6, kind="textured",
                                         texture=str(painting(variant)))]
    return library.LibraryRecord(id=f"{PREFIX}{variant}", kind=f"Dressing/{KIND}", name="Wall art",
                                 catalogue="ravh_sim", catalogue_id=f"art-{variant}", creator="ravh_sim",
                                 licence="same as ravh_sim", size=size, triangles=0, materials=materials)


@functools.cache
def records(kind: str) -> tuple[library.LibraryRecord, ...]:
    """The wall art models (kind ``Dressing/wall_art`` or ``wall_art``), one per variant."""
    if kind.removeprefix("Dressing/") != KIND:
        return ()
    return tuple(_record(v, SIZE) for v in range(VARIANTS))


# --------------------------------------------------------------------------- pictures

def painting(variant: int) -> Path:
    """The PNG of a variant's picture in the asset cache (painted once per version of this module)."""
    def write(path: Path) -> None:
        if not cv2.imwrite(str(path), cv2.cvtColor(_paint(variant), cv2.COLOR_RGB2BGR)):
            raise OSError(f"could not write {path}")
    return cached_asset(_SOURCE + f"/art/{variant}/{ART_TEXELS}".encode(), ".png", write)


def _paint(variant: int) -> np.ndarray:
    """(H, W, 3) uint8 sRGB picture of a variant."""
    rng = np.random.default_rng(zlib.crc32(f"art/{variant}".encode()))
    w, h = ART_TEXELS
    style = _style(variant)
    if style in ("landscape", "seascape", "photograph"):
        image = _landscape(rng, w, h, variant, water=style == "seascape")
        if style == "photograph":          # black and white, with a photograph's contrast and no brush
            grey = image @ np.array([0.3, 0.59, 0.11])
            grey = np.clip((grey - grey.mean()) * 1.3 + 0.5, 0, 1)
            return (np.repeat(grey[..., None], 3, axis=2) * 255).astype(np.uint8)
    elif style == "colour_field":
        image = _colour_field(rng, w, h, variant)
    elif style == "geometric":
        image = _geometric(rng, w, h)
    else:
        image = _botanical(rng, w, h)
    grain = 0.06 if style in ("landscape", "seascape", "colour_field") else 0.025    # brush, or paper
    brush = _noise(rng, h, w, 6) - 0.5
    weave = 0.012 * np.sin(np.arange(w) * 2.2)[None, :] * np.sin(np.arange(h) * 2.2)[:, None]
    image = image * (1 + grain * brush + weave)[..., None]
    return (np.clip(image, 0, 1) * 255).astype(np.uint8)


def _noise(rng: np.random.Generator, h: int, w: int, cell: int) -> np.ndarray:
    """(h, w) smooth value noise in [0, 1] with features about ``cell`` px wide."""
    grid = rng.random((h // cell + 3, w // cell + 3)).astype(np.float32)
    big = cv2.resize(grid, ((w // cell + 3) * cell, (h // cell + 3) * cell), interpolation=cv2.INTER_CUBIC)
    return np.clip(big[cell:cell + h, cell:cell + w], 0, 1)


def _ridge(rng: np.random.Generator, w: int, base: float, amplitude: float) -> np.ndarray:
    """(w,) heights (share of the picture from its top) of a hill line: a few octaves of smooth noise."""
    line = np.zeros(w)
    for octave in range(4):
        cells = 3 * 2 ** octave
        knots = rng.random(cells + 1)
        line += np.interp(np.linspace(0, cells, w), np.arange(cells + 1), knots) / 2 ** octave
    return base - amplitude * (line - line.mean())


def _landscape(rng: np.random.Generator, w: int, h: int, variant: int, water: bool) -> np.ndarray:
    sky, horizon = (np.asarray(c) for c in _SKIES[variant % len(_SKIES)])
    rows = np.linspace(0, 1, h)[:, None, None]
    image = np.broadcast_to(sky + (horizon - sky) * np.clip(rows / 0.55, 0, 1), (h, w, 3)).copy()
    clouds = np.clip((_noise(rng, h, w, 40) * 0.7 + _noise(rng, h, w, 12) * 0.3 - 0.55) * 4, 0, 1)
    clouds *= np.clip(1 - rows[..., 0] / 0.45, 0, 1)
    image += (np.asarray((0.98, 0.97, 0.95)) - image) * clouds[..., None] * 0.85
    y = np.arange(h)[:, None] / h
    # hills from far (hazy, towards the horizon's colour) to near (a meadow), the sea's in front of two
    layers = 2 if water else 3
    for k in range(layers):
        base = (0.48, 0.58, 0.72)[k] + rng.uniform(-0.03, 0.03)
        hill = np.asarray(_FAR_HILLS[variant % len(_FAR_HILLS)] if k == 0 else _HILLS[(variant + k) % len(_HILLS)])
        colour = hill + (horizon - hill) * (0.45 if k == 0 else 0.0)
        below = y > _ridge(rng, w, base, 0.1 - 0.02 * k)[None, :]
        shade = 0.8 + 0.35 * _noise(rng, h, w, 30 - 8 * k) + 0.1 * (y - base)
        image[below] = (colour * shade[below][:, None])
    if not water:                      # a few trees on the near hills: dark crowns on short trunks
        for _ in range(int(rng.integers(2, 6))):
            x, top = int(rng.uniform(0.05, 0.95) * w), int(rng.uniform(0.55, 0.7) * h)
            size = int(rng.uniform(0.04, 0.08) * h)
            crown = np.asarray(_HILLS[0]) * 0.6
            cv2.rectangle(image, (x - 2, top), (x + 2, top + 2 * size), (0.25, 0.2, 0.15), -1)
            cv2.ellipse(image, (x, top), (size, int(size * 1.3)), 0, 0, 360, tuple(float(c) for c in crown), -1,
                        cv2.LINE_AA)
    if water:                          # the sea from the last hills down, a beach at the bottom
        sea = (y > 0.62)[:, 0]
        streaks = cv2.resize(_noise(rng, h, w // 8, 4), (w, h), interpolation=cv2.INTER_LINEAR)   # long waves
        image[sea] = (np.asarray((0.16, 0.34, 0.50)) * (0.8 + 0.4 * streaks)[..., None])[sea]
        beach = y > _ridge(rng, w, 0.86, 0.05)[None, :]
        image[beach] = np.asarray((0.86, 0.78, 0.60)) * (0.9 + 0.2 * _noise(rng, h, w, 5))[beach][:, None]
    return image


def _colour_field(rng: np.random.Generator, w: int, h: int, variant: int) -> np.ndarray:
    ground = np.asarray(_FIELDS[variant % len(_FIELDS)])
    image = np.broadcast_to(ground, (h, w, 3)).copy()
    blocks = rng.integers(2, 4)
    edges = np.sort(rng.uniform(0.08, 0.92, blocks * 2 - 1))
    top = 0.08
    for k in range(blocks):
        bottom = edges[2 * k] if 2 * k < len(edges) else 0.92
        block = np.zeros((h, w), np.float32)
        block[int(top * h):int(bottom * h), int(0.1 * w):int(0.9 * w)] = 1
        mask = cv2.GaussianBlur(block, (0, 0), 6) * (0.85 + 0.3 * _noise(rng, h, w, 20))
        colour = np.asarray(_FIELDS[(variant + 2 + 3 * k) % len(_FIELDS)])
        image += (colour - image) * np.clip(mask, 0, 1)[..., None]
        top = bottom + rng.uniform(0.03, 0.07)
        if top > 0.85:
            break
    return image


def _geometric(rng: np.random.Generator, w: int, h: int) -> np.ndarray:
    image = np.broadcast_to(np.asarray(_PAPER), (h, w, 3)).copy()
    colours = [np.asarray(c) for c in rng.permutation(np.asarray(_PRINT))]
    for k, colour in enumerate(colours[:int(rng.integers(3, 6))]):
        canvas = np.zeros((h, w), np.uint8)
        cx, cy, r = int(rng.uniform(0.2, 0.8) * w), int(rng.uniform(0.25, 0.75) * h), int(rng.uniform(0.12, 0.3) * h)
        shape = k % 3
        if shape == 0:
            cv2.circle(canvas, (cx, cy), r, 1, -1, cv2.LINE_AA)
        elif shape == 1:                   # an arch: a half disc on a bar
            cv2.ellipse(canvas, (cx, cy), (r, r), 180, 0, 180, 1, -1, cv2.LINE_AA)
            cv2.rectangle(canvas, (cx - r, cy), (cx + r, cy + r), 1, -1)
        else:
            cv2.rectangle(canvas, (cx - r // 3, cy - r), (cx + r // 3, cy + r), 1, -1)
        image[canvas > 0] = colour
    return image


def _botanical(rng: np.random.Generator, w: int, h: int) -> np.ndarray:
    image = np.broadcast_to(np.asarray(_PAPER), (h, w, 3)).copy()
    canvas = np.zeros((h, w, 3), np.float32)
    x0, bend = w / 2 + rng.uniform(-0.1, 0.1) * w, rng.uniform(-0.15, 0.15) * w
    stem = [(int(x0 + bend * t * t), int(h * (0.9 - 0.8 * t))) for t in np.linspace(0, 1, 30)]
    greens = ((0.20, 0.36, 0.20), (0.32, 0.48, 0.26), (0.18, 0.30, 0.24))
    cv2.polylines(canvas, [np.asarray(stem, np.int32)], False, (0.25, 0.30, 0.18), 3, cv2.LINE_AA)
    for k in range(4, 28, 3):
        x, y = stem[k]
        side = 1 if k % 2 else -1
        length = int(h * rng.uniform(0.08, 0.14) * (1.2 - k / 40))
        angle = float(np.degrees(np.arctan2(-0.6, side)) + rng.uniform(-15, 15))
        centre = (int(x + side * length * 0.8), int(y - length * 0.5))
        cv2.ellipse(canvas, centre, (length, max(length // 3, 3)), angle, 0, 360, greens[k % 3], -1, cv2.LINE_AA)
    drawn = canvas.sum(axis=2) > 0
    image[drawn] = canvas[drawn]
    image[int(0.93 * h):int(0.935 * h), int(0.35 * w):int(0.65 * w)] = (0.3, 0.3, 0.3)     # its caption
    return image


# --------------------------------------------------------------------------- the model

@functools.lru_cache(maxsize=256)
def model(model_id: str, size: tuple[float, float, float]) -> trimesh.Trimesh:
    """The wall art ``made/art/<variant>`` built to fill a box of ``size`` (front, across, up), centred
    on it: frame bars, a mat and the picture (recessed behind them), or a bare canvas."""
    variant = int(model_id.removeprefix(PREFIX))
    d, w, h = size
    frame, has_mat = _presentation(variant)
    parts = Parts()
    back, front = -d / 2, d / 2
    rim = 0.0
    if frame is not None:
        rim = min(0.07 if frame == "gilt" else 0.025, 0.1 * min(w, h))
        _border(parts, back, front, w / 2, h / 2, rim, 0)
    if has_mat:
        mat = 0.12 * min(w, h)
        _border(parts, back, front - 0.006, w / 2 - rim, h / 2 - rim, mat, 1)
        rim += mat
    picture_front = front - (0.01 if frame is not None else 0.0)
    before = sum(len(v) for v in parts.vertices)
    parts.box((back, -w / 2 + rim, -h / 2 + rim), (picture_front, w / 2 - rim, h / 2 - rim), 2)
    vertices = np.vstack(parts.vertices)
    fitted = library.made_to_box(vertices, size)
    uv = fitted[:, 1:3].copy()          # metres (untextured parts do not read them); the picture's: 0..1
    picture = fitted[before:, 1:3]
    lo, hi = picture.min(axis=0), picture.max(axis=0)
    uv[before:] = (picture - lo) / np.maximum(hi - lo, 1e-9)
    entry = records(KIND)[variant].model_copy(update={"size": (float(d), float(w), float(h))})
    return library.made_model(fitted, np.vstack(parts.faces), uv, entry, np.concatenate(parts.materials),
                              np.concatenate(parts.pieces))


def _border(parts: Parts, back: float, front: float, half_w: float, half_h: float, width: float,
            material: int) -> None:
    """Four bars around a rectangle's edge (a frame or a mat), ``width`` wide, from back to front."""
    parts.box((back, -half_w, half_h - width), (front, half_w, half_h), material)
    parts.box((back, -half_w, -half_h), (front, half_w, -half_h + width), material)
    parts.box((back, -half_w, -half_h + width), (front, -half_w + width, half_h - width), material)
    parts.box((back, half_w - width, -half_h + width), (front, half_w, half_h - width), material)
