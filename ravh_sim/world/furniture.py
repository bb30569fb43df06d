"""Procedural low-poly furniture models, one merged mesh per object.

Why: the upstream houses only give each object a type tag, a prefab name and
an upright box; the Unity meshes themselves cannot be shipped.  This library
turns (type, box size, variant, facing) into a recognisable model that fills
that box, so what the robot's cameras see matches the collision box the
physics uses.  Everything is plain numpy and deterministic: the same inputs
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

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ravh_sim.world.facing import suits_box
from ravh_sim.world.mesh import Mesh, Vec3, box, ellipsoid, frustum, rotation_y, rounded_box
from ravh_sim.world.palette import PALETTE

Parts = list[Mesh]
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


def _blk(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, colour: str) -> Mesh:
    """Box between two corners."""
    return box(*_corners(x0, x1, y0, y1, z0, z1), _c(colour))


def _soft(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, colour: str,
          bevel: float) -> Mesh:
    """Box with chamfered edges between two corners (cushions, mattresses)."""
    return rounded_box(*_corners(x0, x1, y0, y1, z0, z1), _c(colour), bevel)


def _ell(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, colour: str) -> Mesh:
    """Ellipsoid filling the box between two corners (foliage, globes, fruit)."""
    return ellipsoid(*_corners(x0, x1, y0, y1, z0, z1), _c(colour))


def _disc(x: float, y: float, z0: float, z1: float, rx: float, ry: float, colour: str,
          segments: int = 8, top: float = 1.0) -> Mesh:
    """Vertical elliptic cylinder, or a frustum whose top radii are ``top`` times the bottom ones."""
    unit = frustum((0.0, 0.0, 0.0), 1.0, top, max(abs(z1 - z0), _TINY), _c(colour), segments)
    return unit.scaled((max(rx, _TINY), max(ry, _TINY), 1.0)).transformed(0.0, (x, y, (z0 + z1) / 2))


def _post(x: float, y: float, z0: float, z1: float, r: float, colour: str, segments: int = 8) -> Mesh:
    """Vertical round rod."""
    return _disc(x, y, z0, z1, r, r, colour, segments)


def _rod(p0: Sequence[float], p1: Sequence[float], r: float, colour: str, segments: int = 6) -> Mesh:
    """Round rod between two points."""
    r = max(r, _TINY)
    return _along(frustum((0.0, 0.0, 0.0), r, r, 1.0, _c(colour), segments), p0, p1)


def _beam(p0: Sequence[float], p1: Sequence[float], t: float, colour: str, width: float = 0.0) -> Mesh:
    """Bar of section t x t (or t x width) between two points."""
    return _along(box((0.0, 0.0, 0.0), (max(t, _TINY), max(width or t, _TINY), 1.0), _c(colour)), p0, p1)


def _along(unit: Mesh, p0: Sequence[float], p1: Sequence[float]) -> Mesh:
    """Stretch a unit-length part lying along z so it runs from p0 to p1."""
    a, b = np.asarray(p0, np.float64), np.asarray(p1, np.float64)
    length = float(np.linalg.norm(b - a))
    axis = (b - a) / length if length > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.array([0.0, 1.0, 0.0]) if abs(axis[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, axis)
    u /= np.linalg.norm(u)
    frame = np.column_stack([u, np.cross(axis, u), axis])
    return unit.scaled((1.0, 1.0, max(length, _TINY))).transformed(frame, (a + b) / 2)


def _pick(options: Sequence, variant: int):
    return options[variant % len(options)]


def _split(lo: float, hi: float, n: int) -> list[tuple[float, float]]:
    """``n`` equal consecutive intervals covering [lo, hi]."""
    edges = np.linspace(lo, hi, max(n, 1) + 1)
    return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:])]


def _count(length: float, pitch: float, low: int = 1, high: int = 6) -> int:
    """How many items about ``pitch`` apart fit along ``length``, clamped to [low, high]."""
    return int(np.clip(round(length / pitch), low, high))


def _legs(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, t: float,
          colour: str, round_: bool = False) -> Parts:
    """Four legs of thickness t in the corners of a rectangle."""
    xs, ys = (x0 + t / 2, x1 - t / 2), (y0 + t / 2, y1 - t / 2)
    if round_:
        return [_post(x, y, z0, z1, t / 2, colour) for x in xs for y in ys]
    return [_blk(x - t / 2, x + t / 2, y - t / 2, y + t / 2, z0, z1, colour) for x in xs for y in ys]


def _frame(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, f: float,
           colour: str, bottom: str = '') -> Parts:
    """Rectangular picture-style frame of bar width f in the plane x = const."""
    return [_blk(x0, x1, y0, y1, z0, z0 + f, bottom or colour), _blk(x0, x1, y0, y1, z1 - f, z1, colour),
            _blk(x0, x1, y0, y0 + f, z0 + f, z1 - f, colour),
            _blk(x0, x1, y1 - f, y1, z0 + f, z1 - f, colour)]


# --- fronts: doors, drawers, handles ---------------------------------------------------------

@dataclass(frozen=True)
class _Front:
    """A door or drawer front on an x = const face, and where its pull goes."""

    y0: float
    y1: float
    z0: float
    z1: float
    handle: str  # 'left' / 'right': vertical pull at that y edge; 'drawer': centred bar; 'none'
    height: str = 'mid'  # height of a vertical pull: 'top' | 'mid' | 'bottom'
    colour: str = ''  # replaces the finish's panel colour when set


@dataclass(frozen=True)
class _Finish:
    """Materials of a cabinet-like piece."""

    body: str
    panel: str
    handle: str
    pull: str = 'bar'  # 'bar' | 'long' | 'knob'


def _front_depths(d: float) -> tuple[float, float]:
    """Thickness of front panels and how far pulls stick out of them."""
    return min(0.02, 0.06 * d), min(0.025, 0.08 * d)


def _carcass(d: float, y0: float, y1: float, z0: float, z1: float, body: str) -> tuple[Mesh, float]:
    """Cabinet body leaving room in front for fronts and pulls; returns it and its front face x."""
    ft, hd = _front_depths(d)
    xf = d - ft - hd
    return _blk(0.0, xf, y0, y1, z0, z1, body), xf


def _plinth(d: float, w: float, h: float, colour: str) -> Mesh:
    """Recessed kick board under a cabinet."""
    return _blk(0.0, 0.9 * d, -0.49 * w, 0.49 * w, 0.0, h, colour)


def _door_row(y0: float, y1: float, z0: float, z1: float, n: int, height: str = 'mid') -> list[_Front]:
    """``n`` doors side by side, their pulls meeting in pairs."""
    return [_Front(a, b, z0, z1, 'right' if i % 2 == 0 and i + 1 < n else 'left', height)
            for i, (a, b) in enumerate(_split(y0, y1, n))]


def _drawer_grid(y0: float, y1: float, z0: float, z1: float, rows: int, cols: int) -> list[_Front]:
    return [_Front(a, b, c, e, 'drawer') for c, e in _split(z0, z1, rows) for a, b in _split(y0, y1, cols)]


def _fronts(x: float, d: float, fronts: Sequence[_Front], finish: _Finish) -> Parts:
    """Panels on the face at x, each with its pull (pulls stop at x = d)."""
    ft, hd = _front_depths(d)
    parts = []
    for f in fronts:
        gap = min(0.003, 0.04 * (f.y1 - f.y0), 0.04 * (f.z1 - f.z0))
        colour = f.colour or finish.panel
        parts.append(_blk(x, x + ft, f.y0 + gap, f.y1 - gap, f.z0 + gap, f.z1 - gap, colour))
        parts += _pull(x + ft, min(x + ft + hd, d), f, finish)
    return parts


def _pull(x0: float, x1: float, f: _Front, finish: _Finish) -> Parts:
    width, height = f.y1 - f.y0, f.z1 - f.z0
    t = min(0.014, 0.12 * width, 0.12 * height)
    if f.handle == 'none':
        return []
    if f.handle == 'drawer':
        half = t / 2 if finish.pull == 'knob' else min(0.09, 0.22 * width)
        yc, zc = (f.y0 + f.y1) / 2, f.z0 + 0.62 * height
        return [_blk(x0, x1, yc - half, yc + half, zc - t / 2, zc + t / 2, finish.handle)]
    margin = min(0.045, 0.18 * width)
    y = f.y1 - margin if f.handle == 'right' else f.y0 + margin
    length = {'bar': min(0.16, 0.3 * height), 'long': 0.55 * height, 'knob': t}[finish.pull]
    inset = min(0.06, 0.1 * height) + length / 2
    zc = {'top': f.z1 - inset, 'bottom': f.z0 + inset, 'mid': (f.z0 + f.z1) / 2}[f.height]
    return [_blk(x0, x1, y - t / 2, y + t / 2, zc - length / 2, zc + length / 2, finish.handle)]


def _open_shelves(xf: float, d: float, w: float, z0: float, z1: float, colour: str,
                  books: bool = True) -> Parts:
    """An open compartment drawn on a carcass face at x = xf: dark back, boards, sides, books."""
    ft, _ = _front_depths(d)
    t = min(0.02, 0.05 * w)
    levels = np.linspace(z0 + t / 2, z1 - t / 2, _count(z1 - z0, 0.35, 1, 5) + 1)
    parts = [_blk(xf, xf + 0.05 * ft, -w / 2, w / 2, z0, z1, 'charcoal')]
    parts += [_blk(xf, xf + ft, -w / 2, w / 2, z - t / 2, z + t / 2, colour) for z in levels]
    parts += [_blk(xf, xf + ft, y - t / 2, y + t / 2, z0, z1, colour)
              for y in (-w / 2 + t / 2, w / 2 - t / 2)]
    if books:
        openings = [(a + t / 2, b - t / 2) for a, b in zip(levels[:-1], levels[1:])]
        parts += _books(xf, xf + 0.8 * ft, -w / 2 + t, w / 2 - t, openings)
    return parts


_BOOK_COLOURS = ('fabric_red', 'fabric_navy', 'fabric_green', 'cream', 'fabric_mustard', 'charcoal',
                 'fabric_teal')
_BOOK_BLOCKS = ((0.04, 0.3, 0.8), (0.33, 0.5, 0.65), (0.7, 0.9, 0.72))  # (from, to, height) fractions


def _books(x0: float, x1: float, y0: float, y1: float, shelves: Sequence[tuple[float, float]]) -> Parts:
    """Blocks of books standing on shelves given as (shelf top, next shelf bottom)."""
    parts = []
    for i, (z0, z1) in enumerate(shelves):
        for j, (a, b, fill) in enumerate(_BOOK_BLOCKS[:2 + i % 2]):
            parts.append(_blk(x0, x1, y0 + a * (y1 - y0), y0 + b * (y1 - y0), z0, z0 + fill * (z1 - z0),
                              _BOOK_COLOURS[(3 * i + j) % len(_BOOK_COLOURS)]))
    return parts


# --- seating ------------------------------------------------------------------------------

_CHAIRS = (('wood_medium', 'wood_medium', 'slats'), ('chrome', 'fabric_grey', 'panel'),
           ('black', 'white', 'shell'), ('wood_dark', 'fabric_red', 'ladder'))


def _chair(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Dining chair (legs, seat, back at x = 0), or an office chair for the 'Chair_office' prefab."""
    if 'office' in prefab.lower():
        return _office_chair(d, w, h, v)
    frame, seat, back = _pick(_CHAIRS, v)
    seat_z, st = 0.46 * h, min(0.05, 0.06 * h)
    t = min(0.04, 0.12 * min(d, w))
    parts = _legs(0.0, d, -w / 2, w / 2, 0.0, seat_z - st, t, frame, round_=frame == 'chrome')
    if seat == frame:
        parts.append(_blk(0.0, d, -w / 2, w / 2, seat_z - st, seat_z, seat))
    else:
        parts.append(_soft(0.0, d, -w / 2, w / 2, seat_z - st, seat_z, seat, 0.3 * st))
    return parts + _chair_back(min(0.035, 0.1 * d), w, h, seat_z, t, frame, seat, back)


def _chair_back(bt: float, w: float, h: float, seat_z: float, t: float, frame: str, seat: str,
                style: str) -> Parts:
    rise = h - seat_z
    if style == 'shell':
        return [_soft(0.0, bt, -w / 2, w / 2, seat_z, h, seat, 0.3 * bt)]
    post_top = h if style in ('slats', 'ladder') else seat_z + 0.25 * rise
    posts = [_blk(0.0, t, y - t / 2, y + t / 2, seat_z, post_top, frame)
             for y in (-w / 2 + t / 2, w / 2 - t / 2)]
    if style == 'panel':
        return posts + [_soft(0.0, bt, -w / 2, w / 2, seat_z + 0.12 * rise, h, seat, 0.3 * bt)]
    rail = min(0.07, 0.15 * rise)
    parts = posts + [_blk(0.0, bt, -w / 2 + t, w / 2 - t, h - rail, h, frame)]
    if style == 'slats':
        return parts + [_blk(0.2 * bt, 0.8 * bt, a + 0.3 * (b - a), b - 0.3 * (b - a), seat_z, h - rail,
                             frame) for a, b in _split(-w / 2 + t, w / 2 - t, 3)]
    return parts + [_blk(0.1 * bt, 0.9 * bt, -w / 2 + t, w / 2 - t, z - rail / 3, z + rail / 3, frame)
                    for z in (seat_z + 0.3 * rise, h - 1.8 * rail)]


def _office_chair(d: float, w: float, h: float, v: int) -> Parts:
    """Five-star base, gas column, padded seat and back, arm rests."""
    fabric = _pick(('charcoal', 'fabric_blue', 'fabric_grey', 'fabric_red'), v)
    cx, r = d / 2, min(d, w) / 2
    seat_z, st = 0.5 * h, min(0.07, 0.08 * h)
    rise = h - seat_z
    t, bt = min(0.03, 0.12 * r), min(0.06, 0.12 * d)
    star = [_beam((cx, 0.0, t / 2), (cx + r * np.cos(a), r * np.sin(a), t / 2), t, 'black')
            for a in np.arange(5) * 2 * np.pi / 5 + np.pi / 2]
    arms = [_blk(0.25 * d, 0.8 * d, y - 0.03 * w, y + 0.03 * w, seat_z, seat_z + 0.22 * rise, 'black')
            for y in (-0.47 * w, 0.47 * w)]
    return star + arms + [
        _post(cx, 0.0, t, seat_z - st, min(0.025, 0.1 * r), 'chrome'),
        _soft(0.06 * d, d, -w / 2, w / 2, seat_z - st, seat_z, fabric, 0.4 * st),
        _soft(0.0, bt, -0.42 * w, 0.42 * w, seat_z + 0.12 * rise, h, fabric, 0.4 * bt),
        _blk(0.3 * bt, 0.15 * d, -0.04 * w, 0.04 * w, seat_z - st, seat_z + 0.2 * rise, 'black')]


@dataclass(frozen=True)
class _Upholstery:
    fabric: str
    legs: str  # colour of the legs; '' sits the base on the floor
    arms: str  # 'box' | 'round' | 'wood'
    cushion: str = ''  # cushion colour; defaults to the fabric


_UPHOLSTERY = (_Upholstery('fabric_grey', 'wood_dark', 'box'), _Upholstery('leather_brown', '', 'round'),
               _Upholstery('fabric_blue', 'wood_light', 'wood'),
               _Upholstery('fabric_beige', 'black', 'box', 'fabric_mustard'))

_CHAISE_WIDTH = 0.9
"""Width (m) of the long seat of a 'Corner Sofa'."""


def _armchair(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    return _upholstered(d, w, h, _pick(_UPHOLSTERY, v), seats=1)


def _sofa(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Sofa with back along x = 0; a 'Corner Sofa' adds a long seat reaching forward at +y."""
    chaise = d if 'corner' in prefab.lower() else 0.0
    seats = _count(w - (_CHAISE_WIDTH if chaise else 0.0), 0.65, 1, 4)
    return _upholstered(min(d, 1.0) if chaise else d, w, h, _pick(_UPHOLSTERY, v), seats, chaise)


def _upholstered(d: float, w: float, h: float, s: _Upholstery, seats: int, chaise: float = 0.0) -> Parts:
    """Base, back, arms and cushions; ``chaise`` > 0 is the depth of a corner sofa's long seat."""
    lh = 0.1 * h if s.legs else 0.0
    base_top, seat_top, arm_top = 0.42 * h, 0.62 * h, 0.78 * h
    aw = min(0.2, 0.1 * w if seats > 1 else 0.15 * w)
    bd = min(0.25, 0.24 * d)
    cushion = s.cushion or s.fabric
    seat_y1 = w / 2 - aw - (min(_CHAISE_WIDTH, 0.45 * w) if chaise else 0.0)
    parts = [_blk(0.0, d, -w / 2, w / 2, lh, base_top, s.fabric),
             _blk(0.0, bd, -w / 2 + aw, w / 2 - aw, base_top, h, s.fabric)]
    bevel = 0.25 * (seat_top - base_top)
    for a, b in _split(-w / 2 + aw, seat_y1, seats):
        parts += [_soft(bd, d, a, b, base_top, seat_top, cushion, bevel),
                  _blk(bd, 1.5 * bd, a + 0.01 * w, b - 0.01 * w, seat_top, 0.95 * h, cushion)]
    if chaise:
        parts += [_blk(0.0, chaise, seat_y1, w / 2, lh, base_top, s.fabric),
                  _soft(bd, chaise, seat_y1, w / 2 - aw, base_top, seat_top, cushion, bevel),
                  _blk(bd, 1.5 * bd, seat_y1, w / 2 - aw, seat_top, 0.95 * h, cushion)]
    parts += _sofa_arm(-w / 2, -w / 2 + aw, lh, arm_top, d, s)
    parts += _sofa_arm(w / 2 - aw, w / 2, lh, arm_top, chaise or d, s)
    if s.legs:
        t = min(0.05, 0.08 * min(d, w))
        parts += _legs(0.0, d, -w / 2, w / 2, 0.0, lh, t, s.legs)
        if chaise:
            parts += _legs(d, chaise, seat_y1, w / 2, 0.0, lh, t, s.legs)[2:]  # the two front ones
    return parts


def _sofa_arm(y0: float, y1: float, z0: float, z1: float, x1: float, s: _Upholstery) -> Parts:
    if s.arms == 'round':
        return [_soft(0.0, x1, y0, y1, z0, z1, s.fabric, 0.45 * (y1 - y0))]
    if s.arms == 'wood':
        cap = min(0.04, 0.08 * (z1 - z0))
        inset = 0.1 * (y1 - y0)
        return [_blk(0.0, x1, y0 + inset, y1 - inset, z0, z1 - cap, s.fabric),
                _blk(0.0, x1, y0, y1, z1 - cap, z1, s.legs or 'wood_medium')]
    return [_blk(0.0, x1, y0, y1, z0, z1, s.fabric)]


def _stool(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    rx, ry = d / 2, w / 2
    style = v % 4
    if style == 0:  # bar stool: round seat, chrome legs, foot rails
        t = min(0.025, 0.1 * min(d, w))
        rails = [_blk(0.1 * d, 0.9 * d, y - t / 3, y + t / 3, 0.3 * h, 0.3 * h + t / 1.5, 'chrome')
                 for y in (-0.42 * w + t / 2, 0.42 * w - t / 2)]
        legs = _legs(0.08 * d, 0.92 * d, -0.42 * w, 0.42 * w, 0.0, 0.93 * h, t, 'chrome', round_=True)
        return legs + rails + [_disc(rx, 0.0, 0.93 * h, h, rx, ry, 'leather_black', 12)]
    if style == 1:  # wooden square stool with stretchers
        t = min(0.04, 0.14 * min(d, w))
        stretchers = [_blk(t / 2, d - t / 2, y - t / 3, y + t / 3, 0.25 * h, 0.25 * h + t, 'wood_light')
                      for y in (-ry + t / 2, ry - t / 2)]
        return _legs(0.04 * d, 0.96 * d, -0.46 * w, 0.46 * w, 0.0, 0.92 * h, t, 'wood_light') + stretchers + [
            _blk(0.0, d, -ry, ry, 0.92 * h, h, 'wood_light')]
    if style == 2:  # three legs under a cushioned seat
        t = min(0.035, 0.12 * min(d, w))
        legs = [_post(rx + 0.4 * rx * np.cos(a), 0.4 * ry * np.sin(a), 0.0, 0.88 * h, t / 2, 'black', 6)
                for a in np.arange(3) * 2 * np.pi / 3]
        return legs + [_disc(rx, 0.0, 0.82 * h, 0.9 * h, 0.8 * rx, 0.8 * ry, 'wood_dark', 12),
                       _disc(rx, 0.0, 0.9 * h, h, rx, ry, 'fabric_teal', 12, top=0.9)]
    return [_disc(rx, 0.0, 0.0, 0.03 * h, 0.8 * rx, 0.8 * ry, 'charcoal', 12),  # pedestal stool
            _post(rx, 0.0, 0.03 * h, 0.9 * h, min(0.03, 0.12 * min(rx, ry)), 'chrome'),
            _disc(rx, 0.0, 0.9 * h, h, rx, ry, 'fabric_red', 12)]


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


# --- beds and tables ---------------------------------------------------------------------

_BEDS = (('wood_medium', 'panel', 'fabric_blue'), ('fabric_grey', 'padded', 'fabric_beige'),
         ('white', 'slats', 'fabric_green'), ('wood_dark', 'posts', 'fabric_red'),
         ('black', 'metal', 'fabric_teal'))


def _bed(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Headboard at x = 0, foot at x = d (the long axis): frame, mattress, blanket, pillows."""
    frame, head, blanket = _pick(_BEDS, v)
    hb = min(0.07, 0.06 * d)
    lh = 0.08 * h if head in ('metal', 'posts') else 0.0
    frame_top, mattress_top = 0.3 * h, 0.5 * h
    foot = d - (hb if head in ('slats', 'posts', 'metal') else 0.0)
    parts = [_blk(hb, d, -0.49 * w, 0.49 * w, lh, frame_top, frame),
             _soft(hb, foot - 0.01 * d, -0.48 * w, 0.48 * w, frame_top, mattress_top, 'mattress', 0.03 * h),
             _soft(hb + 0.36 * (d - hb), foot, -w / 2, w / 2, frame_top - 0.05 * h, mattress_top + 0.02 * h,
                   blanket, 0.02 * h)]
    pillow = min(0.4, 0.22 * d)
    for a, b in _split(-0.44 * w, 0.44 * w, 2 if w > 1.25 else 1):
        parts.append(_soft(hb + 0.02 * d, hb + 0.02 * d + pillow, a + 0.02 * w, b - 0.02 * w,
                           mattress_top, mattress_top + 0.12 * h, 'pillow', 0.04 * h))
    if lh:
        parts += _legs(hb, d, -w / 2, w / 2, 0.0, lh, min(0.06, 0.05 * w), frame)
    return parts + _headboard(hb, w, h, frame, head) + _footboard(d, hb, w, h, frame, head)


def _headboard(hb: float, w: float, h: float, frame: str, style: str) -> Parts:
    if style == 'panel':
        return [_blk(0.0, hb, -w / 2, w / 2, 0.0, h, frame)]
    if style == 'padded':
        return [_blk(0.0, 0.4 * hb, -w / 2, w / 2, 0.0, 0.6 * h, frame),
                _soft(0.0, hb, -w / 2, w / 2, 0.4 * h, h, frame, 0.3 * hb)]
    posts = [_blk(0.0, hb, y - hb / 2, y + hb / 2, 0.0, h, frame) for y in (-w / 2 + hb / 2, w / 2 - hb / 2)]
    if style == 'slats':
        slats = [_blk(0.2 * hb, 0.8 * hb, a + 0.25 * (b - a), b - 0.25 * (b - a), 0.3 * h, 0.9 * h, frame)
                 for a, b in _split(-w / 2 + hb, w / 2 - hb, _count(w, 0.18, 4, 10))]
        return posts + slats + [_blk(0.0, hb, -w / 2, w / 2, 0.9 * h, h, frame)]
    if style == 'posts':
        return posts + [_blk(0.15 * hb, 0.85 * hb, -w / 2 + hb, w / 2 - hb, 0.3 * h, 0.92 * h, frame)]
    bars = [_blk(0.35 * hb, 0.65 * hb, y - 0.15 * hb, y + 0.15 * hb, 0.3 * h, 0.9 * h, frame)
            for y in np.linspace(-w / 2 + hb, w / 2 - hb, _count(w, 0.25, 4, 8) + 2)[1:-1]]
    rails = [_blk(0.25 * hb, 0.75 * hb, -w / 2, w / 2, z - 0.25 * hb, z + 0.25 * hb, frame)
             for z in (0.3 * h, 0.9 * h)]
    return posts + bars + rails


def _footboard(d: float, hb: float, w: float, h: float, frame: str, style: str) -> Parts:
    if style == 'slats':
        return [_blk(d - hb, d, -w / 2, w / 2, 0.0, 0.56 * h, frame)]
    if style in ('posts', 'metal'):
        return [_blk(d - hb, d, y - hb / 2, y + hb / 2, 0.0, 0.6 * h, frame)
                for y in (-w / 2 + hb / 2, w / 2 - hb / 2)]
    return []


def _table(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    style = v % 4
    tt = min(0.04, 0.1 * h)
    under = h - tt
    if style == 0:  # wooden, legs and apron
        t = min(0.06, 0.1 * min(d, w))
        return _legs(0.03 * d, 0.97 * d, -0.47 * w, 0.47 * w, 0.0, under, t, 'wood_medium') + [
            _blk(0.03 * d, 0.97 * d, -0.47 * w, 0.47 * w, under - min(0.08, 0.15 * h), under, 'wood_medium'),
            _blk(0.0, d, -w / 2, w / 2, under, h, 'wood_medium')]
    if style == 1:  # glass top on chrome legs
        t = min(0.04, 0.08 * min(d, w))
        return _legs(0.05 * d, 0.95 * d, -0.45 * w, 0.45 * w, 0.0, under, t, 'chrome', round_=True) + [
            _blk(0.0, d, -w / 2, w / 2, under, h, 'glass')]
    if style == 2:  # round pedestal table
        return [_disc(d / 2, 0.0, under, h, d / 2, w / 2, 'wood_dark', 12),
                _post(d / 2, 0.0, 0.03 * h, under, min(0.05, 0.1 * min(d, w)), 'wood_dark'),
                _disc(d / 2, 0.0, 0.0, 0.03 * h, 0.3 * d, 0.3 * w, 'wood_dark', 8)]
    t = min(0.04, 0.08 * min(d, w))  # white top on two black trestles
    trestles = [part for y in (-0.42 * w, 0.42 * w) for part in (
        _blk(0.05 * d, 0.95 * d, y - t / 2, y + t / 2, 0.0, t, 'black'),
        _blk(0.05 * d, 0.95 * d, y - t / 2, y + t / 2, under - t, under, 'black'),
        _blk(0.5 * d - t / 2, 0.5 * d + t / 2, y - t / 2, y + t / 2, 0.0, under, 'black'))]
    return trestles + [_blk(0.0, d, -w / 2, w / 2, under, h, 'white')]


_DESKS = (_Finish('wood_light', 'wood_light', 'metal'), _Finish('black', 'white', 'chrome'),
          _Finish('wood_dark', 'wood_dark', 'brass'))


def _desk(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Writing desk: a top on four legs with a drawer, or on a side panel and a drawer pedestal."""
    finish = _pick(_DESKS, v)
    tt, t = min(0.035, 0.06 * h), min(0.04, 0.05 * w)
    under = h - tt
    parts = [_blk(0.0, d, -w / 2, w / 2, under, h, finish.panel)]
    if v % 3 == 1:
        drawer = under - min(0.1, 0.15 * h)
        carcass, xf = _carcass(d, -0.2 * w, 0.2 * w, drawer, under, finish.body)
        return parts + _legs(0.03 * d, 0.97 * d, -0.48 * w, 0.48 * w, 0.0, under, t, finish.body) + [
            carcass] + _fronts(xf, d, [_Front(-0.2 * w, 0.2 * w, drawer, under, 'drawer')], finish)
    side = 1.0 if v % 3 == 0 else -1.0
    inner, outer = side * (w / 2 - min(0.42, 0.32 * w)), side * w / 2
    carcass, xf = _carcass(d, min(inner, outer), max(inner, outer), 0.0, under, finish.body)
    drawers = _drawer_grid(min(inner, outer), max(inner, outer), 0.02 * h, under, 3 if side > 0 else 2, 1)
    panel_y = -side * (w / 2 - t / 2)
    return parts + [carcass, _blk(0.0, d, panel_y - t / 2, panel_y + t / 2, 0.0, under, finish.body),
                    _blk(0.0, t, -w / 2, w / 2, 0.35 * h, under, finish.body)] + _fronts(
        xf, d, drawers, finish)


# --- storage ------------------------------------------------------------------------------

_CABINETS = (_Finish('white', 'white', 'chrome', 'knob'), _Finish('wood_medium', 'wood_medium', 'brass'),
             _Finish('grey_light', 'grey_light', 'metal'), _Finish('wood_dark', 'wood_dark', 'brass', 'knob'))


def _cabinet(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Doors only; glazed doors over solid ones; drawers over doors; open shelves over doors."""
    finish = _pick(_CABINETS, v)
    style = v % 4
    ph = min(0.08, 0.08 * h)
    carcass, xf = _carcass(d, -w / 2, w / 2, ph, h, finish.body)
    cols = _count(w, 0.45, 1, 4)
    parts = [_plinth(d, w, ph, 'grey_light' if finish.body == 'white' else 'charcoal'), carcass]
    if style == 0:
        return parts + _fronts(xf, d, _door_row(-w / 2, w / 2, ph, h, cols), finish)
    split = ph + (0.5 if h > 0.9 else 0.6) * (h - ph)
    lower = _door_row(-w / 2, w / 2, ph, split, cols, 'top')
    if style == 1:
        glazed = [_Front(f.y0, f.y1, f.z0, f.z1, f.handle, 'bottom', 'glass_dark')
                  for f in _door_row(-w / 2, w / 2, split, h, cols)]
        return parts + _fronts(xf, d, glazed + lower, finish)
    if style == 2:
        top = h - min(0.4, 0.35 * (h - ph))
        fronts = _drawer_grid(-w / 2, w / 2, top, h, 2, cols) + _door_row(-w / 2, w / 2, ph, top, cols, 'top')
        return parts + _fronts(xf, d, fronts, finish)
    return parts + _open_shelves(xf, d, w, split, h, finish.body) + _fronts(xf, d, lower, finish)


_CLOSETS = (_Finish('white', 'white', 'chrome', 'long'),
            _Finish('wood_medium', 'wood_medium', 'brass', 'knob'),
            _Finish('wood_light', 'wood_light', 'metal', 'long'), _Finish('wood_dark', 'wood_dark', 'brass'))


def _closet(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Wardrobe: hinged doors; with a cornice; sliding wood and mirror panels; doors over drawers."""
    finish = _pick(_CLOSETS, v)
    style = v % 4
    ph = min(0.08, 0.05 * h)
    top = h - (min(0.06, 0.03 * h) if style == 1 else 0.0)
    carcass, xf = _carcass(d, -w / 2, w / 2, ph, top, finish.body)
    parts = [_plinth(d, w, ph, 'charcoal'), carcass, _blk(0.0, d, -w / 2, w / 2, top, h, finish.body)]
    n = _count(w, 0.5, 2, 6)
    if style == 2:
        panels = [_Front(a, b, ph, top, 'left' if i % 2 else 'right', colour='mirror' if i % 2 else '')
                  for i, (a, b) in enumerate(_split(-w / 2, w / 2, max(2, n // 2)))]
        return parts + _fronts(xf, d, panels, finish)
    if style == 3:
        split = ph + min(0.45, 0.22 * (h - ph))
        fronts = _door_row(-w / 2, w / 2, split, top, n) + _drawer_grid(-w / 2, w / 2, ph, split, 2, n)
        return parts + _fronts(xf, d, fronts, finish)
    return parts + _fronts(xf, d, _door_row(-w / 2, w / 2, ph, top, n), finish)


_DRESSERS = ((_Finish('wood_light', 'wood_light', 'wood_dark', 'knob'), 3, 'legs'),
             (_Finish('white', 'white', 'chrome'), 4, 'plinth'),
             (_Finish('wood_dark', 'wood_red', 'brass', 'knob'), 3, 'buns'))


def _dresser(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Chest of drawers: a row of small drawers over wide ones, on legs, a plinth or bun feet."""
    finish, rows, feet = _pick(_DRESSERS, v)
    fh, tt = min(0.1, 0.15 * h), min(0.03, 0.06 * h)
    carcass, xf = _carcass(d, -w / 2, w / 2, fh, h - tt, finish.body)
    cols = 2 if w > 0.8 else 1
    small = h - tt - (h - tt - fh) / (rows + 1)
    fronts = (_drawer_grid(-w / 2, w / 2, fh, small, rows - 1, cols)
              + _drawer_grid(-w / 2, w / 2, small, h - tt, 1, cols + 1))
    return [carcass, _blk(0.0, d, -w / 2, w / 2, h - tt, h, finish.body)] + _feet(
        d, w, fh, finish.body, feet) + _fronts(xf, d, fronts, finish)


def _feet(d: float, w: float, fh: float, colour: str, kind: str) -> Parts:
    if kind == 'plinth':
        return [_plinth(d, w, fh, colour)]
    t = min(0.05, 0.12 * min(d, w))
    if kind == 'buns':
        return [_post(x, y, 0.0, fh, t / 2, colour)
                for x in (t / 2, d - t / 2) for y in (-w / 2 + t / 2, w / 2 - t / 2)]
    return _legs(0.0, d, -w / 2, w / 2, 0.0, fh, t, colour)


_NIGHTSTANDS = ((_Finish('wood_medium', 'wood_medium', 'black'), 'legs'),
                (_Finish('white', 'white', 'chrome'), 'plinth'),
                (_Finish('wood_dark', 'wood_dark', 'brass', 'knob'), 'buns'))


def _nightstand(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Drawer over an open shelf on legs; two drawers; three drawers."""
    finish, feet = _pick(_NIGHTSTANDS, v)
    style = v % 3
    fh, tt = min(0.12 if style == 0 else 0.05, 0.2 * h), min(0.025, 0.06 * h)
    carcass, xf = _carcass(d, -w / 2, w / 2, fh, h - tt, finish.body)
    parts = [carcass, _blk(0.0, d, -w / 2, w / 2, h - tt, h, finish.body)]
    parts += _feet(d, w, fh, finish.body, feet)
    if style == 0:
        split = fh + 0.55 * (h - tt - fh)
        return parts + _open_shelves(xf, d, w, fh, split, finish.body, books=False) + _fronts(
            xf, d, [_Front(-w / 2, w / 2, split, h - tt, 'drawer')], finish)
    return parts + _fronts(xf, d, _drawer_grid(-w / 2, w / 2, fh, h - tt, style + 1, 1), finish)


def _shelf(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Wall shelf (wall at x = 0): wooden board; white board on brackets; glass on clamps."""
    style = v % 3
    if style == 0:
        return [_soft(0.0, d, -w / 2, w / 2, 0.0, h, 'wood_light', 0.15 * min(d, h))]
    if style == 1:
        t = min(0.02, 0.05 * w)
        return [_blk(0.0, d, -w / 2, w / 2, 0.45 * h, h, 'white')] + [
            _blk(0.0, 0.8 * d, y - t / 2, y + t / 2, 0.0, 0.45 * h, 'black') for y in (-0.35 * w, 0.35 * w)]
    t = min(0.03, 0.05 * w)
    return [_blk(0.0, d, -w / 2, w / 2, 0.25 * h, 0.75 * h, 'glass')] + [
        _blk(0.0, 0.25 * d, y - t, y + t, 0.0, h, 'chrome') for y in (-0.35 * w, 0.35 * w)]


def _standard(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Racks ('rack_N' prefabs): bookcase, cube shelving, metal rack, bookcase over cupboard;
    or a low TV unit ('Tv Table')."""
    if 'tv' in prefab.lower():
        return _tv_unit(d, w, h, v)
    style = v % 4
    if style == 2:
        return _metal_rack(d, w, h)
    colour = {0: 'wood_medium', 1: 'white', 3: 'wood_dark'}[style]
    t = min(0.025, 0.05 * min(d, w))
    levels = np.linspace(0.0, h - t, _count(h, 0.36, 1, 6) + 1)
    openings = [(float(a + t), float(b)) for a, b in zip(levels[:-1], levels[1:])]
    parts = [_blk(0.0, d, y - t / 2, y + t / 2, 0.0, h, colour) for y in (-w / 2 + t / 2, w / 2 - t / 2)]
    parts += [_blk(0.0, d, -w / 2 + t, w / 2 - t, z, z + t, colour) for z in levels]
    back = 'grey_light' if style == 1 else 'charcoal'
    parts.append(_blk(0.0, 0.02 * d, -w / 2 + t, w / 2 - t, 0.0, h, back))
    if style == 1:
        return parts + _cubbies(d, w, h, t, colour, openings)
    if style == 3:
        ft, hd = _front_depths(d)
        doors = _door_row(-w / 2 + t, w / 2 - t, *openings[0], _count(w, 0.45, 1, 4))
        return parts + _books(0.2 * d, d - ft - hd, -w / 2 + t, w / 2 - t, openings[1:]) + _fronts(
            d - ft - hd, d, doors, _Finish(colour, colour, 'brass', 'knob'))
    return parts + _books(0.15 * d, 0.95 * d, -w / 2 + t, w / 2 - t, openings)


def _cubbies(d: float, w: float, h: float, t: float, colour: str,
             openings: Sequence[tuple[float, float]]) -> Parts:
    """Cube shelving: a middle divider when wide, fabric boxes in most cubbies."""
    columns = _split(-w / 2 + t, w / 2 - t, 2 if w > 0.6 else 1)
    parts = [_blk(0.0, d, -t / 2, t / 2, 0.0, h, colour)] if len(columns) == 2 else []
    for i, (z0, z1) in enumerate(openings):
        for j, (a, b) in enumerate(columns):
            if (i + j) % 3 != 2:  # leave some cubbies open
                margin = 0.08 * (b - a)
                parts.append(_blk(0.3 * d, d, a + margin, b - margin, z0, z0 + 0.8 * (z1 - z0),
                                  _pick(_BOOK_COLOURS, i + j)))
    return parts


def _metal_rack(d: float, w: float, h: float) -> Parts:
    """Four black posts, grey shelves and a few boxes."""
    t = min(0.025, 0.08 * min(d, w))
    levels = np.linspace(0.05 * h, h - t / 2, _count(h, 0.4, 1, 5) + 1)
    parts = [_blk(x, x + t, y, y + t, 0.0, h, 'black') for x in (0.0, d - t) for y in (-w / 2, w / 2 - t)]
    parts += [_blk(0.0, d, -w / 2, w / 2, z - t / 4, z + t / 4, 'metal') for z in levels]
    for i, (z0, z1) in enumerate(zip(levels[:-1], levels[1:])):
        y0 = -0.4 * w if i % 2 == 0 else 0.05 * w
        parts.append(_blk(0.15 * d, 0.85 * d, y0, y0 + 0.35 * w, z0 + t / 4, z0 + 0.6 * (z1 - z0),
                          _pick(('cream', 'wood_light', 'fabric_blue'), i)))
    return parts


_TV_UNITS = (_Finish('wood_medium', 'white', 'chrome'), _Finish('white', 'white', 'chrome', 'knob'),
             _Finish('black', 'wood_light', 'black'), _Finish('wood_dark', 'wood_dark', 'brass'))


def _tv_unit(d: float, w: float, h: float, v: int) -> Parts:
    """Low sideboard: drawers at both ends, an open bay in the middle, short legs."""
    finish = _pick(_TV_UNITS, v)
    fh = min(0.08, 0.25 * h)
    carcass, xf = _carcass(d, -w / 2, w / 2, fh, h, finish.body)
    side = min(0.4, 0.35 * w)
    fronts = [_Front(-w / 2, -w / 2 + side, fh, h, 'drawer'), _Front(w / 2 - side, w / 2, fh, h, 'drawer')]
    legs = _legs(0.05 * d, 0.95 * d, -0.48 * w, 0.48 * w, 0.0, fh, min(0.04, 0.1 * d), 'black')
    bay = _open_shelves(xf, d, w - 2 * side, fh, h, finish.body, books=False)
    return [carcass] + legs + bay + _fronts(xf, d, fronts, finish)


# --- kitchen --------------------------------------------------------------------------------

_KITCHEN = (_Finish('white', 'white', 'chrome'), _Finish('off_white', 'wood_medium', 'steel'),
            _Finish('grey', 'grey_dark', 'chrome'), _Finish('cream', 'cream', 'brass', 'knob'))


def _kitchen(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Kitchen unit carcass and fronts.

    Worktops, basins and hobs are separate Counter, Sink and Burner objects
    upstream, so units stop at their own top.  The prefab names the layout:
    wall-hung ('Up'), door count ('2Door', '3 Door Up'), 'Corner', 'Sink'
    (false drawer over doors) or 'Burner and Oven' (oven door over a drawer).
    """
    name = prefab.lower()
    finish = _pick(_KITCHEN, v)
    digits = re.findall(r'(\d)\s*door', name)
    doors = int(digits[0]) if digits else _count(w, 0.5, 1, 3) if name else 1 + v % 3
    wall = 'up' in name.split()
    ph = 0.0 if wall else min(0.1, 0.12 * h)
    carcass, xf = _carcass(d, -w / 2, w / 2, ph, h, finish.body)
    parts = [carcass] if wall else [carcass, _plinth(d, w, ph, 'charcoal')]
    if 'oven' in name:
        drawer = ph + 0.2 * (h - ph)
        return parts + _fronts(xf, d, [_Front(-w / 2, w / 2, ph, drawer, 'drawer')], finish) + _oven_front(
            xf, d, w, drawer, h, 'black')
    if 'sink' in name:
        top = h - 0.18 * (h - ph)
        under_sink = _door_row(-w / 2, w / 2, ph, top, _count(w, 0.5, 1, 2), 'top')
        fronts = [_Front(-w / 2, w / 2, top, h, 'drawer')] + under_sink
        return parts + _fronts(xf, d, fronts, finish)
    height = 'bottom' if wall else 'top'
    if 'corner' in name:  # a blind panel where the neighbouring run butts in
        fronts = [_Front(-w / 2, -0.1 * w, ph, h, 'none'), _Front(-0.1 * w, w / 2, ph, h, 'left', height)]
    else:
        fronts = _door_row(-w / 2, w / 2, ph, h, doors, height)
    return parts + _fronts(xf, d, fronts, finish)


def _oven_front(xf: float, d: float, w: float, z0: float, z1: float, colour: str) -> Parts:
    """Oven door with a dark window and a bar handle, under a steel control strip with knobs."""
    strip = min(0.1, 0.15 * (z1 - z0))
    ft, _ = _front_depths(d)
    window = _blk(xf + ft, xf + 1.15 * ft, -0.35 * w, 0.35 * w, z0 + 0.2 * (z1 - z0),
                  z1 - strip - 0.25 * (z1 - z0), 'glass_dark')
    knobs = [_rod((xf + ft, y, z1 - strip / 2), (d, y, z1 - strip / 2), min(0.018, 0.3 * strip), 'metal')
             for y in np.linspace(-0.35 * w, 0.35 * w, 4)]
    door = _Front(-w / 2, w / 2, z0, z1 - strip, 'drawer')
    return _fronts(xf, d, [door], _Finish(colour, colour, 'chrome')) + knobs + [
        window, _blk(xf, xf + ft, -w / 2, w / 2, z1 - strip, z1, 'steel')]


def _counter(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Worktop slab with a front edge band."""
    top, edge = _pick((('marble', 'marble'), ('granite', 'granite'), ('wood_light', 'wood_medium'),
                       ('white', 'steel')), v)
    e = min(0.02, 0.06 * d)
    return [_blk(0.0, d - e, -w / 2, w / 2, 0.0, h, top), _blk(d - e, d, -w / 2, w / 2, 0.0, h, edge)]


def _burner(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Black glass hob with four burners."""
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.0, 0.6 * h, 'black')]
    r = 0.2 * min(d, w)
    for x in (0.28 * d, 0.72 * d):
        for y in (-0.23 * w, 0.23 * w):
            parts += [_disc(x, y, 0.0, 0.8 * h, r, r, 'grey_dark', 8),
                      _disc(x, y, 0.0, h, r / 2, r / 2, 'charcoal', 8)]
    return parts


def _tap(x: float, y: float, z0: float, z1: float, reach: float) -> Parts:
    """Chrome tap: a pillar from z0 to z1 and a spout reaching along +x."""
    r = min(0.015, 0.08 * (z1 - z0))
    return [_post(x, y, z0, z1, r, 'chrome'), _rod((x, y, z1 - r), (x + reach, y, z1 - r), 0.8 * r, 'chrome'),
            _blk(x + reach - r, x + reach + r, y - r, y + r, z1 - 3 * r, z1 - r, 'chrome')]


def _sink(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """A basin set into a worktop, with its tap: steel single, ceramic bowl, steel double."""
    style = v % 3
    tap = _tap(0.08 * d, 0.0, 0.55 * h, h, 0.3 * d)
    if style == 1:
        rx, ry = 0.42 * d, 0.5 * w
        return tap + [_disc(0.58 * d, 0.0, 0.0, 0.6 * h, 0.6 * rx, 0.6 * ry, 'ceramic', 12, top=1 / 0.6),
                      _disc(0.58 * d, 0.0, 0.59 * h, 0.61 * h, 0.8 * rx, 0.8 * ry, 'ceramic_shade', 12)]
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.5 * h, 0.55 * h, 'steel')]
    for a, b in _split(-0.45 * w, 0.45 * w, 2 if style == 2 else 1):
        parts += [_blk(0.2 * d, 0.95 * d, a + 0.02 * w, b - 0.02 * w, 0.0, 0.5 * h, 'steel'),
                  _blk(0.22 * d, 0.93 * d, a + 0.04 * w, b - 0.04 * w, 0.55 * h, 0.56 * h, 'grey')]
    return parts + tap


_FRIDGES = (('white', 'grey_light', False), ('steel', 'chrome', False), ('cream', 'chrome', True))


def _fridge(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Fridge door over a freezer door (or a small freezer on top), long handles."""
    colour, handle, freezer_top = _pick(_FRIDGES, v)
    carcass, xf = _carcass(d, -w / 2, w / 2, 0.0, h, colour)
    split = (0.72 if freezer_top else 0.36) * h
    doors = [_Front(-w / 2, w / 2, split, h, 'left', 'bottom' if freezer_top else 'mid'),
             _Front(-w / 2, w / 2, 0.02 * h, split, 'left', 'mid' if freezer_top else 'top')]
    return [carcass, _blk(0.0, 0.95 * d, -0.48 * w, 0.48 * w, 0.0, 0.02 * h, 'charcoal')] + _fronts(
        xf, d, doors, _Finish(colour, colour, handle, 'long'))


def _oven(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    carcass, xf = _carcass(d, -w / 2, w / 2, 0.0, h, 'charcoal')
    return [carcass] + _oven_front(xf, d, w, 0.0, h, 'steel')


def _microwave(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Steel box, door with a dark window on the left, control panel with buttons on the right."""
    ft, hd = _front_depths(d)
    xf = d - ft - hd
    panel = 0.28 * w
    button = 0.06 * panel
    buttons = [_blk(xf + ft, xf + ft + 0.3 * hd, y - button, y + button, z - 0.03 * h, z + 0.03 * h, 'grey')
               for z in (0.25 * h, 0.42 * h, 0.6 * h) for y in (w / 2 - 0.35 * panel, w / 2 - 0.65 * panel)]
    door = _Front(-0.48 * w, w / 2 - panel, 0.05 * h, 0.95 * h, 'right')
    return [_soft(0.0, xf, -w / 2, w / 2, 0.0, h, 'steel', 0.04 * min(d, h)),
            _blk(xf + ft, xf + 1.1 * ft, -0.42 * w, w / 2 - panel - 0.08 * w, 0.2 * h, 0.8 * h, 'glass_dark'),
            _blk(xf, xf + ft, w / 2 - panel, 0.48 * w, 0.1 * h, 0.9 * h, 'charcoal'),
            _blk(xf + ft, xf + 1.2 * ft, w / 2 - 0.8 * panel, w / 2 - 0.2 * panel, 0.7 * h, 0.8 * h,
                 'led')] + _fronts(xf, d, [door], _Finish('steel', 'black', 'steel')) + buttons


def _dishwasher(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Steel door with a bar handle under a dark control strip, black kick plate."""
    carcass, xf = _carcass(d, -w / 2, w / 2, 0.0, h, 'grey')
    strip = min(0.1, 0.12 * h)
    ft, _ = _front_depths(d)
    return [carcass, _blk(xf, xf + ft, -w / 2, w / 2, h - strip, h, 'charcoal'),
            _blk(xf + ft, xf + 1.15 * ft, 0.25 * w, 0.4 * w, h - 0.6 * strip, h - 0.4 * strip, 'led'),
            _blk(xf, xf + ft, -0.48 * w, 0.48 * w, 0.0, 0.08 * h, 'black')] + _fronts(
        xf, d, [_Front(-w / 2, w / 2, 0.08 * h, h - strip, 'drawer')], _Finish('steel', 'steel', 'chrome'))


def _washing_machine(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """White cube, round door with dark glass, control strip with drawer and dial."""
    _, hd = _front_depths(d)
    xf = d - hd
    strip = min(0.12, 0.15 * h)
    r = 0.36 * min(w, h - strip)
    zc = 0.05 * h + (h - strip) / 2
    return [_blk(0.0, xf, -w / 2, w / 2, 0.0, h, 'white'),
            _blk(xf, xf + 0.1 * hd, -0.46 * w, 0.46 * w, h - strip, h - 0.1 * strip, 'off_white'),
            _blk(xf, xf + 0.3 * hd, -0.44 * w, -0.1 * w, h - 0.8 * strip, h - 0.25 * strip, 'grey_light'),
            _rod((xf, 0.3 * w, h - strip / 2), (d, 0.3 * w, h - strip / 2), 0.3 * strip, 'grey', 8),
            _rod((xf, 0.0, zc), (xf + 0.6 * hd, 0.0, zc), r, 'chrome', 12),
            _rod((xf, 0.0, zc), (d, 0.0, zc), 0.75 * r, 'glass_dark', 12)]


# --- bathroom ------------------------------------------------------------------------------

def _toilet(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Cistern at the back (x = 0), bowl with seat and lid reaching forward along the long axis."""
    seat_z = 0.45 * h
    bowl_x, rx, ry = 0.62 * d, 0.38 * d, 0.5 * w
    return [_disc(bowl_x, 0.0, 0.0, seat_z - 0.04 * h, 0.55 * rx, 0.55 * ry, 'ceramic', 12, top=1 / 0.55),
            _disc(bowl_x, 0.0, seat_z - 0.04 * h, seat_z - 0.02 * h, rx, ry, 'grey_light', 12),
            _disc(bowl_x, 0.0, seat_z - 0.02 * h, seat_z, 0.97 * rx, 0.97 * ry, 'white', 12),
            _blk(0.1 * d, 0.45 * d, -0.3 * w, 0.3 * w, 0.15 * h, seat_z - 0.02 * h, 'ceramic'),
            _soft(0.0, 0.3 * d, -0.44 * w, 0.44 * w, seat_z, 0.96 * h, 'ceramic', 0.02 * d),
            _blk(0.0, 0.32 * d, -0.46 * w, 0.46 * w, 0.959 * h, 0.98 * h, 'ceramic'),
            _disc(0.16 * d, 0.0, 0.98 * h, h, 0.05 * d, 0.05 * d, 'chrome', 8)]


def _washbasin(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Basin on a vanity with doors, on a pedestal, or on a drawer unit; a mirror above in tall boxes."""
    style = v % 3
    tall = h > 1.05
    counter = min(0.85, 0.8 * h) if tall else 0.78 * h
    basin = min(0.15, 0.18 * counter)
    parts = [_soft(0.0, d, -w / 2, w / 2, counter - basin, counter, 'ceramic', 0.3 * basin),
             _blk(0.25 * d, 0.9 * d, -0.38 * w, 0.38 * w, counter - 0.01 * basin, counter + 0.02 * basin,
                  'ceramic_shade')]
    parts += _tap(0.1 * d, 0.0, counter, counter + 0.3 * (h - counter) if tall else h, 0.2 * d)
    if tall:
        above = h - counter
        parts += _frame(0.0, 0.05 * d, -0.42 * w, 0.42 * w, counter + 0.4 * above, h, 0.06 * above,
                        'wood_medium' if style == 0 else 'chrome')
        parts.append(_blk(0.0, 0.04 * d, -0.4 * w, 0.4 * w, counter + 0.4 * above, h, 'mirror'))
    if style == 1:
        return parts + [_disc(0.35 * d, 0.0, 0.0, counter - basin, 0.18 * d, 0.12 * w, 'ceramic', 8, top=1.3)]
    body = 'wood_medium' if style == 0 else 'white'
    finish = _Finish(body, body, 'chrome')
    z0 = 0.0 if style == 0 else 0.25 * counter  # the drawer unit hangs on the wall over its waste pipe
    carcass, xf = _carcass(d, -0.48 * w, 0.48 * w, z0, counter - basin, finish.body)
    if style == 0:
        doors = _door_row(-0.48 * w, 0.48 * w, z0, counter - basin, 2, 'top')
        return parts + [carcass] + _fronts(xf, d, doors, finish)
    return parts + [carcass, _post(0.2 * d, 0.0, 0.0, z0, min(0.02, 0.05 * w), 'chrome')] + _fronts(
        xf, d, _drawer_grid(-0.48 * w, 0.48 * w, z0, counter - basin, 2, 1), finish)


def _shower(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Tray, chrome frame, glass side walls, sliding glass door on the front, shower at the back."""
    tray = min(0.12, 0.06 * h)
    t = min(0.03, 0.04 * min(d, w))
    g = 0.3 * t
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.0, tray, 'ceramic'),
             _blk(0.0, g, -w / 2, w / 2, tray, h, 'ceramic_shade')]
    parts += [_blk(x, x + t, y, y + t, tray, h, 'chrome') for x in (0.0, d - t) for y in (-w / 2, w / 2 - t)]
    parts += [_blk(0.0, d, y, y + t, h - t, h, 'chrome') for y in (-w / 2, w / 2 - t)]
    parts += [_blk(d - t, d, -w / 2 + t, w / 2 - t, h - t, h, 'chrome'),
              _blk(t, d - t, -w / 2 + 0.35 * t, -w / 2 + 0.65 * t, tray, h - t, 'glass'),
              _blk(t, d - t, w / 2 - 0.65 * t, w / 2 - 0.35 * t, tray, h - t, 'glass'),
              _blk(d - t, d - t + g, -w / 2 + t, 0.05 * w, tray, h - t, 'glass'),
              _blk(d - g, d, -0.05 * w, w / 2 - t, tray, h - t, 'glass'),
              _blk(d - g - t, d - g, -0.02 * w, 0.0, 0.45 * h, 0.6 * h, 'chrome')]
    riser_y, r = 0.25 * w, min(0.01, 0.3 * t)
    head = min(0.1, 0.15 * d)
    return parts + [_post(g + 2 * r, riser_y, 0.4 * h, 0.9 * h, r, 'chrome'),
                    _rod((g, riser_y, 0.9 * h), (0.25 * d, riser_y, 0.9 * h), r, 'chrome'),
                    _disc(0.25 * d, riser_y, 0.88 * h, 0.9 * h, head, head, 'chrome', 8)]


def _bathtub(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """White tub along y with its tap at the -y end; tall boxes ('Bathtub 2') add a shower."""
    tap = min(0.15, 0.2 * h)
    rim_h = min(0.58, h - tap)
    rim, lip = min(0.08, 0.12 * min(d, w)), min(0.03, 0.1 * rim_h)
    shell = rim_h - lip
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.0, shell, 'ceramic'),
             _blk(rim, d - rim, -w / 2 + rim, w / 2 - rim, shell, shell + 0.2 * lip, 'ceramic_shade')]
    parts += [_blk(0.0, d, -w / 2, -w / 2 + rim, shell, rim_h, 'ceramic'),  # the rim
              _blk(0.0, d, w / 2 - rim, w / 2, shell, rim_h, 'ceramic'),
              _blk(0.0, rim, -w / 2 + rim, w / 2 - rim, shell, rim_h, 'ceramic'),
              _blk(d - rim, d, -w / 2 + rim, w / 2 - rim, shell, rim_h, 'ceramic')]
    parts += _tap(0.3 * rim, -w / 2 + 0.5 * rim, rim_h, rim_h + tap, 0.0)
    if h > 1.2:
        screen, r = 0.1 * rim, min(0.012, 0.03 * d)
        xs = d - rim / 2
        parts += [_blk(xs - screen, xs + screen, -w / 2 + rim, -0.05 * w, rim_h, 0.85 * h, 'glass'),
                  _post(2 * r, -w / 2 + rim, rim_h, h, r, 'chrome'),
                  _disc(0.1 * d, -w / 2 + rim, h - 0.02 * h, h, 0.1 * d, 0.1 * d, 'chrome', 8)]
    return parts


_TOWELS = (('white', 'grey_light'), ('fabric_blue', 'white'), ('fabric_pink', ''), ('fabric_green', 'cream'))


def _towel(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Towel folded over a wall bar (wall at x = 0), in different colours and stripes."""
    cloth, stripe = _pick(_TOWELS, v)
    r = min(0.012, 0.15 * d)
    bar_z, xc = h - 2 * r, 0.55 * d
    parts = [_rod((xc, -w / 2, bar_z), (xc, w / 2, bar_z), r, 'chrome'),
             _blk(0.0, 0.1 * d, -w / 2, -w / 2 + 2 * r, bar_z - 2 * r, bar_z + r, 'chrome'),
             _blk(0.0, 0.1 * d, w / 2 - 2 * r, w / 2, bar_z - 2 * r, bar_z + r, 'chrome'),
             _blk(0.15 * d, xc - r, -0.44 * w, 0.44 * w, 0.2 * h, bar_z, cloth),
             _blk(xc + r, 0.95 * d, -0.44 * w, 0.44 * w, 0.0, bar_z, cloth),
             _soft(0.15 * d, 0.95 * d, -0.44 * w, 0.44 * w, bar_z - r, h, cloth, 0.3 * d)]
    if stripe:
        parts += [_blk(0.95 * d, d, -0.44 * w, 0.44 * w, z, z + 0.05 * h, stripe)
                  for z in (0.08 * h, 0.16 * h)]
    return parts


def _drying(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Heated towel rail (wall at x = 0): chrome ladder; white panel radiator; black ladder with towel."""
    style = v % 3
    colour = ('chrome', 'white', 'black')[style]
    r = min(0.015, 0.2 * d, 0.05 * w)
    xc = d - 1.5 * r
    brackets = [_blk(0.0, xc, y - r / 2, y + r / 2, z - r / 2, z + r / 2, colour)
                for y in (-w / 2 + r, w / 2 - r) for z in (0.2 * h, 0.85 * h)]
    if style == 1:
        tubes = [_blk(xc - r, xc + r, y - 0.35 * r, y + 0.35 * r, 0.05 * h, 0.95 * h, colour)
                 for y in np.linspace(-w / 2 + 2 * r, w / 2 - 2 * r, _count(w, 0.05, 4, 12))]
        headers = [_rod((xc, -w / 2, z), (xc, w / 2, z), 1.5 * r, colour) for z in (0.05 * h, 0.95 * h)]
        return brackets + tubes + headers
    parts = brackets + [_post(xc, y, 0.0, h, r, colour) for y in (-w / 2 + r, w / 2 - r)] + [
        _rod((xc, -w / 2 + r, z), (xc, w / 2 - r, z), 0.7 * r, colour)
        for z in np.linspace(0.12 * h, 0.95 * h, _count(h, 0.1, 3, 9))]
    if style == 2:
        parts += [_blk(xc - 2.5 * r, xc - r, -0.3 * w, 0.3 * w, 0.45 * h, 0.97 * h, 'fabric_teal'),
                  _blk(xc + r, xc + 1.5 * r, -0.3 * w, 0.3 * w, 0.3 * h, 0.97 * h, 'fabric_teal'),
                  _blk(xc - 2.5 * r, xc + 1.5 * r, -0.3 * w, 0.3 * w, 0.95 * h, h, 'fabric_teal')]
    return parts


def _cup(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Mug of coffee with its handle on the +y side."""
    hw = 0.25 * w
    r, cy = min(d / 2, (w - hw) / 2), -hw / 2
    t = 0.2 * hw
    y1 = cy + r + hw
    return [_disc(d / 2, cy, 0.0, 0.97 * h, r, r, 'ceramic', 12),
            _disc(d / 2, cy, 0.96 * h, h, 0.8 * r, 0.8 * r, 'coffee', 12),
            _blk(d / 2 - t, d / 2 + t, y1 - t, y1, 0.25 * h, 0.8 * h, 'ceramic'),
            _blk(d / 2 - t, d / 2 + t, cy + 0.9 * r, y1, 0.7 * h, 0.8 * h, 'ceramic'),
            _blk(d / 2 - t, d / 2 + t, cy + 0.9 * r, y1, 0.25 * h, 0.35 * h, 'ceramic')]


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


def _brush(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Toilet brush standing in its holder."""
    r = min(d, w) / 2
    return [_disc(d / 2, 0.0, 0.0, 0.4 * h, 0.85 * r, 0.85 * r, 'white', 8, top=1 / 0.85),
            _disc(d / 2, 0.0, 0.4 * h, 0.42 * h, r, r, 'chrome', 8),
            _post(d / 2, 0.0, 0.42 * h, 0.93 * h, 0.12 * r, 'grey_light'),
            _ell(d / 2 - 0.18 * r, d / 2 + 0.18 * r, -0.18 * r, 0.18 * r, 0.9 * h, h, 'chrome')]


# --- lighting ------------------------------------------------------------------------------

def _lamp(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Table lamp; standing lamp; desk lamp with a jointed arm; globe lamp."""
    style = v % 4
    rx, ry, cx = d / 2, w / 2, d / 2
    if style == 0:
        return [_disc(cx, 0.0, 0.0, 0.08 * h, 0.4 * rx, 0.4 * ry, 'ceramic_blue', 8),
                _disc(cx, 0.0, 0.08 * h, 0.45 * h, 0.3 * rx, 0.3 * ry, 'ceramic_blue', 8, top=0.5),
                _post(cx, 0.0, 0.45 * h, 0.6 * h, 0.05 * min(rx, ry), 'brass'),
                _disc(cx, 0.0, 0.55 * h, h, rx, ry, 'lamp_shade', 12, top=0.6)]
    if style == 1:
        return [_disc(cx, 0.0, 0.0, 0.03 * h, 0.6 * rx, 0.6 * ry, 'charcoal', 12),
                _post(cx, 0.0, 0.03 * h, 0.75 * h, 0.06 * min(rx, ry), 'metal'),
                _disc(cx, 0.0, 0.7 * h, h, rx, ry, 'cream', 12)]
    if style == 2:
        elbow, head = (0.1 * d, -0.2 * w, 0.75 * h), (0.85 * d, 0.2 * ry, 0.85 * h)
        t = 0.05 * min(d, w, h)
        return [_blk(0.0, 0.45 * d, -ry, 0.0, 0.0, 0.05 * h, 'black'),
                _beam((0.22 * d, -0.5 * ry, 0.05 * h), elbow, t, 'black'), _beam(elbow, head, t, 'black'),
                _disc(0.85 * d, 0.2 * ry, 0.6 * h, h, 0.3 * rx, 0.8 * ry, 'black', 8, top=0.4),
                _disc(0.85 * d, 0.2 * ry, 0.58 * h, 0.6 * h, 0.25 * rx, 0.6 * ry, 'bulb', 8)]
    globe = min(0.85 * h, 1.3 * max(d, w))  # on a stem when the box is tall
    base = min(0.15 * h, h - globe)
    parts = [_disc(cx, 0.0, 0.0, base, 0.5 * rx, 0.5 * ry, 'wood_light', 8, top=0.8),
             _ell(0.0, d, -ry, ry, h - globe, h, 'bulb')]
    if h - globe > base:
        parts.append(_post(cx, 0.0, base, h - 0.9 * globe, 0.05 * min(rx, ry), 'brass'))
    return parts


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


def _light(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Ceiling fixture hanging from z = h: round dome; square panel; black pendant shade."""
    style = v % 3
    rx, ry, cx = d / 2, w / 2, d / 2
    if style == 0:
        return [_disc(cx, 0.0, 0.8 * h, h, 0.4 * rx, 0.4 * ry, 'white', 12),
                _disc(cx, 0.0, 0.1 * h, 0.8 * h, rx, ry, 'off_white', 12, top=0.8),
                _disc(cx, 0.0, 0.0, 0.1 * h, 0.7 * rx, 0.7 * ry, 'bulb', 12)]
    if style == 1:
        return [_blk(0.0, d, -ry, ry, 0.2 * h, h, 'grey_light'),
                _blk(0.08 * d, 0.92 * d, -0.92 * ry, 0.92 * ry, 0.0, 0.2 * h, 'bulb')]
    return [_disc(cx, 0.0, 0.85 * h, h, 0.3 * rx, 0.3 * ry, 'black', 8),
            _post(cx, 0.0, 0.5 * h, 0.85 * h, 0.05 * min(rx, ry), 'black'),
            _disc(cx, 0.0, 0.05 * h, 0.5 * h, rx, ry, 'black', 12, top=0.35),
            _disc(cx, 0.0, 0.0, 0.05 * h, 0.5 * rx, 0.5 * ry, 'bulb', 8)]


# --- screens, wall art, electronics ---------------------------------------------------------

_TVS = (('charcoal', 'pedestal'), ('metal', 'feet'), ('white', 'bar'))


def _tv(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Flat screen facing +x, on a stand unless the box is wall-thin."""
    bezel, stand = _pick(_TVS, v)
    wall = d < 0.08
    st = min(0.05, (0.6 if wall else 0.3) * d)
    x0, z0 = (0.0, 0.0) if wall else (d / 2 - st / 2, 0.15 * h)
    rim = min(0.02, 0.03 * w)
    parts = [_blk(x0, x0 + st, -w / 2, w / 2, z0, h, bezel),
             _blk(x0 + st, x0 + 1.1 * st, -w / 2 + rim, w / 2 - rim, z0 + rim, h - rim, 'screen')]
    if wall:
        return parts
    foot = 0.02 * h
    if stand == 'pedestal':
        return parts + [_blk(0.0, d, -0.2 * w, 0.2 * w, 0.0, foot, bezel),
                        _blk(d / 2 - st, d / 2, -0.05 * w, 0.05 * w, foot, 0.3 * h, bezel)]
    if stand == 'feet':
        return parts + [_beam((x, y, foot / 2), (d / 2, 0.9 * y, z0), foot, bezel)
                        for x in (0.0, d) for y in (-0.4 * w, 0.4 * w)]
    return parts + [_blk(0.0, d, -0.35 * w, 0.35 * w, 0.0, foot, bezel),
                    _blk(d / 2 - st / 2, d / 2 + st / 2, -0.3 * w, 0.3 * w, foot, z0, bezel)]


_ART = (('wood_medium', 'landscape'), ('black', 'blocks'), ('white', 'sea'), ('brass', 'circles'))


def _picture(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Framed canvas hanging on a wall at x = 0; variants differ in frame and painting."""
    frame, art = _pick(_ART, v)
    f = min(0.05, 0.08 * min(w, h))
    canvas = _canvas(0.5 * d, 0.7 * d, -w / 2 + f, w / 2 - f, f, h - f, art)
    return _frame(0.0, d, -w / 2, w / 2, 0.0, h, f, frame) + canvas


def _canvas(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, art: str) -> Parts:
    """A simple painting: background bands (layer 0) and motifs standing slightly proud of them."""
    cw, ch, step = y1 - y0, z1 - z0, 0.15 * (x1 - x0)

    def at(a: float, b: float, c: float, e: float, colour: str, layer: int = 1) -> Mesh:
        return _blk(x0 if layer == 0 else x1, x1 + layer * step, y0 + a * cw, y0 + b * cw,
                    z0 + c * ch, z0 + e * ch, colour)

    if art == 'landscape':
        return [at(0, 1, 0.45, 1, 'sky', 0), at(0, 1, 0, 0.45, 'art_green', 0),
                at(0.1, 0.55, 0.3, 0.55, 'plant_dark'), at(0.7, 0.82, 0.65, 0.85, 'sun')]
    if art == 'blocks':
        return [at(0, 1, 0, 1, 'white', 0), at(0, 0.4, 0.55, 1, 'art_red'), at(0.7, 1, 0, 0.3, 'art_blue'),
                at(0.45, 0.65, 0, 0.25, 'art_yellow'), at(0.4, 0.44, 0, 1, 'black', 2),
                at(0, 1, 0.5, 0.54, 'black', 2)]
    if art == 'sea':
        return [at(0, 1, 0.5, 1, 'sky', 0), at(0, 1, 0.2, 0.5, 'sea', 0), at(0, 1, 0, 0.2, 'sand', 0),
                at(0.55, 0.62, 0.5, 0.78, 'white'), at(0.15, 0.3, 0.75, 0.82, 'white')]
    circles = ((0.3, 0.6, 0.22, 'art_red'), (0.65, 0.35, 0.2, 'art_yellow'), (0.72, 0.75, 0.12, 'sun'))
    return [at(0, 1, 0, 1, 'grey_dark', 0)] + [
        _rod((x1, y0 + a * cw, z0 + b * ch), (x1 + step, y0 + a * cw, z0 + b * ch), r * min(cw, ch), colour,
             10) for a, b, r, colour in circles]


def _mirror(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Wall mirror: wide wooden frame; thin black frame; oval in a brass rim."""
    style = v % 3
    if style == 2:
        return [_oval(0.0, 0.6 * d, w / 2, h / 2, h / 2, 'brass'),
                _oval(0.0, d, 0.45 * w, 0.45 * h, h / 2, 'mirror')]
    f = min(0.06, 0.1 * min(w, h)) if style == 0 else min(0.02, 0.05 * min(w, h))
    return _frame(0.0, d, -w / 2, w / 2, 0.0, h, f, 'wood_medium' if style == 0 else 'black') + [
        _blk(0.0, 0.7 * d, -w / 2 + f, w / 2 - f, f, h - f, 'mirror')]


def _oval(x0: float, x1: float, ry: float, rz: float, zc: float, colour: str) -> Mesh:
    """Elliptic slab between x0 and x1, facing +x, centred on y = 0 and z = zc."""
    unit = frustum((0.0, 0.0, 0.0), 1.0, 1.0, max(x1 - x0, _TINY), _c(colour), 12, axis='x')
    return unit.scaled((1.0, ry, rz)).transformed(0.0, ((x0 + x1) / 2, 0.0, zc))


def _keyboard(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Keyboard lying flat: rows of keys along y, the space bar row at the front (+x)."""
    parts = [_soft(0.0, d, -w / 2, w / 2, 0.0, 0.6 * h, 'charcoal', 0.2 * h)]
    for i, (a, b) in enumerate(_split(0.08 * d, 0.92 * d, 5)):
        pad = 0.12 * (b - a)
        blocks = ((0.03, 0.27), (0.32, 0.68), (0.73, 0.97)) if i == 4 else ((0.03, 0.76), (0.8, 0.97))
        parts += [_blk(a + pad, b - pad, -w / 2 + p * w, -w / 2 + q * w, 0.6 * h, h, 'grey_dark')
                  for p, q in blocks]
    return parts


_LAPTOPS = (('steel', 'black'), ('charcoal', 'black'), ('white', 'grey'))


def _laptop(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Open laptop: base on the table, screen leaning back from the hinge at the back."""
    shell, keys = _pick(_LAPTOPS, v)
    bt, lid = min(0.02, 0.08 * h), min(0.008, 0.05 * d)
    tilt, length = np.radians(12.0), h - bt
    hinge = length * np.sin(tilt) + lid
    screen = Mesh.merged([_blk(-lid, 0.0, -w / 2, w / 2, 0.0, length, shell),
                          _blk(0.0, 0.2 * lid, -0.46 * w, 0.46 * w, 0.05 * length, 0.95 * length, 'screen')])
    reach = d - hinge
    return [_blk(hinge - lid, d, -w / 2, w / 2, 0.0, bt, shell),
            _blk(hinge + 0.05 * reach, hinge + 0.5 * reach, -0.44 * w, 0.44 * w, bt, 1.1 * bt, keys),
            _blk(hinge + 0.62 * reach, hinge + 0.92 * reach, -0.15 * w, 0.15 * w, bt, 1.05 * bt, 'grey'),
            screen.transformed(rotation_y(-tilt), (hinge, 0.0, bt))]


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

def _decoration(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Upright boxes get a potted plant, flowers in a vase or grasses; flat ones a plate, fruit or books."""
    style = v % 3
    if h < 0.4 * min(d, w):
        return _flat_decoration(d, w, h, style)
    rx, ry = d / 2, w / 2
    if style == 0:
        return [_disc(rx, 0.0, 0.0, 0.35 * h, 0.35 * rx, 0.35 * ry, 'terracotta', 8, top=1.3),
                _disc(rx, 0.0, 0.33 * h, 0.36 * h, 0.42 * rx, 0.42 * ry, 'soil', 8),
                _ell(0.05 * d, 0.75 * d, -0.95 * ry, 0.2 * ry, 0.35 * h, 0.8 * h, 'plant_green'),
                _ell(0.3 * d, d, -0.1 * ry, ry, 0.4 * h, 0.85 * h, 'plant_dark'),
                _ell(0.2 * d, 0.8 * d, -0.5 * ry, 0.5 * ry, 0.6 * h, h, 'plant_green')]
    if style == 1:
        parts = [_disc(rx, 0.0, 0.0, 0.25 * h, 0.3 * rx, 0.3 * ry, 'ceramic_blue', 8, top=1.5),
                 _disc(rx, 0.0, 0.25 * h, 0.5 * h, 0.45 * rx, 0.45 * ry, 'ceramic_blue', 8, top=0.45)]
        for i, a in enumerate(np.arange(5) * 2 * np.pi / 5):
            x, y, z = rx + 0.7 * rx * np.cos(a), 0.7 * ry * np.sin(a), (0.9 - 0.05 * (i % 2)) * h
            parts += [_beam((rx, 0.0, 0.45 * h), (x, y, z), 0.05 * min(rx, ry), 'plant_green'),
                      _ell(x - 0.3 * rx, x + 0.3 * rx, y - 0.3 * ry, y + 0.3 * ry, z - 0.05 * h, z + 0.1 * h,
                           ('art_red', 'art_yellow', 'fabric_pink')[i % 3])]
        return parts
    tips = [(rx + 0.9 * rx * np.cos(a), 0.9 * ry * np.sin(a), h) for a in np.arange(7) * 2 * np.pi / 7]
    return [_disc(rx, 0.0, 0.0, 0.45 * h, 0.35 * rx, 0.35 * ry, 'white', 8, top=0.6)] + [
        _beam((rx, 0.0, 0.4 * h), tip, 0.04 * min(rx, ry), 'sand') for tip in tips]


def _flat_decoration(d: float, w: float, h: float, style: int) -> Parts:
    rx, ry = d / 2, w / 2
    if style == 0:  # decorative plate
        return [_disc(rx, 0.0, 0.0, 0.6 * h, 0.6 * rx, 0.6 * ry, 'ceramic_blue', 12, top=1 / 0.6),
                _disc(rx, 0.0, 0.6 * h, h, 0.7 * rx, 0.7 * ry, 'white', 12)]
    if style == 1:  # fruit bowl
        fruit = ((0.35 * d, -0.2 * w, 'fruit_orange'), (0.65 * d, -0.1 * w, 'fruit_red'),
                 (0.45 * d, 0.22 * w, 'fruit_green'))
        return [_disc(rx, 0.0, 0.0, 0.5 * h, 0.6 * rx, 0.6 * ry, 'wood_medium', 12, top=1 / 0.6)] + [
            _ell(x - 0.25 * d, x + 0.25 * d, y - 0.25 * w, y + 0.25 * w, 0.3 * h, h, colour)
            for x, y, colour in fruit]
    return [_blk(0.05 * d, 0.95 * d, -0.45 * w, 0.4 * w, 0.0, 0.33 * h, 'fabric_red'),  # stack of books
            _blk(0.0, 0.9 * d, -0.5 * w, 0.45 * w, 0.33 * h, 0.66 * h, 'fabric_navy'),
            _blk(0.1 * d, d, -0.4 * w, 0.5 * w, 0.66 * h, h, 'cream')]


def _generic(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    return [_soft(0.0, d, -w / 2, w / 2, 0.0, h, 'grey_light', 0.1 * min(d, w, h))]


# --- registry and entry points -------------------------------------------------------------

@dataclass(frozen=True)
class _Spec:
    build: Builder
    variants: int
    front: str = 'any'  # the box side the front belongs on: 'short' | 'long' | 'any'


_SPECS: dict[str, _Spec] = {
    'Armchair': _Spec(_armchair, 4), 'Bathtub': _Spec(_bathtub, 1, 'short'), 'Bed': _Spec(_bed, 5, 'long'),
    'Brush': _Spec(_brush, 1), 'Burner': _Spec(_burner, 1), 'Cabinet': _Spec(_cabinet, 4, 'short'),
    'Chair': _Spec(_chair, 4), 'Closet': _Spec(_closet, 4, 'short'), 'Counter': _Spec(_counter, 4),
    'Cup': _Spec(_cup, 1), 'Decoration': _Spec(_decoration, 3), 'Desk': _Spec(_desk, 3, 'short'),
    'Dishwasher': _Spec(_dishwasher, 1), 'Door': _Spec(_door, 3, 'short'),
    'Dresser': _Spec(_dresser, 3, 'short'), 'Drying': _Spec(_drying, 3, 'short'),
    'Keyboard': _Spec(_keyboard, 1, 'short'), 'KitchenFurniture': _Spec(_kitchen, 4), 'Lamp': _Spec(_lamp, 4),
    'Laptop': _Spec(_laptop, 3, 'short'), 'Light': _Spec(_light, 3), 'Lighter': _Spec(_lighter, 1, 'short'),
    'Microwave': _Spec(_microwave, 1, 'short'), 'Mirror': _Spec(_mirror, 3, 'short'),
    'Nightstand': _Spec(_nightstand, 3), 'Oven': _Spec(_oven, 1), 'Picture': _Spec(_picture, 4, 'short'),
    'Pouf': _Spec(_pouf, 4), 'Refrigerator': _Spec(_fridge, 3), 'Shelf': _Spec(_shelf, 3, 'short'),
    'ShowerCabin': _Spec(_shower, 1), 'Sink': _Spec(_sink, 3), 'Sofa': _Spec(_sofa, 4, 'short'),
    'Standard': _Spec(_standard, 4, 'short'), 'Station': _Spec(_station, 1), 'Stool': _Spec(_stool, 4),
    'Table': _Spec(_table, 4), 'Toilet': _Spec(_toilet, 1, 'long'), 'Toothbrush': _Spec(_toothbrush, 1),
    'Towel': _Spec(_towel, 4, 'short'), 'Tv': _Spec(_tv, 3, 'short'), 'Wall': _Spec(_window, 3, 'short'),
    'Washbasin': _Spec(_washbasin, 3, 'short'), 'WashingMachine': _Spec(_washing_machine, 1),
}
_GENERIC = _Spec(_generic, 1)

OBJECT_TYPES: tuple[str, ...] = tuple(sorted(_SPECS))
"""Every type with a dedicated model; any other type string gets a generic bevelled box."""


def variant_count(object_type: str) -> int:
    """How many visibly different models ``build_model`` offers for a type."""
    return _SPECS.get(object_type, _GENERIC).variants


def front_axis(object_type: str) -> str:
    """Which box side a type's front belongs on: 'short', 'long' or 'any' (see ``facing.suits_box``).

    Pass it to ``facing.choose_facing`` so that, say, a wardrobe in a corner
    backs onto the wall behind its long side.
    """
    return _SPECS.get(object_type, _GENERIC).front


def build_model(object_type: str, size: Vec3, variant: int, facing: int = 0,
                prefab: str = '') -> Mesh:
    """Model of ``object_type`` filling the upright box ``size`` (sx, sy, sz) centred at the origin.

    ``variant`` is taken modulo ``variant_count``; ``facing`` (0..3) makes the
    front look along local +x, +y, -x, -y.  Types whose front belongs on a
    particular side of the box (``front_axis``: a bed's foot on the long axis,
    a wardrobe's doors on its long side) turn a quarter when ``facing`` does
    not suit the box.
    """
    return Mesh.merged(build_parts(object_type, size, variant, facing, prefab))


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
    if not suits_box(spec.front, extents, facing):
        facing = (facing + 1) % 4
    d, w, h = extents[[0, 1, 2] if facing % 2 == 0 else [1, 0, 2]]
    parts = spec.build(d, w, h, int(variant) % spec.variants, prefab or '')
    lo, hi = Mesh.merged(parts).bounds()
    return [_fit(part, lo, hi, (d, w, h)).transformed(facing * np.pi / 2) for part in parts]


def _clean_size(size: Vec3) -> np.ndarray:
    values = np.abs(np.asarray(size, np.float64).reshape(3))
    return np.maximum(np.where(np.isfinite(values), values, MIN_EXTENT), MIN_EXTENT)


def _fit(part: Mesh, lo: np.ndarray, hi: np.ndarray, size: Sequence[float]) -> Mesh:
    """Map ``part`` as the box between ``lo`` and ``hi`` (the whole model's bounds) maps exactly
    onto a box of ``size`` centred at the origin."""
    scale = np.asarray(size, np.float64) / np.maximum(hi - lo, 1e-12)
    return Mesh((part.vertices - (lo + hi) / 2) * scale, part.faces, part.colours)
