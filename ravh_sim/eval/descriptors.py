"""Whole-image descriptors for appearance-based localization: a baseline and the plug-in interface.

A descriptor is any Python callable ``image -> vector``: it receives an (H, W, 3) uint8 RGB image
and returns a 1-D array (any length, the same for every image). Vectors are compared by cosine
similarity (they are L2-normalised here, so a callable need not do it). To evaluate your own
(NetVLAD, a CNN's pooled features...), pass ``--descriptor package.module:function`` to
``ravh eval localization`` or a callable to :func:`~ravh_sim.eval.table4.run_table4`.

The baseline, :func:`gradient_grid`, needs no learned weights: a HOG/GIST-style layout of edge
orientations. The image is made grey and small (:data:`SIZE`), its gradients are binned into
:data:`ORIENTATIONS` unsigned orientations over a :data:`CELLS` grid of cells, weighted by
magnitude; each cell's histogram is normalised on its own (so a darker or brighter region counts
the same: lighting changes brightness far more than edge directions) and square-rooted (Hellinger
kernel, so no single strong edge dominates).
"""
from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable

import cv2
import numpy as np

from ravh_sim.errors import UserError

Descriptor = Callable[[np.ndarray], np.ndarray]

SIZE = (128, 96)                   # px (w, h) the image is reduced to
CELLS = (8, 6)                     # cells across, down
ORIENTATIONS = 9                   # unsigned orientation bins over 180 degrees
CELL_EPS = 1e-3                    # keeps flat (textureless) cells near zero after normalising


def gradient_grid(image: np.ndarray) -> np.ndarray:
    """The baseline descriptor (see the module): CELLS * ORIENTATIONS values."""
    grey = cv2.cvtColor(np.ascontiguousarray(image, np.uint8), cv2.COLOR_RGB2GRAY)
    small = cv2.resize(grey, SIZE, interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0
    gx = cv2.Sobel(small, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(small, cv2.CV_32F, 0, 1, ksize=3)
    magnitude = np.hypot(gx, gy)
    orientation = np.mod(np.arctan2(gy, gx), np.pi)
    bins = np.minimum((orientation / np.pi * ORIENTATIONS).astype(np.int64), ORIENTATIONS - 1)
    cols, rows = CELLS
    h, w = small.shape
    cell = (np.arange(h)[:, None] * rows // h) * cols + (np.arange(w)[None, :] * cols // w)
    hist: np.ndarray = np.bincount((cell * ORIENTATIONS + bins).ravel(), weights=magnitude.ravel(),
                       minlength=rows * cols * ORIENTATIONS).reshape(rows * cols, ORIENTATIONS)
    hist /= np.linalg.norm(hist, axis=1, keepdims=True) + CELL_EPS
    return np.sqrt(hist).ravel()


def constant(image: np.ndarray) -> np.ndarray:
    """A descriptor that sees nothing: every image alike, so a localizer has only the odometry."""
    return np.ones(1)


BASELINE = "gradient_grid"
BUILT_IN: dict[str, Descriptor] = {BASELINE: gradient_grid, "constant": constant}


def load_descriptor(spec: str | None) -> tuple[str, Descriptor]:
    """(name, callable) for ``spec``: None is the baseline, a name of :data:`BUILT_IN` that
    descriptor, 'module:function' imports a user's callable."""
    if spec is None:
        return BASELINE, gradient_grid
    if spec in BUILT_IN:
        return spec, BUILT_IN[spec]
    module_name, _, attr = spec.partition(":")
    if not attr:
        raise UserError(f"descriptor {spec!r}: expected {' or '.join(BUILT_IN)} or 'module:function'")
    try:
        function = getattr(importlib.import_module(module_name), attr)
    except (ImportError, AttributeError) as e:
        raise UserError(f"descriptor {spec!r}: cannot load ({e})") from None
    if not callable(function):
        raise UserError(f"descriptor {spec!r}: not callable")
    return spec, function


def describe(images: Iterable[np.ndarray], descriptor: Descriptor) -> np.ndarray:
    """(N, D) float32 L2-normalised descriptors of an iterable of RGB images."""
    rows: list[np.ndarray] = []
    for image in images:
        v = np.asarray(descriptor(image), np.float32).ravel()
        if rows and v.shape != rows[0].shape:
            raise UserError(f"the descriptor returned {v.size} values, earlier {rows[0].size}")
        if not np.all(np.isfinite(v)):
            raise UserError("the descriptor returned a non-finite value")
        rows.append(v)
    if not rows:
        return np.zeros((0, 0), np.float32)
    out = np.stack(rows)
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)
