"""Soft furnishings made here: pillows, duvets, cushions and throws (the catalogues have none).

Each is a library-style model (:mod:`ravh_sim.world.library`: a ``record`` in ``metadata``, a
``material`` and ``piece`` per face, texture coordinates) built to the box it is placed in, so the
renderer draws it like any library model (one fabric material in a seeded colour) and the World gives
it a collider of its triangles. Model ids are ``soft/<kind>/<variant>``: the variant picks the colour
and the small seeded irregularities of the shape, so a footprint's ``asset`` rebuilds the same model.

Shapes, in the model's frame (front along +x, up +z, centred on its box, as library models are):

- **Pillow**: a flattened rounded box, puffed: thickest in the middle, thin at its seams, with pointed
  corners, lying flat.
- **Duvet**: a thin slab with rounded edges and a quilted top, its head end (-x) turned back as a
  thicker band (the fold).
- **Cushion**: a plump rounded square standing up, leaning back (-x) against the sofa's back.
- **Throw**: a folded blanket, a thin slab with a rolled fold along its front edge.

Every shape lies inside its box and touches its bottom (the placement's rest test and the footprint's
box stay true).
"""
from __future__ import annotations

import functools
import math
import random

import numpy as np
import trimesh

from ravh_sim.world import library

KINDS = ("pillow", "duvet", "cushion", "throw")
VARIANTS = 8
PREFIX = "soft/"

# sRGB fabric colours: bed linen is mostly pale, sofa cushions and throws bolder
_BED_COLOURS = ((0.93, 0.92, 0.89), (0.95, 0.95, 0.95), (0.80, 0.82, 0.84), (0.70, 0.78, 0.86),
                (0.74, 0.80, 0.70), (0.86, 0.80, 0.70), (0.86, 0.72, 0.72), (0.33, 0.38, 0.50))
_SOFA_COLOURS = ((0.78, 0.60, 0.22), (0.22, 0.45, 0.48), (0.70, 0.38, 0.26), (0.55, 0.56, 0.57),
                 (0.20, 0.25, 0.40), (0.45, 0.47, 0.28), (0.90, 0.87, 0.80), (0.52, 0.18, 0.22))
_NAMES = {"pillow": "Pillow", "duvet": "Duvet", "cushion": "Cushion", "throw": "Throw"}
SIZES = {"pillow": (0.45, 0.7, 0.14), "duvet": (1.3, 1.5, 0.1), "cushion": (0.2, 0.45, 0.45),
         "throw": (0.5, 0.9, 0.07)}


def is_soft(model_id: str) -> bool:
    return model_id.startswith(PREFIX)


def _colour(kind: str, variant: int) -> tuple[float, float, float]:
    colours = _BED_COLOURS if kind in ("pillow", "duvet") else _SOFA_COLOURS
    return colours[variant % len(colours)]


def _record(kind: str, variant: int, size: tuple[float, float, float]) -> library.LibraryRecord:
    material = library.LibraryMaterial(name=f"fabric_{kind}", colour=_colour(kind, variant), roughness=0.92,
                                       kind="fabric")
    return library.LibraryRecord(id=f"{PREFIX}{kind}/{variant}", kind=f"Dressing/{kind}", name=_NAMES[kind],
                                 catalogue="ravh_sim", catalogue_id=f"{kind}-{variant}", creator="ravh_sim",
                                 licence="same as ravh_sim", size=size, triangles=0, materials=[material])


@functools.cache
def records(kind: str) -> tuple[library.LibraryRecord, ...]:
    """The soft models of a kind (``Dressing/pillow`` or ``pillow``), one per variant."""
    kind = kind.removeprefix("Dressing/")
    if kind not in KINDS:
        return ()
    return tuple(_record(kind, v, SIZES[kind]) for v in range(VARIANTS))


def _cube_sphere(n: int) -> tuple[np.ndarray, np.ndarray]:
    """A cube's surface, n x n quads a side, its shared corners merged: (vertices on [-1, 1]^3, faces)."""
    t = np.linspace(-1.0, 1.0, n + 1)
    uu, vv = np.meshgrid(t, t, indexing="ij")
    verts: list[np.ndarray] = []
    faces: list[np.ndarray] = []
    base = 0
    for axis in range(3):
        for sign in (-1.0, 1.0):
            p = np.empty((n + 1, n + 1, 3))
            a, b = [k for k in range(3) if k != axis]
            p[..., axis], p[..., a], p[..., b] = sign, uu, vv
            idx = np.arange((n + 1) * (n + 1)).reshape(n + 1, n + 1) + base
            q0, q1, q2, q3 = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
            faces.append(np.stack([q0, q1, q2], -1).reshape(-1, 3))
            faces.append(np.stack([q0, q2, q3], -1).reshape(-1, 3))
            verts.append(p.reshape(-1, 3))
            base += (n + 1) * (n + 1)
    vertices, faces_ = np.concatenate(verts), np.concatenate(faces)
    unique, inverse = np.unique(np.round(vertices, 6), axis=0, return_inverse=True)
    faces_ = inverse.reshape(-1)[faces_]
    # outward winding (the cube is convex about the origin)
    tri = unique[faces_]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flip = np.einsum("ij,ij->i", normal, tri.mean(axis=1)) < 0
    faces_[flip] = faces_[flip][:, ::-1]
    return unique, faces_


def _rounded(unit: np.ndarray, exponent: float) -> np.ndarray:
    """Cube points mapped through the sphere onto a superellipsoid (exponent 1: a sphere, towards 0: a
    box with rounder edges): a rounded box in [-1, 1]^3."""
    s = unit / np.linalg.norm(unit, axis=1, keepdims=True)
    return np.sign(s) * np.abs(s) ** exponent


def _shape(kind: str, variant: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices in [-1, 1]^3 before fitting, faces, uv) of a kind's shape."""
    rng = random.Random(f"soft/{kind}/{variant}")
    unit, faces = _cube_sphere(14 if kind in ("duvet", "throw") else 10)
    v = _rounded(unit, {"pillow": 0.45, "duvet": 0.22, "cushion": 0.5, "throw": 0.25}[kind])
    x, y, z = v[:, 0].copy(), v[:, 1].copy(), v[:, 2].copy()
    phase = rng.uniform(0, 2 * math.pi)
    if kind in ("pillow", "cushion"):
        # thick in the middle, thin at the seams; the thin axis is z for a pillow, x for a cushion
        a, b = (x, y) if kind == "pillow" else (y, z)
        puff = 0.35 + 0.65 * np.clip(1 - a * a, 0, 1) ** 0.6 * np.clip(1 - b * b, 0, 1) ** 0.6
        dent = 1 + 0.06 * np.sin(3.1 * a + phase) * np.cos(2.3 * b - phase)
        if kind == "pillow":
            z = z * puff * dent
        else:
            x = x * puff * dent
    elif kind == "duvet":
        top = z > 0
        quilt = 0.12 * np.abs(np.sin(math.pi * 2.5 * (x + 1))) * np.abs(np.sin(math.pi * 2.0 * (y + 1)))
        wave = 0.08 * np.sin(2.0 * y + phase) * np.sin(1.5 * x + 2 * phase)
        fold = np.where(x < -0.62, 0.9, 0.0) * np.clip((x + 1) / 0.1, 0, 1)   # the turned-back band
        z = np.where(top, z * (0.75 + quilt + wave) + fold, z)
    else:                                                                       # throw
        top = z > 0
        roll = 0.9 * np.clip((x - 0.7) / 0.3, 0, 1) ** 0.5                    # the fold along the front
        ripple = 0.15 * np.sin(4.0 * y + phase) * np.clip(1 - x * x, 0, 1)
        z = np.where(top, z * (0.6 + ripple) + roll, z)
    vertices = np.stack([x, y, z], axis=1)
    if kind == "cushion":                      # leaning back: the top towards -x
        lean = math.radians(rng.uniform(10.0, 16.0))
        c, s = math.cos(lean), math.sin(lean)
        vertices = vertices @ np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]]).T
    uv = np.stack([vertices[:, 1], vertices[:, 0] + vertices[:, 2]], axis=1)
    return vertices, faces, uv


@functools.lru_cache(maxsize=512)
def model(model_id: str, size: tuple[float, float, float]) -> trimesh.Trimesh:
    """The soft model ``soft/<kind>/<variant>`` built to fill a box of ``size`` (front, across, up),
    centred on it, as :func:`ravh_sim.world.library.fit` sets a library model."""
    kind, variant = model_id.removeprefix(PREFIX).split("/")
    vertices, faces, uv = _shape(kind, int(variant))
    box = np.asarray(size, np.float64)
    entry = _record(kind, int(variant), tuple(float(s) for s in box))   # type: ignore[arg-type]
    single = np.zeros(len(faces), np.int64)                             # one fabric, one piece
    return library.made_model(library.made_to_box(vertices, size), faces, uv * box[:2].max(), entry, single, single)
