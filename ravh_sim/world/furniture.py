"""Procedural models of what the furniture library has no model of: door leaves, window frames,
worktops, pictures, mirrors, poufs, keyboards, wall sconces, toothbrushes, wall shelves (a board on
brackets: the library's shelves are bookcases), toilet brushes and the robot's station.

Why: these are parts of the house's structure (a door leaf in its doorway, a window in its wall
opening, a worktop cut to the units below it) or small items the open catalogues lack; everything
else is a modelled library model (:mod:`ravh_sim.world.library`). This module turns (type, box
size, variant, facing) into a model that fills that box, so what the robot's cameras see matches
the collision box the physics uses.  Everything is plain numpy and deterministic: the same inputs
give the same arrays, so generated OBJ files can be cached by their inputs.

How: each builder draws its model in a canonical frame, with the box spanning
x in [0, d] (back at x = 0, front at x = d), y in [-w/2, w/2] and z in
[0, h].  Part sizes are fractions of the box, capped at real-world sizes, so
tiny or odd boxes still give sane models.  ``build_model`` then maps the
model's bounding box exactly onto the requested box (so it always fits inside
and fills it, whatever rounding a builder did) and turns it so the front looks
along the requested ``facing``.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import trimesh

from ravh_sim.world.facing import front_axis, suits_box
from ravh_sim.world.mesh import Vec3, box, coloured, colours, frustum, merged, rounded_box, scaled, transformed
from ravh_sim.world.palette import PALETTE

Parts = list[trimesh.Trimesh]
Builder = Callable[[float, float, float, int, str], Parts]

MIN_EXTENT = 1e-3
"""Smallest box extent built (m); zero, negative or non-finite extents are raised to it."""

_TINY = 1e-6
"""Smallest part extent (m), so no part collapses into zero-area triangles."""


# --- part helpers (canonical frame) --------------------------------------------------------

def _c(name: str) -> int:
    return PALETTE.index(name)


def _corners(x0: float, x1: float, y0: float, y1: float, z0: float,
             z1: float) -> tuple[np.ndarray, np.ndarray]:
    """Centre and (non-degenerate) size of the box between two corners."""
    lo, hi = np.minimum((x0, y0, z0), (x1, y1, z1)), np.maximum((x0, y0, z0), (x1, y1, z1))
    return (lo + hi) / 2, np.maximum(hi - lo, _TINY)


def _blk(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, colour: str) -> trimesh.Trimesh:
    """Box between two corners."""
    return box(*_corners(x0, x1, y0, y1, z0, z1), _c(colour))


def _soft(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, colour: str,
          bevel: float) -> trimesh.Trimesh:
    """Box with chamfered edges between two corners (cushions, mattresses)."""
    return rounded_box(*_corners(x0, x1, y0, y1, z0, z1), _c(colour), bevel)


def _disc(x: float, y: float, z0: float, z1: float, rx: float, ry: float, colour: str,
          segments: int = 8, top: float = 1.0) -> trimesh.Trimesh:
    """Vertical elliptic cylinder, or a frustum whose top radii are ``top`` times the bottom ones."""
    unit = frustum((0.0, 0.0, 0.0), 1.0, top, max(abs(z1 - z0), _TINY), _c(colour), segments)
    return transformed(scaled(unit, (max(rx, _TINY), max(ry, _TINY), 1.0)), 0.0, (x, y, (z0 + z1) / 2))


def _rod(p0: Sequence[float], p1: Sequence[float], r: float, colour: str, segments: int = 6) -> trimesh.Trimesh:
    """Round rod between two points."""
    r = max(r, _TINY)
    return _along(frustum((0.0, 0.0, 0.0), r, r, 1.0, _c(colour), segments), p0, p1)


def _beam(p0: Sequence[float], p1: Sequence[float], t: float, colour: str, width: float = 0.0) -> trimesh.Trimesh:
    """Bar of section t x t (or t x width) between two points."""
    return _along(box((0.0, 0.0, 0.0), (max(t, _TINY), max(width or t, _TINY), 1.0), _c(colour)), p0, p1)


def _along(unit: trimesh.Trimesh, p0: Sequence[float], p1: Sequence[float]) -> trimesh.Trimesh:
    """Stretch a unit-length part lying along z so it runs from p0 to p1."""
    a, b = np.asarray(p0, np.float64), np.asarray(p1, np.float64)
    length = float(np.linalg.norm(b - a))
    axis = (b - a) / length if length > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.array([0.0, 1.0, 0.0]) if abs(axis[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, axis)
    u /= np.linalg.norm(u)
    frame = np.column_stack([u, np.cross(axis, u), axis])
    return transformed(scaled(unit, (1.0, 1.0, max(length, _TINY))), frame, (a + b) / 2)


def _split(lo: float, hi: float, n: int) -> list[tuple[float, float]]:
    """``n`` equal consecutive intervals covering [lo, hi]."""
    edges = np.linspace(lo, hi, max(n, 1) + 1)
    return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:])]


def _pick(options: Sequence, variant: int):
    return options[variant % len(options)]


def _frame(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, f: float,
           colour: str, bottom: str = '') -> Parts:
    """Rectangular picture-style frame of bar width f in the plane x = const."""
    return [_blk(x0, x1, y0, y1, z0, z0 + f, bottom or colour), _blk(x0, x1, y0, y1, z1 - f, z1, colour),
            _blk(x0, x1, y0, y0 + f, z0 + f, z1 - f, colour),
            _blk(x0, x1, y1 - f, y1, z0 + f, z1 - f, colour)]


# --- seating ------------------------------------------------------------------------------


def _pouf(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    rx, ry = d / 2, w / 2
    bevel = min(d, w, h)
    style = v % 4
    if style == 0:  # round, with a domed top
        return [_disc(rx, 0.0, 0.0, 0.9 * h, rx, ry, 'fabric_grey', 12),
                _disc(rx, 0.0, 0.9 * h, h, 0.95 * rx, 0.95 * ry, 'fabric_grey', 12, top=0.9)]
    if style == 1:  # square, buttoned
        buttons = [_blk(x - 0.02 * d, x + 0.02 * d, y - 0.02 * w, y + 0.02 * w, 0.97 * h, h, 'fabric_navy')
                   for x in (0.3 * d, 0.7 * d) for y in (-0.2 * w, 0.2 * w)]
        return [_soft(0.0, d, -ry, ry, 0.0, 0.98 * h, 'fabric_blue', 0.2 * bevel)] + buttons
    if style == 2:  # leather drum with a brass band
        return [_disc(rx, 0.0, 0.0, h, 0.97 * rx, 0.97 * ry, 'leather_brown', 12),
                _disc(rx, 0.0, 0.45 * h, 0.55 * h, rx, ry, 'brass', 12)]
    return [_soft(0.0, d, -ry, ry, 0.0, 0.75 * h, 'fabric_pink', 0.15 * bevel),  # with a loose cushion
            _soft(0.04 * d, 0.96 * d, -0.46 * w, 0.46 * w, 0.7 * h, h, 'fabric_pink', 0.3 * bevel)]


# --- kitchen --------------------------------------------------------------------------------


def _counter(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Worktop slab with a front edge band."""
    top, edge = _pick((('marble', 'marble'), ('granite', 'granite'), ('wood_light', 'wood_medium'),
                       ('white', 'steel')), v)
    e = min(0.02, 0.06 * d)
    return [_blk(0.0, d - e, -w / 2, w / 2, 0.0, h, top), _blk(d - e, d, -w / 2, w / 2, 0.0, h, edge)]


# --- bathroom ------------------------------------------------------------------------------


def _toothbrush(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Two brushes in a tumbler when the box is upright, else one brush lying along y."""
    if h < 0.6 * max(d, w):
        t = 0.5 * min(d, h)
        return [_blk(d / 2 - t / 2, d / 2 + t / 2, -w / 2, 0.3 * w, 0.0, 0.5 * h, 'art_blue'),
                _blk(d / 2 - t / 2, d / 2 + t / 2, 0.3 * w, w / 2, 0.0, 0.4 * h, 'white'),
                _blk(d / 2 - 0.4 * t, d / 2 + 0.4 * t, 0.3 * w, w / 2, 0.4 * h, h, 'sky')]
    r = min(d, w) / 2
    parts = [_disc(d / 2, 0.0, 0.0, 0.55 * h, 0.9 * r, 0.9 * r, 'glass', 8, top=1.1)]
    for side, colour in ((-1.0, 'art_blue'), (1.0, 'art_green')):
        top = (d / 2, side * (w / 2 - 0.2 * r), 0.85 * h)
        parts += [_beam((d / 2, side * 0.3 * r, 0.1 * h), top, 0.12 * r, colour),
                  _beam(top, (d / 2, top[1], h), 0.14 * r, 'white', 0.3 * r)]
    return parts


def _toilet_brush(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """A toilet brush standing in its holder: a tapered pot, the handle rising from it, a knob."""
    r = min(d, w) / 2
    pot = 0.45 * h
    return [_disc(d / 2, 0.0, 0.0, pot, 0.95 * r, 0.95 * r, 'white', 12, top=0.85),
            _rod((d / 2, 0.0, pot), (d / 2, 0.0, 0.93 * h), 0.08 * r, 'chrome', 8),
            _disc(d / 2, 0.0, 0.93 * h, h, 0.18 * r, 0.18 * r, 'chrome', 8, top=0.7)]


def _wall_shelf(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """A board on two brackets fixed to the wall at x = 0 (a wall shelf; the box is its board's
    thickness and the brackets' depth below it)."""
    board, bracket = _pick((('wood_medium', 'metal'), ('white', 'white'), ('wood_dark', 'black')), v)
    t = 0.6 * h
    parts = [_blk(0.0, d, -w / 2, w / 2, h - t, h, board)]
    for y in (-0.35 * w, 0.35 * w):
        parts.append(_blk(0.0, 0.7 * d, y - 0.01, y + 0.01, 0.0, h - t, bracket))
    return parts


# --- lighting ------------------------------------------------------------------------------


def _lighter(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Twin wall sconce: a plate on the wall (x = 0), two arms, upturned shades."""
    plate = min(0.02, 0.1 * d)
    r = min((d - plate) / 2, w / 4)
    parts = [_blk(0.0, plate, -0.12 * w, 0.12 * w, 0.0, 0.7 * h, 'brass')]
    for side in (-1.0, 1.0):
        y = side * (w / 2 - r)
        parts += [_beam((plate, side * 0.08 * w, 0.35 * h), (d - r, y, 0.3 * h), 0.06 * min(w, h), 'brass'),
                  _disc(d - r, y, 0.15 * h, 0.4 * h, 0.3 * r, 0.3 * r, 'brass', 8),
                  _disc(d - r, y, 0.4 * h, h, 0.65 * r, 0.65 * r, 'lamp_shade', 8, top=1 / 0.65)]
    return parts


# --- screens, wall art, electronics ---------------------------------------------------------


def _mirror(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Wall mirror: wide wooden frame; thin black frame; oval in a brass rim."""
    style = v % 3
    if style == 2:
        return [_oval(0.0, 0.6 * d, w / 2, h / 2, h / 2, 'brass'),
                _oval(0.0, d, 0.45 * w, 0.45 * h, h / 2, 'mirror')]
    f = min(0.06, 0.1 * min(w, h)) if style == 0 else min(0.02, 0.05 * min(w, h))
    return _frame(0.0, d, -w / 2, w / 2, 0.0, h, f, 'wood_medium' if style == 0 else 'black') + [
        _blk(0.0, 0.7 * d, -w / 2 + f, w / 2 - f, f, h - f, 'mirror')]


def _oval(x0: float, x1: float, ry: float, rz: float, zc: float, colour: str) -> trimesh.Trimesh:
    """Elliptic slab between x0 and x1, facing +x, centred on y = 0 and z = zc."""
    unit = frustum((0.0, 0.0, 0.0), 1.0, 1.0, max(x1 - x0, _TINY), _c(colour), 12, axis='x')
    return transformed(scaled(unit, (1.0, ry, rz)), 0.0, ((x0 + x1) / 2, 0.0, zc))


def _keyboard(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Keyboard lying flat: rows of keys along y, the space bar row at the front (+x)."""
    parts = [_soft(0.0, d, -w / 2, w / 2, 0.0, 0.6 * h, 'charcoal', 0.2 * h)]
    for i, (a, b) in enumerate(_split(0.08 * d, 0.92 * d, 5)):
        pad = 0.12 * (b - a)
        blocks = ((0.03, 0.27), (0.32, 0.68), (0.73, 0.97)) if i == 4 else ((0.03, 0.76), (0.8, 0.97))
        parts += [_blk(a + pad, b - pad, -w / 2 + p * w, -w / 2 + q * w, 0.6 * h, h, 'grey_dark')
                  for p, q in blocks]
    return parts


def _station(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Robot charging pad: the robot docks from +x onto contacts near the back."""
    return [_blk(0.0, d, -w / 2, w / 2, 0.0, 0.7 * h, 'grey_dark'),
            _blk(0.05 * d, 0.25 * d, -0.3 * w, -0.1 * w, 0.7 * h, h, 'brass'),
            _blk(0.05 * d, 0.25 * d, 0.1 * w, 0.3 * w, 0.7 * h, h, 'brass'),
            _blk(0.02 * d, 0.06 * d, -0.03 * w, 0.03 * w, 0.7 * h, h, 'led'),
            _blk(0.9 * d, d, -w / 2, w / 2, 0.7 * h, h, 'art_yellow')]


# --- openings ------------------------------------------------------------------------------

_DOORS = (('wood_medium', 'white', 'plain'), ('off_white', 'white', 'panels'),
          ('wood_dark', 'wood_dark', 'glass'))


def _door(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Frame through the wall (x spans the wall) and a closed leaf with lever handles on both sides."""
    leaf, frame, style = _pick(_DOORS, v)
    fw, lt = min(0.07, 0.08 * w, 0.08 * h), min(0.045, 0.4 * d)
    x0, x1 = d / 2 - lt / 2, d / 2 + lt / 2
    y0, y1, top = -w / 2 + fw, w / 2 - fw, h - fw
    parts = [_blk(0.0, d, -w / 2, y0, 0.0, h, frame), _blk(0.0, d, y1, w / 2, 0.0, h, frame),
             _blk(0.0, d, y0, y1, top, h, frame), _blk(x0, x1, y0, y1, 0.0, top, leaf)]
    proud, inset = 0.1 * lt, 0.15 * (y1 - y0)
    if style == 'panels':
        parts += [_blk(x0 - proud, x1 + proud, y0 + inset, y1 - inset, a * top, b * top, 'white')
                  for a, b in ((0.08, 0.42), (0.52, 0.92))]
    if style == 'glass':
        parts += [_blk(x0 - proud / 2, x1 + proud / 2, y0 + 1.3 * inset, y1 - 1.3 * inset, a * top, b * top,
                       'glass') for a, b in ((0.45, 0.6), (0.64, 0.78), (0.82, 0.94))]
    return parts + _lever_handles(x0, x1, y1 - min(0.08, 0.12 * (y1 - y0)), min(1.0, 0.42 * h), w, h)


def _lever_handles(x0: float, x1: float, y: float, z: float, w: float, h: float) -> Parts:
    """Lever handles on both faces of a leaf spanning [x0, x1]; levers point towards -y."""
    reach = max(min(0.06, 0.45 * x0), _TINY)
    plate_w, plate_h, lever = min(0.025, 0.03 * w), min(0.07, 0.03 * h), min(0.13, 0.15 * w)
    t = min(0.012, 0.005 * h)
    parts = []
    for face, out in ((x0, -1.0), (x1, 1.0)):
        tip = face + out * reach
        parts += [_blk(face, face + out * 0.3 * reach, y - plate_w, y + plate_w, z - plate_h, z + plate_h,
                       'chrome'),
                  _blk(tip - out * 0.3 * reach, tip, y - lever + plate_w, y + plate_w / 2, z - t, z + t,
                       'chrome')]
    return parts


_WINDOWS = (('white', 'casement'), ('wood_medium', 'cross'), ('grey_dark', 'transom'))


def _window(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Window set in the wall (x spans the wall): frame with a sill, glass, mullions."""
    frame, layout = _pick(_WINDOWS, v)
    fw = min(0.07, 0.1 * min(w, h))
    sash, xm = min(0.04, 0.5 * fw), d / 2
    depth = min(2 * sash, 0.4 * d)
    sill = 'grey_light' if frame == 'white' else 'white'
    parts = _frame(0.0, d, -w / 2, w / 2, 0.0, h, fw, frame, bottom=sill)
    parts.append(_blk(xm - 0.1 * depth, xm + 0.1 * depth, -w / 2 + fw, w / 2 - fw, fw, h - fw, 'glass'))
    transom = fw + (0.55 if layout == 'cross' else 0.72) * (h - 2 * fw)
    if layout != 'casement':
        parts.append(_blk(xm - depth, xm + depth, -w / 2 + fw, w / 2 - fw, transom - sash, transom + sash,
                          frame))
    top = transom if layout == 'transom' else h - fw
    return parts + [_blk(xm - depth, xm + depth, -sash, sash, fw, top, frame)]


# --- decoration ----------------------------------------------------------------------------


def _generic(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    return [_soft(0.0, d, -w / 2, w / 2, 0.0, h, 'grey_light', 0.1 * min(d, w, h))]


# --- registry and entry points -------------------------------------------------------------

@dataclass(frozen=True)
class _Spec:
    build: Builder
    variants: int


_SPECS: dict[str, _Spec] = {
    'Brush': _Spec(_toilet_brush, 1), 'Counter': _Spec(_counter, 4), 'Door': _Spec(_door, 3),
    'Keyboard': _Spec(_keyboard, 1), 'Lighter': _Spec(_lighter, 1),
    'Mirror': _Spec(_mirror, 3), 'Pouf': _Spec(_pouf, 4),
    'Shelf': _Spec(_wall_shelf, 3), 'Station': _Spec(_station, 1), 'Toothbrush': _Spec(_toothbrush, 1),
    'Wall': _Spec(_window, 3),
}
_GENERIC = _Spec(_generic, 1)

OBJECT_TYPES: tuple[str, ...] = tuple(sorted(_SPECS))
"""Every type with a dedicated model; any other type string gets a generic bevelled box."""


def variant_count(object_type: str) -> int:
    """How many visibly different models ``build_model`` offers for a type."""
    return _SPECS.get(object_type, _GENERIC).variants


def build_model(object_type: str, size: Vec3, variant: int, facing: int = 0,
                prefab: str = '') -> trimesh.Trimesh:
    """Model of ``object_type`` filling the upright box ``size`` (sx, sy, sz) centred at the origin.

    ``variant`` is taken modulo ``variant_count``; ``facing`` (0..3) makes the
    front look along local +x, +y, -x, -y.  Types whose front belongs on a
    particular side of the box (``front_axis``: a bed's foot on the long axis,
    a wardrobe's doors on its long side) turn a quarter when ``facing`` does
    not suit the box.
    """
    return merged(build_parts(object_type, size, variant, facing, prefab))


def build_parts(object_type: str, size: Vec3, variant: int, facing: int = 0,
                prefab: str = '') -> Parts:
    """The parts ``build_model`` merges (same arguments, same placement in the box), one by one.

    Every part is a convex solid (a box, prism, bevelled box or icosahedron), so physics can
    collide with each part as its own convex hull: legs with gaps between them, an L-shaped sofa
    with a free corner, exactly the surfaces the camera sees.
    """
    spec = _SPECS.get(object_type, _GENERIC)
    extents = _clean_size(size)
    facing = int(facing) % 4
    if not suits_box(front_axis(object_type), extents, facing):
        facing = (facing + 1) % 4
    d, w, h = extents[[0, 1, 2] if facing % 2 == 0 else [1, 0, 2]]
    parts = spec.build(d, w, h, int(variant) % spec.variants, prefab or '')
    lo, hi = merged(parts).bounds
    return [transformed(_fit(part, lo, hi, (d, w, h)), facing * np.pi / 2) for part in parts]


def _clean_size(size: Vec3) -> np.ndarray:
    values = np.abs(np.asarray(size, np.float64).reshape(3))
    return np.maximum(np.where(np.isfinite(values), values, MIN_EXTENT), MIN_EXTENT)


def _fit(part: trimesh.Trimesh, lo: np.ndarray, hi: np.ndarray, size: Sequence[float]) -> trimesh.Trimesh:
    """Map ``part`` as the box between ``lo`` and ``hi`` (the whole model's bounds) maps exactly
    onto a box of ``size`` centred at the origin."""
    scale = np.asarray(size, np.float64) / np.maximum(hi - lo, 1e-12)
    return coloured((part.vertices - (lo + hi) / 2) * scale, part.faces, colours(part))
