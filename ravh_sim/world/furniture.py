"""Procedural low-poly furniture models, one merged mesh per object.

Why: the upstream houses only give each object a type tag, a prefab name and
an upright box; the Unity meshes themselves cannot be shipped.  This library
turns (type, box size, variant, facing) into a recognisable model that fills
that box, so what the robot's cameras see matches the collision box the
physics uses.  Everything is plain numpy and deterministic: the same inputs
give the same arrays, so generated OBJ files can be cached by their inputs.

How: each builder draws its model in a canonical frame, with the box spanning
x in [0, depth] (back at x = 0, front at x = depth), y in [-width/2, width/2]
and z in [0, height].  ``build_model`` then maps the model's bounding box
exactly onto the requested box (so it always fits inside and fills it, whatever
rounding the builder did) and turns it so the front looks along the
requested ``facing``.
"""
from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ravh_sim.world.mesh import Mesh, box, ellipsoid, frustum, rotation_y, rotation_z, rounded_box
from ravh_sim.world.palette import PALETTE

Parts = list[Mesh]
Builder = Callable[[float, float, float, int, str], Parts]

MIN_EXTENT = 1e-3
"""Smallest box extent built (m); zero or negative extents are raised to it."""

SWAP_RATIO = 1.15
"""A 'short'/'long' fronted type turns a quarter when its facing contradicts the box by this much."""


# --- part helpers (canonical frame) ------------------------------------------

def _c(name: str) -> int:
    return PALETTE.index(name)


def _blk(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, colour: str) -> Mesh:
    """Box between two corners."""
    lo, hi = np.minimum((x0, y0, z0), (x1, y1, z1)), np.maximum((x0, y0, z0), (x1, y1, z1))
    return box((lo + hi) / 2, np.maximum(hi - lo, 1e-6), _c(colour))


def _soft(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, colour: str,
          bevel: float) -> Mesh:
    """Box with chamfered edges between two corners (cushions, mattresses)."""
    lo, hi = np.minimum((x0, y0, z0), (x1, y1, z1)), np.maximum((x0, y0, z0), (x1, y1, z1))
    return rounded_box((lo + hi) / 2, np.maximum(hi - lo, 1e-6), _c(colour), bevel)


def _ell(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, colour: str) -> Mesh:
    """Ellipsoid filling a box (foliage, globes, fruit)."""
    lo, hi = np.minimum((x0, y0, z0), (x1, y1, z1)), np.maximum((x0, y0, z0), (x1, y1, z1))
    return ellipsoid((lo + hi) / 2, np.maximum(hi - lo, 1e-6), _c(colour))


def _disc(x: float, y: float, z0: float, z1: float, rx: float, ry: float, colour: str,
          segments: int = 8, top: float = 1.0) -> Mesh:
    """Vertical elliptic cylinder (or frustum with top radii scaled by ``top``)."""
    height = max(abs(z1 - z0), 1e-6)
    unit = frustum((0.0, 0.0, 0.0), 1.0, top, height, _c(colour), segments)
    return unit.scaled((max(rx, 1e-6), max(ry, 1e-6), 1.0)).transformed(0.0, (x, y, (z0 + z1) / 2))


def _post(x: float, y: float, z0: float, z1: float, r: float, colour: str, segments: int = 8) -> Mesh:
    """Vertical round rod."""
    return _disc(x, y, z0, z1, r, r, colour, segments)


def _rod(p0: Sequence[float], p1: Sequence[float], r: float, colour: str, segments: int = 6) -> Mesh:
    """Round rod between two points."""
    return _along(frustum((0.0, 0.0, 0.0), max(r, 1e-6), max(r, 1e-6), 1.0, _c(colour), segments), p0, p1)


def _beam(p0: Sequence[float], p1: Sequence[float], t: float, colour: str, width: float = 0.0) -> Mesh:
    """Square (or t x width) bar between two points."""
    unit = box((0.0, 0.0, 0.0), (max(t, 1e-6), max(width or t, 1e-6), 1.0), _c(colour))
    return _along(unit, p0, p1)


def _along(unit: Mesh, p0: Sequence[float], p1: Sequence[float]) -> Mesh:
    """Stretch a unit-length z-aligned part to run from p0 to p1."""
    a, b = np.asarray(p0, np.float64), np.asarray(p1, np.float64)
    length = max(float(np.linalg.norm(b - a)), 1e-6)
    axis = (b - a) / length if np.linalg.norm(b - a) > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.array([0.0, 1.0, 0.0]) if abs(axis[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, axis)
    u /= np.linalg.norm(u)
    frame = np.column_stack([u, np.cross(axis, u), axis])
    return unit.scaled((1.0, 1.0, length)).transformed(frame, (a + b) / 2)


def _pick(options: Sequence, variant: int):
    return options[variant % len(options)]


def _split(lo: float, hi: float, n: int) -> list[tuple[float, float]]:
    """``n`` equal consecutive intervals covering [lo, hi]."""
    edges = np.linspace(lo, hi, max(n, 1) + 1)
    return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:])]


def _count(length: float, pitch: float, low: int = 1, high: int = 6) -> int:
    """How many items of about ``pitch`` fit along ``length``."""
    return int(np.clip(round(length / max(pitch, 1e-9)), low, high))


def _legs(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, t: float,
          colour: str, round_: bool = False) -> Parts:
    """Four legs of thickness t in the corners of a rectangle."""
    xs, ys = (x0 + t / 2, x1 - t / 2), (y0 + t / 2, y1 - t / 2)
    if round_:
        return [_post(x, y, z0, z1, t / 2, colour) for x in xs for y in ys]
    return [_blk(x - t / 2, x + t / 2, y - t / 2, y + t / 2, z0, z1, colour) for x in xs for y in ys]


# --- fronts: doors, drawers, handles -----------------------------------------

@dataclass(frozen=True)
class _Front:
    """A door or drawer front on the x = const face; ``handle`` names where its pull goes."""

    y0: float
    y1: float
    z0: float
    z1: float
    handle: str  # 'left' | 'right' (vertical pull at that y edge), 'drawer', 'none'
    height: str = 'mid'  # vertical pull position: 'top' | 'mid' | 'bottom'
    colour: str = ''  # overrides the panel colour when set


@dataclass(frozen=True)
class _Finish:
    """Materials of a cabinet-like piece."""

    body: str
    panel: str
    handle: str
    pull: str = 'bar'  # 'bar' | 'long' | 'knob'


def _front_depths(d: float) -> tuple[float, float]:
    """Thickness of front panels and how far pulls stick out."""
    return min(0.02, 0.06 * d), min(0.025, 0.08 * d)


def _door_row(y0: float, y1: float, z0: float, z1: float, n: int, height: str = 'mid') -> list[_Front]:
    """``n`` doors side by side, pulls next to each other in pairs."""
    return [_Front(a, b, z0, z1, 'right' if i % 2 == 0 and i + 1 < n else 'left', height)
            for i, (a, b) in enumerate(_split(y0, y1, n))]


def _drawer_grid(y0: float, y1: float, z0: float, z1: float, rows: int, cols: int) -> list[_Front]:
    return [_Front(a, b, c, e, 'drawer') for c, e in _split(z0, z1, rows) for a, b in _split(y0, y1, cols)]


def _fronts(x: float, d: float, fronts: Sequence[_Front], finish: _Finish) -> Parts:
    """Panels on the face x (sticking out to ``d``), each with its pull."""
    ft, hd = _front_depths(d)
    parts = []
    for f in fronts:
        gap = min(0.003, 0.04 * (f.y1 - f.y0), 0.04 * (f.z1 - f.z0))
        parts.append(_blk(x, x + ft, f.y0 + gap, f.y1 - gap, f.z0 + gap, f.z1 - gap, f.colour or finish.panel))
        parts += _pull(x + ft, min(x + ft + hd, d), f, finish)
    return parts


def _pull(x0: float, x1: float, f: _Front, finish: _Finish) -> Parts:
    width, height = f.y1 - f.y0, f.z1 - f.z0
    t = min(0.014, 0.12 * width, 0.12 * height)
    margin = min(0.045, 0.18 * width)
    if f.handle == 'none':
        return []
    if f.handle == 'drawer':
        half = min(0.09, 0.22 * width) if finish.pull != 'knob' else t / 2
        zc = f.z0 + 0.62 * height
        return [_blk(x0, x1, -half + (f.y0 + f.y1) / 2, half + (f.y0 + f.y1) / 2, zc - t / 2, zc + t / 2, finish.handle)]
    y = f.y1 - margin if f.handle == 'right' else f.y0 + margin
    length = {'bar': min(0.16, 0.3 * height), 'long': 0.55 * height, 'knob': t}[finish.pull]
    zc = {'top': f.z1 - min(0.06, 0.1 * height) - length / 2, 'bottom': f.z0 + min(0.06, 0.1 * height) + length / 2,
          'mid': (f.z0 + f.z1) / 2}[f.height]
    return [_blk(x0, x1, y - t / 2, y + t / 2, zc - length / 2, zc + length / 2, finish.handle)]


def _carcass(d: float, w: float, z0: float, z1: float, body: str) -> tuple[Mesh, float]:
    """Cabinet body from z0 to z1 leaving room for fronts; returns it and its front face x."""
    ft, hd = _front_depths(d)
    xf = d - ft - hd
    return _blk(0.0, xf, -w / 2, w / 2, z0, z1, body), xf


def _plinth(d: float, w: float, h: float, colour: str) -> Mesh:
    """Recessed kick board under a cabinet."""
    return _blk(0.0, 0.9 * d, -w / 2 + 0.01 * w, w / 2 - 0.01 * w, 0.0, h, colour)


# --- seating -------------------------------------------------------------------

def _chair(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    if 'office' in prefab.lower():
        return _office_chair(d, w, h, v)
    frame, seat, back = _pick([('wood_medium', 'wood_medium', 'slats'),
                               ('chrome', 'fabric_grey', 'panel'),
                               ('black', 'white', 'shell'),
                               ('wood_dark', 'fabric_red', 'ladder')], v)
    seat_z, st = 0.46 * h, min(0.05, 0.06 * h)
    t = min(0.04, 0.12 * min(d, w))
    bt = min(0.035, 0.1 * d)
    parts = _legs(0.0, d, -w / 2, w / 2, 0.0, seat_z - st, t, frame, round_=frame == 'chrome')
    if seat == 'wood_medium':
        parts.append(_blk(0.0, d, -w / 2, w / 2, seat_z - st, seat_z, seat))
    else:
        parts.append(_soft(0.0, d, -w / 2, w / 2, seat_z - st, seat_z, seat, 0.3 * st))
    return parts + _chair_back(d, w, h, seat_z, t, bt, frame, seat, back)


def _chair_back(d: float, w: float, h: float, seat_z: float, t: float, bt: float,
                frame: str, seat: str, style: str) -> Parts:
    if style in ('panel', 'shell'):
        z0 = seat_z + (0.0 if style == 'shell' else 0.12 * (h - seat_z))
        posts = [] if style == 'shell' else [_blk(0.0, t, y - t / 2, y + t / 2, seat_z, z0 + 0.1 * (h - seat_z), frame)
                                             for y in (-w / 2 + t / 2, w / 2 - t / 2)]
        return posts + [_soft(0.0, bt, -w / 2, w / 2, z0, h, seat, 0.3 * bt)]
    posts = [_blk(0.0, t, y - t / 2, y + t / 2, seat_z, h, frame) for y in (-w / 2 + t / 2, w / 2 - t / 2)]
    rail = min(0.07, 0.15 * (h - seat_z))
    top = [_blk(0.0, bt, -w / 2 + t, w / 2 - t, h - rail, h, frame)]
    inner = w - 2 * t
    if style == 'slats':
        slats = [_blk(0.2 * bt, 0.8 * bt, -w / 2 + t + a + 0.3 * (b - a), -w / 2 + t + b - 0.3 * (b - a),
                      seat_z, h - rail, frame) for a, b in _split(0.0, inner, 3)]
        return posts + top + slats
    rails = [_blk(0.1 * bt, 0.9 * bt, -w / 2 + t, w / 2 - t, z - rail / 3, z + rail / 3, frame)
             for z in np.linspace(seat_z + 0.3 * (h - seat_z), h - 1.8 * rail, 2)]
    return posts + top + rails


def _office_chair(d: float, w: float, h: float, v: int) -> Parts:
    fabric = _pick(['charcoal', 'fabric_blue', 'fabric_grey', 'fabric_red'], v)
    cx, r = d / 2, min(d, w) / 2
    seat_z, st = 0.5 * h, min(0.07, 0.08 * h)
    leg_t = min(0.03, 0.12 * r)
    star = [_beam((cx, 0.0, leg_t / 2), (cx + r * np.cos(a), r * np.sin(a), leg_t / 2), leg_t, 'black')
            for a in np.arange(5) * 2 * np.pi / 5 + np.pi / 2]
    column = _post(cx, 0.0, leg_t, seat_z - st, min(0.025, 0.1 * r), 'chrome')
    seat = _soft(0.06 * d, d, -w / 2, w / 2, seat_z - st, seat_z, fabric, 0.4 * st)
    bt = min(0.06, 0.12 * d)
    back = _soft(0.0, bt, -0.42 * w, 0.42 * w, seat_z + 0.12 * (h - seat_z), h, fabric, 0.4 * bt)
    spine = _blk(0.3 * bt, 0.15 * d, -0.04 * w, 0.04 * w, seat_z - st, seat_z + 0.2 * (h - seat_z), 'black')
    arms = [_blk(0.25 * d, 0.8 * d, y - 0.03 * w, y + 0.03 * w, seat_z, seat_z + 0.22 * (h - seat_z), 'black')
            for y in (-0.47 * w, 0.47 * w)]
    return star + [column, seat, back, spine] + arms


@dataclass(frozen=True)
class _Upholstery:
    fabric: str
    legs: str  # colour of the legs, '' for a plinth to the floor
    arms: str  # 'box' | 'round' | 'wood'
    cushion: str = ''  # cushion colour, defaults to the fabric


_UPHOLSTERY = (_Upholstery('fabric_grey', 'wood_dark', 'box'),
               _Upholstery('leather_brown', '', 'round'),
               _Upholstery('fabric_blue', 'wood_light', 'wood'),
               _Upholstery('fabric_beige', 'black', 'box', 'fabric_mustard'))


def _armchair(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    return _upholstered(d, w, h, _pick(_UPHOLSTERY, v), seats=1, chaise=False)


def _sofa(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    style = _pick(_UPHOLSTERY, v)
    chaise = 'corner' in prefab.lower()
    seats = _count(w - (0.9 if chaise else 0.0), 0.65, 1, 4)
    return _upholstered(min(d, 1.0) if chaise else d, w, h, style, seats, chaise, chaise_depth=d)


def _upholstered(d: float, w: float, h: float, s: _Upholstery, seats: int, chaise: bool,
                 chaise_depth: float = 0.0) -> Parts:
    lh = 0.1 * h if s.legs else 0.0
    base_top, seat_top, arm_top = 0.42 * h, 0.62 * h, 0.78 * h
    aw = min(0.2, 0.1 * w if seats > 1 else 0.15 * w)
    bd = min(0.25, 0.24 * d)
    cushion = s.cushion or s.fabric
    chaise_w = min(0.9, 0.45 * w) if chaise else 0.0
    seat_y1 = w / 2 - aw - chaise_w
    parts = [_blk(0.0, d, -w / 2, w / 2, lh, base_top, s.fabric),
             _blk(0.0, bd, -w / 2 + aw, w / 2 - aw, base_top, h, s.fabric)]
    for a, b in _split(-w / 2 + aw, seat_y1, seats):
        parts.append(_soft(bd, d, a, b, base_top, seat_top, cushion, 0.25 * (seat_top - base_top)))
        parts.append(_blk(bd, bd + 0.5 * bd, a + 0.01 * w, b - 0.01 * w, seat_top, 0.95 * h, cushion))
    if chaise:
        parts += _chaise(d, chaise_depth, w, h, lh, base_top, seat_top, seat_y1, aw, s)
    depth = chaise_depth if chaise else d
    parts += _sofa_arm(-w / 2, -w / 2 + aw, lh, arm_top, s, ends_at=d)
    parts += _sofa_arm(w / 2 - aw, w / 2, lh, arm_top, s, ends_at=depth)
    if s.legs:
        t = min(0.05, 0.08 * min(d, w))
        parts += _legs(0.0, d, -w / 2, w / 2, 0.0, lh, t, s.legs)
        if chaise:
            parts += _legs(d, chaise_depth, seat_y1, w / 2, 0.0, lh, t, s.legs)[2:]
    return parts


def _chaise(d: float, chaise_depth: float, w: float, h: float, lh: float, base_top: float,
            seat_top: float, y0: float, aw: float, s: _Upholstery) -> Parts:
    """The long seat of a corner sofa, reaching forward at the +y end."""
    y1 = w / 2 - aw
    return [_blk(0.0, chaise_depth, y0, w / 2, lh, base_top, s.fabric),
            _blk(0.0, 0.25 * d, y0, y1, base_top, h, s.fabric),
            _soft(0.25 * d, chaise_depth, y0, y1, base_top, seat_top, s.cushion or s.fabric,
                  0.25 * (seat_top - base_top)),
            _blk(0.25 * d, 0.37 * d, y0, y1, seat_top, 0.95 * h, s.cushion or s.fabric)]


def _sofa_arm(y0: float, y1: float, z0: float, z1: float, s: _Upholstery, ends_at: float) -> Parts:
    if s.arms == 'round':
        return [_soft(0.0, ends_at, y0, y1, z0, z1, s.fabric, 0.45 * (y1 - y0))]
    if s.arms == 'wood':
        cap = min(0.04, 0.08 * (z1 - z0))
        return [_blk(0.0, ends_at, y0 + 0.1 * (y1 - y0), y1 - 0.1 * (y1 - y0), z0, z1 - cap, s.fabric),
                _blk(0.0, ends_at, y0, y1, z1 - cap, z1, s.legs or 'wood_medium')]
    return [_blk(0.0, ends_at, y0, y1, z0, z1, s.fabric)]


def _stool(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    rx, ry = d / 2, w / 2
    style = v % 4
    if style == 0:  # bar stool: round seat, chrome legs, foot ring
        t = min(0.025, 0.1 * min(d, w))
        legs = _legs(0.08 * d, 0.92 * d, -0.42 * w, 0.42 * w, 0.0, 0.93 * h, t, 'chrome', round_=True)
        ring = [_blk(0.1 * d, 0.9 * d, y - t / 3, y + t / 3, 0.3 * h, 0.3 * h + t / 1.5, 'chrome')
                for y in (-0.42 * w + t / 2, 0.42 * w - t / 2)]
        return legs + ring + [_disc(rx, 0.0, 0.93 * h, h, rx, ry, 'leather_black', 12)]
    if style == 1:  # wooden square stool with stretchers
        t = min(0.04, 0.14 * min(d, w))
        top = _blk(0.0, d, -ry, ry, 0.92 * h, h, 'wood_light')
        stretchers = [_blk(t / 2, d - t / 2, y - t / 3, y + t / 3, 0.25 * h, 0.25 * h + t, 'wood_light')
                      for y in (-ry + t / 2, ry - t / 2)]
        return _legs(0.04 * d, 0.96 * d, -0.46 * w, 0.46 * w, 0.0, 0.92 * h, t, 'wood_light') + stretchers + [top]
    if style == 2:  # three-legged with cushion
        t = min(0.035, 0.12 * min(d, w))
        legs = [_post(rx + 0.4 * rx * np.cos(a), 0.4 * ry * np.sin(a), 0.0, 0.88 * h, t / 2, 'black', 6)
                for a in np.arange(3) * 2 * np.pi / 3]
        return legs + [_disc(rx, 0.0, 0.82 * h, 0.9 * h, 0.8 * rx, 0.8 * ry, 'wood_dark', 12),
                       _disc(rx, 0.0, 0.9 * h, h, rx, ry, 'fabric_teal', 12, top=0.9)]
    return [_disc(rx, 0.0, 0.0, 0.03 * h, 0.8 * rx, 0.8 * ry, 'charcoal', 12),  # pedestal stool
            _post(rx, 0.0, 0.03 * h, 0.9 * h, min(0.03, 0.12 * min(rx, ry)), 'chrome'),
            _disc(rx, 0.0, 0.9 * h, h, rx, ry, 'fabric_red', 12)]


def _pouf(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    style = v % 4
    if style == 0:
        return [_disc(d / 2, 0.0, 0.0, 0.9 * h, d / 2, w / 2, 'fabric_grey', 12),
                _disc(d / 2, 0.0, 0.9 * h, h, 0.95 * d / 2, 0.95 * w / 2, 'fabric_grey', 12, top=0.9)]
    if style == 1:
        buttons = [_blk(x - 0.02 * d, x + 0.02 * d, y - 0.02 * w, y + 0.02 * w, 0.97 * h, h, 'fabric_navy')
                   for x in (0.3 * d, 0.7 * d) for y in (-0.2 * w, 0.2 * w)]
        return [_soft(0.0, d, -w / 2, w / 2, 0.0, 0.98 * h, 'fabric_blue', 0.2 * min(d, w, h))] + buttons
    if style == 2:
        return [_disc(d / 2, 0.0, 0.0, h, d / 2, w / 2, 'leather_brown', 12),
                _disc(d / 2, 0.0, 0.45 * h, 0.55 * h, 1.0 * d / 2, 1.0 * w / 2, 'brass', 12)]
    return [_soft(0.0, d, -w / 2, w / 2, 0.0, 0.75 * h, 'fabric_pink', 0.15 * min(d, w, h)),
            _soft(0.04 * d, 0.96 * d, -0.46 * w, 0.46 * w, 0.7 * h, h, 'fabric_pink', 0.3 * min(d, w, h))]


# --- beds and tables -------------------------------------------------------------

_BEDS = (('wood_medium', 'panel', 'fabric_blue'),
         ('fabric_grey', 'padded', 'fabric_beige'),
         ('white', 'slats', 'fabric_green'),
         ('wood_dark', 'posts', 'fabric_red'),
         ('black', 'metal', 'fabric_teal'))


def _bed(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Headboard at x = 0, foot at x = d (the long axis)."""
    frame, head, blanket = _pick(_BEDS, v)
    hb = min(0.07, 0.06 * d)
    lh = 0.08 * h if head in ('metal', 'posts') else 0.0
    frame_top, mattress_top = 0.3 * h, 0.5 * h
    foot = d - (hb if head in ('slats', 'posts', 'metal') else 0.0)
    parts = [_blk(hb, d, -0.49 * w, 0.49 * w, lh, frame_top, frame),
             _soft(hb, foot - 0.01 * d, -0.48 * w, 0.48 * w, frame_top, mattress_top, 'mattress', 0.03 * h),
             _soft(hb + 0.36 * (d - hb), foot, -w / 2, w / 2, frame_top - 0.05 * h, mattress_top + 0.02 * h,
                   blanket, 0.02 * h)]
    n = 2 if w > 1.25 else 1
    depth = min(0.4, 0.22 * d)
    for a, b in _split(-0.44 * w, 0.44 * w, n):
        parts.append(_soft(hb + 0.02 * d, hb + 0.02 * d + depth, a + 0.02 * w, b - 0.02 * w,
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
        slats = [_blk(0.2 * hb, 0.8 * hb, a + 0.25 * (b - a), b - 0.25 * (b - a), 0.3 * h, h - 0.1 * h, frame)
                 for a, b in _split(-w / 2 + hb, w / 2 - hb, _count(w, 0.18, 4, 10))]
        return posts + slats + [_blk(0.0, hb, -w / 2, w / 2, 0.9 * h, h, frame)]
    if style == 'posts':
        return posts + [_blk(0.15 * hb, 0.85 * hb, -w / 2 + hb, w / 2 - hb, 0.3 * h, 0.92 * h, frame)]
    bars = [_blk(0.35 * hb, 0.65 * hb, y - 0.15 * hb, y + 0.15 * hb, 0.3 * h, 0.9 * h, frame)
            for y in np.linspace(-w / 2 + hb, w / 2 - hb, _count(w, 0.2, 4, 8) + 2)[1:-1]]
    rails = [_blk(0.25 * hb, 0.75 * hb, -w / 2, w / 2, z - 0.25 * hb, z + 0.25 * hb, frame) for z in (0.3 * h, 0.9 * h)]
    return posts + bars + rails


def _footboard(d: float, hb: float, w: float, h: float, frame: str, style: str) -> Parts:
    if style == 'slats':
        return [_blk(d - hb, d, -w / 2, w / 2, 0.0, 0.56 * h, frame)]
    if style in ('posts', 'metal'):
        return [_blk(d - hb, d, y - hb / 2, y + hb / 2, 0.0, 0.6 * h, frame) for y in (-w / 2 + hb / 2, w / 2 - hb / 2)]
    return []


def _table(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    style = v % 4
    tt = min(0.04, 0.1 * h)
    if style == 0:
        t = min(0.06, 0.1 * min(d, w))
        apron = _blk(0.03 * d, 0.97 * d, -0.47 * w, 0.47 * w, h - tt - min(0.08, 0.15 * h), h - tt, 'wood_medium')
        return _legs(0.03 * d, 0.97 * d, -0.47 * w, 0.47 * w, 0.0, h - tt, t, 'wood_medium') + [
            apron, _blk(0.0, d, -w / 2, w / 2, h - tt, h, 'wood_medium')]
    if style == 1:
        t = min(0.04, 0.08 * min(d, w))
        return _legs(0.05 * d, 0.95 * d, -0.45 * w, 0.45 * w, 0.0, h - tt, t, 'chrome', round_=True) + [
            _blk(0.0, d, -w / 2, w / 2, h - tt, h, 'glass')]
    if style == 2:
        return [_disc(d / 2, 0.0, h - tt, h, d / 2, w / 2, 'wood_dark', 12),
                _post(d / 2, 0.0, 0.03 * h, h - tt, min(0.05, 0.1 * min(d, w)), 'wood_dark'),
                _disc(d / 2, 0.0, 0.0, 0.03 * h, 0.3 * d, 0.3 * w, 'wood_dark', 8)]
    t = min(0.04, 0.08 * min(d, w))
    sides = []
    for y in (-0.42 * w, 0.42 * w):
        sides += [_blk(0.05 * d, 0.95 * d, y - t / 2, y + t / 2, 0.0, t, 'black'),
                  _blk(0.05 * d, 0.95 * d, y - t / 2, y + t / 2, h - tt - t, h - tt, 'black'),
                  _blk(0.5 * d - t / 2, 0.5 * d + t / 2, y - t / 2, y + t / 2, 0.0, h - tt, 'black')]
    return sides + [_blk(0.0, d, -w / 2, w / 2, h - tt, h, 'white')]


def _desk(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    top, frame, handle = _pick([('wood_light', 'wood_light', 'metal'), ('white', 'black', 'chrome'),
                                ('wood_dark', 'wood_dark', 'brass')], v)
    tt, t = min(0.035, 0.06 * h), min(0.04, 0.05 * w)
    parts = [_blk(0.0, d, -w / 2, w / 2, h - tt, h, top)]
    if v % 3 == 1:
        parts += _legs(0.03 * d, 0.97 * d, -0.48 * w, 0.48 * w, 0.0, h - tt, t, frame)
        carcass, xf = _carcass(d, 0.4 * w, h - tt - min(0.1, 0.15 * h), h - tt, frame)
        return parts + [carcass] + _fronts(xf, d, [_Front(-0.2 * w, 0.2 * w, h - tt - min(0.1, 0.15 * h),
                                                          h - tt, 'drawer')], _Finish(frame, top, handle))
    pedestal_w = min(0.42, 0.32 * w)
    side = 1.0 if v % 3 == 0 else -1.0
    y_ped = side * (w / 2 - pedestal_w / 2)
    carcass, xf = _carcass(d, pedestal_w, 0.0, h - tt, frame)
    carcass = carcass.transformed(0.0, (0.0, y_ped, 0.0))
    drawers = [_Front(f.y0 + y_ped, f.y1 + y_ped, f.z0, f.z1, 'drawer')
               for f in _drawer_grid(-pedestal_w / 2, pedestal_w / 2, 0.02 * h, h - tt, 3 if side > 0 else 2, 1)]
    other = -side * (w / 2 - t / 2)
    return parts + [carcass, _blk(0.0, d, other - t / 2, other + t / 2, 0.0, h - tt, frame),
                    _blk(0.0, t, -w / 2, w / 2, 0.35 * h, h - tt, frame)] + _fronts(xf, d, drawers,
                                                                                _Finish(frame, top, handle))


# --- storage --------------------------------------------------------------------

def _cabinet(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    finish = _pick([_Finish('white', 'white', 'chrome', 'knob'), _Finish('wood_medium', 'wood_medium', 'brass'),
                    _Finish('grey_light', 'grey_light', 'metal'), _Finish('wood_dark', 'wood_dark', 'brass', 'knob')], v)
    style = v % 4
    ph = min(0.08, 0.08 * h)
    carcass, xf = _carcass(d, w, ph, h, finish.body)
    cols = _count(w, 0.45, 1, 4)
    y0, y1 = -w / 2, w / 2
    parts = [_plinth(d, w, ph, 'charcoal' if finish.body != 'white' else 'grey_light'), carcass]
    if style == 0:
        return parts + _fronts(xf, d, _door_row(y0, y1, ph, h, cols), finish)
    split = ph + 0.5 * (h - ph) if h > 0.9 else ph + 0.6 * (h - ph)
    if style == 1:  # glazed upper doors over solid lower doors
        upper = [_Front(f.y0, f.y1, f.z0, f.z1, f.handle, 'bottom', 'glass_dark') for f in _door_row(y0, y1, split, h, cols)]
        return parts + _fronts(xf, d, upper + _door_row(y0, y1, ph, split, cols, 'top'), finish)
    if style == 2:  # drawers over doors
        top_z = h - min(0.4, 0.35 * (h - ph))
        return parts + _fronts(xf, d, _drawer_grid(y0, y1, top_z, h, 2, cols) + _door_row(y0, y1, ph, top_z, cols, 'top'),
                               finish)
    return parts + _open_shelves(xf, d, w, split, h, finish.body) + _fronts(xf, d, _door_row(y0, y1, ph, split, cols, 'top'),
                                                                         finish)


def _open_shelves(xf: float, d: float, w: float, z0: float, z1: float, colour: str, books: bool = True) -> Parts:
    """Open compartment faked on a carcass face at x = xf: dark back, proud boards and sides, books."""
    ft, _ = _front_depths(d)
    t = min(0.02, 0.05 * w)
    levels = np.linspace(z0 + t / 2, z1 - t / 2, _count(z1 - z0, 0.35, 1, 5) + 1)
    parts = [_blk(xf, xf + 0.001, -w / 2, w / 2, z0, z1, 'charcoal')]
    parts += [_blk(xf, xf + ft, -w / 2, w / 2, z - t / 2, z + t / 2, colour) for z in levels]
    parts += [_blk(xf, xf + ft, y - t / 2, y + t / 2, z0, z1, colour) for y in (-w / 2 + t / 2, w / 2 - t / 2)]
    if books:
        openings = [(a + t / 2, b - t / 2) for a, b in zip(levels[:-1], levels[1:])]
        parts += _books(xf, xf + 0.8 * ft, -w / 2 + t, w / 2 - t, openings)
    return parts


_BOOK_COLOURS = ('fabric_red', 'fabric_navy', 'fabric_green', 'cream', 'fabric_mustard', 'charcoal', 'fabric_teal')


def _books(x0: float, x1: float, y0: float, y1: float, shelves: Sequence[tuple[float, float]]) -> Parts:
    """A few blocks of books standing on each shelf (z0 = shelf top, z1 = next shelf bottom)."""
    parts = []
    for i, (z0, z1) in enumerate(shelves):
        gap = z1 - z0
        for j, (a, b, fill) in enumerate(((0.04, 0.3, 0.8), (0.33, 0.5, 0.65), (0.7, 0.9, 0.72))[: 2 + i % 2]):
            parts.append(_blk(x0, x1, y0 + a * (y1 - y0), y0 + b * (y1 - y0), z0, z0 + fill * gap,
                              _BOOK_COLOURS[(3 * i + j) % len(_BOOK_COLOURS)]))
    return parts


def _closet(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    finish = _pick([_Finish('white', 'white', 'chrome', 'long'), _Finish('wood_medium', 'wood_medium', 'brass', 'knob'),
                    _Finish('wood_light', 'wood_light', 'metal', 'long'), _Finish('wood_dark', 'wood_dark', 'brass', 'bar')], v)
    style = v % 4
    ph, cornice = min(0.08, 0.05 * h), min(0.06, 0.03 * h) if style == 1 else 0.0
    carcass, xf = _carcass(d, w, ph, h - cornice, finish.body)
    parts = [_plinth(d, w, ph, 'charcoal'), carcass]
    if cornice:
        parts.append(_blk(0.0, d, -w / 2, w / 2, h - cornice, h, finish.body))
    n = _count(w, 0.5, 2, 6)
    top = h - cornice
    if style == 2:  # sliding doors, alternating wood and mirror
        panels = [_Front(a, b, ph, top, 'left' if i % 2 else 'right', colour='mirror' if i % 2 else '')
                  for i, (a, b) in enumerate(_split(-w / 2, w / 2, max(2, n // 2)))]
        return parts + _fronts(xf, d, panels, finish)
    if style == 3:  # doors over a row of drawers
        split = ph + min(0.45, 0.22 * (h - ph))
        return parts + _fronts(xf, d, _door_row(-w / 2, w / 2, split, top, n) + _drawer_grid(-w / 2, w / 2, ph, split, 2, n),
                               finish)
    return parts + _fronts(xf, d, _door_row(-w / 2, w / 2, ph, top, n), finish)


def _dresser(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    finish, rows, feet = _pick([(_Finish('wood_light', 'wood_light', 'wood_dark', 'knob'), 3, 'legs'),
                                (_Finish('white', 'white', 'chrome'), 4, 'plinth'),
                                (_Finish('wood_dark', 'wood_red', 'brass', 'knob'), 3, 'buns')], v)
    fh = min(0.1, 0.15 * h)
    cols = 2 if w > 0.8 else 1
    tt = min(0.03, 0.06 * h)
    carcass, xf = _carcass(d, w, fh, h - tt, finish.body)
    parts = [carcass, _blk(0.0, d, -w / 2, w / 2, h - tt, h, finish.body)] + _feet(d, w, fh, finish.body, feet)
    fronts = _drawer_grid(-w / 2, w / 2, fh, h - tt - (h - tt - fh) / (rows + 1), rows - 1, cols)
    fronts += _drawer_grid(-w / 2, w / 2, h - tt - (h - tt - fh) / (rows + 1), h - tt, 1, cols + 1)
    return parts + _fronts(xf, d, fronts, finish)


def _feet(d: float, w: float, fh: float, colour: str, kind: str) -> Parts:
    if kind == 'plinth':
        return [_plinth(d, w, fh, colour)]
    t = min(0.05, 0.12 * min(d, w))
    if kind == 'buns':
        return [_post(x, y, 0.0, fh, t / 2, colour) for x in (t / 2, d - t / 2) for y in (-w / 2 + t / 2, w / 2 - t / 2)]
    return _legs(0.0, d, -w / 2, w / 2, 0.0, fh, t, colour)


def _nightstand(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    finish, feet = _pick([(_Finish('wood_medium', 'wood_medium', 'black'), 'legs'),
                          (_Finish('white', 'white', 'chrome'), 'plinth'),
                          (_Finish('wood_dark', 'wood_dark', 'brass', 'knob'), 'buns')], v)
    style = v % 3
    fh = min(0.12 if style == 0 else 0.05, 0.2 * h)
    tt = min(0.025, 0.06 * h)
    carcass, xf = _carcass(d, w, fh, h - tt, finish.body)
    parts = [carcass, _blk(0.0, d, -w / 2, w / 2, h - tt, h, finish.body)] + _feet(d, w, fh, finish.body, feet)
    if style == 0:
        split = fh + 0.55 * (h - tt - fh)
        parts += _open_shelves(xf, d, w, fh, split, finish.body, books=False)
        return parts + _fronts(xf, d, [_Front(-w / 2, w / 2, split, h - tt, 'drawer')], finish)
    return parts + _fronts(xf, d, _drawer_grid(-w / 2, w / 2, fh, h - tt, 2 if style == 1 else 3, 1), finish)


def _shelf(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Wall shelf board; the wall is at x = 0."""
    style = v % 3
    if style == 0:
        return [_soft(0.0, d, -w / 2, w / 2, 0.0, h, 'wood_light', 0.15 * min(d, h))]
    if style == 1:
        board = _blk(0.0, d, -w / 2, w / 2, 0.45 * h, h, 'white')
        t = min(0.02, 0.05 * w)
        brackets = [_blk(0.0, 0.8 * d, y - t / 2, y + t / 2, 0.0, 0.45 * h, 'black') for y in (-0.35 * w, 0.35 * w)]
        return [board] + brackets
    t = min(0.03, 0.05 * w)
    clamps = [_blk(0.0, 0.25 * d, y - t, y + t, 0.0, h, 'chrome') for y in (-0.35 * w, 0.35 * w)]
    return [_blk(0.0, d, -w / 2, w / 2, 0.25 * h, 0.75 * h, 'glass')] + clamps


def _standard(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Racks and bookcases ('rack_N' prefabs) or a low TV unit ('Tv Table')."""
    if 'tv' in prefab.lower():
        return _tv_unit(d, w, h, v)
    style = v % 4
    if style == 2:
        return _metal_rack(d, w, h)
    colour = _pick(['wood_medium', 'white', 'black', 'wood_dark'], v)
    t = min(0.025, 0.05 * min(d, w))
    shelves = _count(h, 0.36, 1, 6)
    levels = np.linspace(0.0, h - t, shelves + 1)
    parts = [_blk(0.0, d, y - t / 2, y + t / 2, 0.0, h, colour) for y in (-w / 2 + t / 2, w / 2 - t / 2)]
    parts += [_blk(0.0, d, -w / 2 + t, w / 2 - t, z, z + t, colour) for z in levels]
    parts.append(_blk(0.0, 0.01 * d + 0.002, -w / 2 + t, w / 2 - t, 0.0, h, 'charcoal' if colour != 'white' else 'grey_light'))
    openings = [(float(a + t), float(b)) for a, b in zip(levels[:-1], levels[1:])]
    if style == 1 and w > 0.6:
        parts.append(_blk(0.0, d, -t / 2, t / 2, 0.0, h, colour))
        boxes = [_soft(0.3 * d, d, y0 + 0.06 * w, y0 + 0.44 * w, z0, z0 + 0.8 * (z1 - z0), _pick(_BOOK_COLOURS, i), 0.02)
                 for i, (z0, z1) in enumerate(openings) for y0 in (-w / 2, 0.0) if i % 2 == 0 or y0 == 0.0]
        return parts + boxes
    if style == 3:
        doors = _door_row(-w / 2 + t, w / 2 - t, openings[0][0], openings[0][1], _count(w, 0.45, 1, 4))
        ft, hd = _front_depths(d)
        return parts + _books(0.2 * d, d - ft - hd, -w / 2 + t, w / 2 - t, openings[1:]) + _fronts(
            d - ft - hd, d, doors, _Finish(colour, colour, 'brass', 'knob'))
    return parts + _books(0.15 * d, 0.95 * d, -w / 2 + t, w / 2 - t, openings)


def _metal_rack(d: float, w: float, h: float) -> Parts:
    t = min(0.025, 0.08 * min(d, w))
    shelves = _count(h, 0.4, 1, 5)
    parts = [_blk(x, x + t, y, y + t, 0.0, h, 'black') for x in (0.0, d - t) for y in (-w / 2, w / 2 - t)]
    levels = np.linspace(0.05 * h, h - t / 2, shelves + 1)
    parts += [_blk(0.0, d, -w / 2, w / 2, z - t / 4, z + t / 4, 'metal') for z in levels]
    for i, (z0, z1) in enumerate(zip(levels[:-1], levels[1:])):
        y0 = -0.4 * w if i % 2 == 0 else 0.05 * w
        parts.append(_blk(0.15 * d, 0.85 * d, y0, y0 + 0.35 * w, z0 + t / 4, z0 + 0.6 * (z1 - z0),
                          _pick(('cream', 'wood_light', 'fabric_blue'), i)))
    return parts


def _tv_unit(d: float, w: float, h: float, v: int) -> Parts:
    finish = _pick([_Finish('wood_medium', 'white', 'chrome'), _Finish('white', 'white', 'chrome', 'knob'),
                    _Finish('black', 'wood_light', 'black'), _Finish('wood_dark', 'wood_dark', 'brass')], v)
    fh = min(0.08, 0.25 * h)
    carcass, xf = _carcass(d, w, fh, h, finish.body)
    side = min(0.4, 0.35 * w)
    fronts = [_Front(-w / 2, -w / 2 + side, fh, h, 'drawer'), _Front(w / 2 - side, w / 2, fh, h, 'drawer')]
    return [carcass] + _legs(0.05 * d, 0.95 * d, -0.48 * w, 0.48 * w, 0.0, fh, min(0.04, 0.1 * d), 'black') + (
        _open_shelves(xf, d, w - 2 * side, fh, h, finish.body, books=False)) + _fronts(xf, d, fronts, finish)


# --- kitchen ------------------------------------------------------------------------

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
    carcass, xf = _carcass(d, w, ph, h, finish.body)
    parts = [carcass] if wall else [carcass, _plinth(d, w, ph, 'charcoal')]
    if 'oven' in name:
        drawer = ph + 0.2 * (h - ph)
        return parts + _fronts(xf, d, [_Front(-w / 2, w / 2, ph, drawer, 'drawer')], finish) + _oven_front(
            xf, d, w, drawer, h, 'black')
    if 'sink' in name:
        top = h - 0.18 * (h - ph)
        return parts + _fronts(xf, d, [_Front(-w / 2, w / 2, top, h, 'drawer')] + _door_row(
            -w / 2, w / 2, ph, top, _count(w, 0.5, 1, 2), 'top'), finish)
    return parts + _fronts(xf, d, _kitchen_doors(w, ph, h, doors, 'bottom' if wall else 'top', 'corner' in name),
                           finish)


def _kitchen_doors(w: float, z0: float, z1: float, doors: int, height: str, corner: bool) -> list[_Front]:
    if corner:  # a blind panel where the neighbouring run butts in
        blind = 0.4 * w
        return [_Front(-w / 2, -w / 2 + blind, z0, z1, 'none'), _Front(-w / 2 + blind, w / 2, z0, z1, 'left', height)]
    return _door_row(-w / 2, w / 2, z0, z1, doors, height)


def _tap(x: float, y: float, z0: float, z1: float, reach: float) -> Parts:
    r = min(0.015, 0.08 * (z1 - z0))
    return [_post(x, y, z0, z1, r, 'chrome'),
            _rod((x, y, z1 - r), (x + reach, y, z1 - r), r * 0.8, 'chrome'),
            _blk(x + reach - r, x + reach + r, y - r, y + r, z1 - 3 * r, z1 - r, 'chrome')]


def _hob(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> Parts:
    """Black glass cooktop with four rings."""
    parts = [_blk(x0, x1, y0, y1, z0, z0 + 0.6 * (z1 - z0), 'black')]
    r = 0.2 * min(x1 - x0, y1 - y0)
    for x in (x0 + 0.28 * (x1 - x0), x0 + 0.72 * (x1 - x0)):
        for y in (y0 + 0.27 * (y1 - y0), y0 + 0.73 * (y1 - y0)):
            parts.append(_disc(x, y, z0, z1 - 0.2 * (z1 - z0), r, r, 'grey_dark', 8))
            parts.append(_disc(x, y, z0, z1, 0.5 * r, 0.5 * r, 'charcoal', 8))
    return parts


def _oven_front(xf: float, d: float, w: float, z0: float, z1: float, colour: str) -> Parts:
    """Oven door with a dark window, a bar handle and a control strip above."""
    strip = min(0.1, 0.15 * (z1 - z0))
    finish = _Finish(colour, colour, 'chrome')
    door = _Front(-w / 2, w / 2, z0, z1 - strip, 'drawer')
    ft, _ = _front_depths(d)
    window = _blk(xf + ft, xf + ft + 0.003, -0.35 * w, 0.35 * w, z0 + 0.2 * (z1 - z0), z1 - strip - 0.25 * (z1 - z0),
                  'glass_dark')
    knobs = [_rod((xf + ft, y, z1 - strip / 2), (d, y, z1 - strip / 2), min(0.018, 0.3 * strip), 'metal')
             for y in np.linspace(-0.35 * w, 0.35 * w, 4)]
    panel = _blk(xf, xf + ft, -w / 2, w / 2, z1 - strip, z1, 'steel')
    return _fronts(xf, d, [door], finish) + [window, panel] + knobs


def _counter(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    top, edge = _pick([('marble', 'marble'), ('granite', 'granite'), ('wood_light', 'wood_medium'),
                       ('white', 'steel')], v)
    e = min(0.02, 0.06 * d)
    return [_blk(0.0, d - e, -w / 2, w / 2, 0.0, h, top), _blk(d - e, d, -w / 2, w / 2, 0.0, h, edge)]


def _burner(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    return _hob(0.0, d, -w / 2, w / 2, 0.0, h)


def _sink(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """A basin with its tap (the unit under it is a separate object)."""
    style = v % 3
    tap = _tap(0.08 * d, 0.0, 0.55 * h, h, 0.3 * d)
    if style == 1:  # round ceramic vessel
        rx, ry = 0.42 * d, 0.5 * w
        return [_disc(0.58 * d, 0.0, 0.0, 0.6 * h, 0.6 * rx, 0.6 * ry, 'ceramic', 12, top=1 / 0.6),
                _disc(0.58 * d, 0.0, 0.6 * h - 0.001, 0.6 * h + 0.004, 0.8 * rx, 0.8 * ry, 'ceramic_shade', 12)] + tap
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.5 * h, 0.55 * h, 'steel')]
    for a, b in _split(-0.45 * w, 0.45 * w, 2 if style == 2 else 1):
        parts += [_blk(0.2 * d, 0.95 * d, a + 0.02 * w, b - 0.02 * w, 0.0, 0.5 * h, 'steel'),
                  _blk(0.22 * d, 0.93 * d, a + 0.04 * w, b - 0.04 * w, 0.55 * h, 0.56 * h, 'grey')]
    return parts + tap


def _fridge(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    colour, handle, freezer_top = _pick([('white', 'grey_light', False), ('steel', 'chrome', False),
                                         ('cream', 'chrome', True)], v)
    carcass, xf = _carcass(d, w, 0.0, h, colour)
    split = 0.72 * h if freezer_top else 0.36 * h
    doors = [_Front(-w / 2, w / 2, split, h, 'left', 'bottom' if freezer_top else 'mid'),
             _Front(-w / 2, w / 2, 0.02 * h, split, 'left', 'mid' if freezer_top else 'top')]
    finish = _Finish(colour, colour, handle, 'long')
    parts = [carcass] + _fronts(xf, d, doors, finish)
    return parts + [_blk(0.0, 0.95 * d, -0.48 * w, 0.48 * w, 0.0, 0.02 * h, 'charcoal')]


def _oven(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    carcass, xf = _carcass(d, w, 0.0, h, 'charcoal')
    return [carcass] + _oven_front(xf, d, w, 0.0, h, 'steel')


def _microwave(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    ft, hd = _front_depths(d)
    xb = d - ft - hd
    split = 0.28 * w
    finish = _Finish('steel', 'black', 'steel')
    buttons = [_blk(xb + ft, xb + ft + 0.3 * hd, y - 0.06 * split, y + 0.06 * split, z - 0.03 * h, z + 0.03 * h, 'grey')
               for z in np.linspace(0.25 * h, 0.6 * h, 3) for y in (w / 2 - 0.35 * split, w / 2 - 0.65 * split)]
    return [_soft(0.0, xb, -w / 2, w / 2, 0.0, h, 'steel', 0.04 * min(d, h)),
            _blk(xb + ft, xb + ft + 0.002, -0.42 * w, w / 2 - split - 0.08 * w, 0.2 * h, 0.8 * h, 'glass_dark'),
            _blk(xb, xb + ft, w / 2 - split, w / 2 - 0.02 * w, 0.1 * h, 0.9 * h, 'charcoal'),
            _blk(xb + ft, xb + ft + 0.004, w / 2 - 0.8 * split, w / 2 - 0.2 * split, 0.7 * h, 0.8 * h, 'led')] + _fronts(
        xb, d, [_Front(-w / 2 + 0.02 * w, w / 2 - split, 0.05 * h, 0.95 * h, 'right')], finish) + buttons


def _dishwasher(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    carcass, xf = _carcass(d, w, 0.0, h, 'grey')
    strip = min(0.1, 0.12 * h)
    finish = _Finish('steel', 'steel', 'chrome')
    ft, _ = _front_depths(d)
    return [carcass, _blk(xf, xf + ft, -w / 2, w / 2, h - strip, h, 'charcoal'),
            _blk(xf + ft, xf + ft + 0.003, 0.25 * w, 0.4 * w, h - 0.6 * strip, h - 0.4 * strip, 'led'),
            _blk(xf, xf + ft, -0.48 * w, 0.48 * w, 0.0, 0.08 * h, 'black')] + _fronts(
        xf, d, [_Front(-w / 2, w / 2, 0.08 * h, h - strip, 'drawer')], finish)


def _washing_machine(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    ft, hd = _front_depths(d)
    xf = d - ft - hd
    strip = min(0.12, 0.15 * h)
    r = 0.36 * min(w, h - strip)
    zc = 0.05 * h + (h - strip) / 2
    return [_blk(0.0, xf + ft, -w / 2, w / 2, 0.0, h, 'white'),
            _blk(xf + ft, xf + ft + 0.002, -0.46 * w, 0.46 * w, h - strip, h - 0.1 * strip, 'off_white'),
            _blk(xf + ft, xf + ft + 0.008, -0.44 * w, -0.1 * w, h - 0.8 * strip, h - 0.25 * strip, 'grey_light'),
            _rod((xf + ft, 0.3 * w, h - strip / 2), (d, 0.3 * w, h - strip / 2), 0.3 * strip, 'grey', 8),
            _rod((xf + ft, 0.0, zc), (xf + ft + 0.6 * hd, 0.0, zc), r, 'chrome', 12),
            _rod((xf + ft, 0.0, zc), (d, 0.0, zc), 0.75 * r, 'glass_dark', 12)]


# --- bathroom -----------------------------------------------------------------------

def _toilet(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Cistern at the back (x = 0), bowl reaching forward along the long axis."""
    seat_z = 0.45 * h
    bowl_x, rx, ry = 0.62 * d, 0.38 * d, 0.5 * w
    return [_disc(bowl_x, 0.0, 0.0, seat_z - 0.04 * h, 0.55 * rx, 0.55 * ry, 'ceramic', 12, top=1 / 0.55),
            _disc(bowl_x, 0.0, seat_z - 0.04 * h, seat_z - 0.02 * h, rx, ry, 'grey_light', 12),
            _disc(bowl_x, 0.0, seat_z - 0.02 * h, seat_z, 0.97 * rx, 0.97 * ry, 'white', 12),
            _blk(0.1 * d, 0.45 * d, -0.3 * w, 0.3 * w, 0.15 * h, seat_z - 0.02 * h, 'ceramic'),
            _soft(0.0, 0.3 * d, -0.44 * w, 0.44 * w, seat_z, 0.96 * h, 'ceramic', 0.02 * d),
            _blk(0.0, 0.32 * d, -0.46 * w, 0.46 * w, 0.96 * h - 0.001, h - 0.02 * h, 'ceramic'),
            _disc(0.16 * d, 0.0, h - 0.02 * h, h, 0.05 * d, 0.05 * d, 'chrome', 8)]


def _washbasin(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Basin on a vanity or pedestal, tap and (in tall boxes) a mirror on the wall."""
    style = v % 3
    counter = min(0.85, 0.8 * h) if h > 1.05 else 0.78 * h
    basin = min(0.15, 0.18 * counter)
    parts = [_soft(0.0, d, -w / 2, w / 2, counter - basin, counter, 'ceramic', 0.3 * basin),
             _blk(0.25 * d, 0.9 * d, -0.38 * w, 0.38 * w, counter - 0.001, counter + 0.003, 'ceramic_shade')]
    parts += _tap(0.1 * d, 0.0, counter, min(h, counter + 0.2) if h > 1.05 else h, 0.2 * d)
    if h > 1.05:
        frame = 'wood_medium' if style == 0 else 'chrome'
        parts += [_blk(0.0, 0.03 * d, -0.42 * w, 0.42 * w, counter + 0.22, h, frame),
                  _blk(0.03 * d, 0.05 * d, -0.39 * w, 0.39 * w, counter + 0.25, h - 0.03, 'mirror')]
    if style == 1:  # pedestal
        return parts + [_disc(0.35 * d, 0.0, 0.0, counter - basin, 0.18 * d, 0.12 * w, 'ceramic', 8, top=1.3)]
    finish = _Finish('wood_medium', 'wood_medium', 'chrome') if style == 0 else _Finish('white', 'white', 'chrome')
    z0 = 0.0 if style == 0 else 0.25 * counter
    carcass, xf = _carcass(d, 0.96 * w, z0, counter - basin, finish.body)
    fronts = (_door_row(-0.48 * w, 0.48 * w, z0, counter - basin, 2, 'top') if style == 0
              else _drawer_grid(-0.48 * w, 0.48 * w, z0, counter - basin, 2, 1))
    waste = [] if style == 0 else [_post(0.2 * d, 0.0, 0.0, z0, min(0.02, 0.05 * w), 'chrome')]
    return parts + [carcass] + waste + _fronts(xf, d, fronts, finish)


def _shower(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Tray, chrome frame, glass walls with a door on the front, shower column at the back."""
    tray = min(0.12, 0.06 * h)
    t = min(0.03, 0.04 * min(d, w))
    g = min(0.008, 0.3 * t)
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.0, tray, 'ceramic'),
             _blk(0.0, g, -w / 2, w / 2, tray, h, 'ceramic_shade')]
    parts += [_blk(x, x + t, y, y + t, tray, h, 'chrome') for x in (0.0, d - t) for y in (-w / 2, w / 2 - t)]
    parts += [_blk(0.0, d, y, y + t, h - t, h, 'chrome') for y in (-w / 2, w / 2 - t)]
    parts.append(_blk(d - t, d, -w / 2, w / 2, h - t, h, 'chrome'))
    parts += [_blk(t, d - t, y + t / 2 - g / 2, y + t / 2 + g / 2, tray, h - t, 'glass') for y in (-w / 2, w / 2 - t)]
    parts += [_blk(d - t, d - t + g, -w / 2 + t, 0.05 * w, tray, h - t, 'glass'),
              _blk(d - g, d, -0.05 * w, w / 2 - t, tray, h - t, 'glass'),
              _blk(d - g - t, d - g, -0.02 * w, 0.0, 0.45 * h, 0.6 * h, 'chrome')]
    riser_y = 0.25 * w
    return parts + [_post(g + 0.02, riser_y, 0.4 * h, 0.9 * h, 0.01, 'chrome'),
                    _rod((g, riser_y, 0.9 * h), (0.25 * d, riser_y, 0.9 * h), 0.01, 'chrome'),
                    _disc(0.25 * d, riser_y, 0.88 * h, 0.9 * h, min(0.1, 0.15 * d), min(0.1, 0.15 * d), 'chrome', 8)]


def _bathtub(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """White tub along y with its tap at the -y end; tall boxes get a shower screen and riser."""
    tap = min(0.15, 0.2 * h)
    rim_h = min(0.58, h - tap)
    rim, lip = min(0.08, 0.12 * min(d, w)), min(0.03, 0.1 * rim_h)
    shell = rim_h - lip
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.0, shell, 'ceramic'),
             _blk(0.0, d, -w / 2, -w / 2 + rim, shell, rim_h, 'ceramic'),
             _blk(0.0, d, w / 2 - rim, w / 2, shell, rim_h, 'ceramic'),
             _blk(0.0, rim, -w / 2 + rim, w / 2 - rim, shell, rim_h, 'ceramic'),
             _blk(d - rim, d, -w / 2 + rim, w / 2 - rim, shell, rim_h, 'ceramic'),
             _blk(rim, d - rim, -w / 2 + rim, w / 2 - rim, shell, shell + 0.2 * lip, 'ceramic_shade')]
    parts += _tap(0.3 * rim, -w / 2 + 0.5 * rim, rim_h, rim_h + tap, 0.0)
    if h > 1.2:
        parts += [_blk(d - rim / 2 - 0.005, d - rim / 2 + 0.005, -w / 2 + rim, -w / 2 + 0.45 * w, rim_h, 0.85 * h, 'glass'),
                  _post(0.02, -w / 2 + rim, rim_h, h, 0.012, 'chrome'),
                  _disc(0.08, -w / 2 + rim, h - 0.03, h, 0.08, 0.08, 'chrome', 8)]
    return parts


def _towel(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Towel folded over a wall bar (wall at x = 0), in different colours and stripes."""
    cloth, stripe = _pick([('white', 'grey_light'), ('fabric_blue', 'white'), ('fabric_pink', ''),
                           ('fabric_green', 'cream')], v)
    r = min(0.012, 0.15 * d)
    bar_z, xc = h - 2 * r, 0.55 * d
    parts = [_rod((xc, -w / 2, bar_z), (xc, w / 2, bar_z), r, 'chrome'),
             _blk(0.0, 0.1 * d, -w / 2, -w / 2 + 2 * r, bar_z - 2 * r, bar_z + r, 'chrome'),
             _blk(0.0, 0.1 * d, w / 2 - 2 * r, w / 2, bar_z - 2 * r, bar_z + r, 'chrome'),
             _blk(0.15 * d, xc - r, -0.44 * w, 0.44 * w, 0.2 * h, bar_z, cloth),
             _blk(xc + r, 0.95 * d, -0.44 * w, 0.44 * w, 0.0, bar_z, cloth),
             _soft(0.15 * d, 0.95 * d, -0.44 * w, 0.44 * w, bar_z - r, h, cloth, 0.3 * d)]
    if stripe:
        parts += [_blk(0.95 * d, d, -0.44 * w, 0.44 * w, z, z + 0.05 * h, stripe) for z in (0.08 * h, 0.16 * h)]
    return parts


def _drying(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Heated towel rail: a ladder of tubes (wall at x = 0)."""
    style = v % 3
    colour = ('chrome', 'white', 'black')[style]
    r = min(0.015, 0.2 * d, 0.05 * w)
    xc = d - 1.5 * r
    if style == 1:  # panel radiator: vertical tubes between headers
        tubes = [_blk(xc - r, xc + r, y - 0.35 * r, y + 0.35 * r, 0.05 * h, 0.95 * h, colour)
                 for y in np.linspace(-w / 2 + 2 * r, w / 2 - 2 * r, _count(w, 0.05, 4, 12))]
        headers = [_rod((xc, -w / 2, z), (xc, w / 2, z), 1.5 * r, colour) for z in (0.05 * h, 0.95 * h)]
        return tubes + headers + _rail_brackets(xc, w, h, r, colour)
    posts = [_post(xc, y, 0.0, h, r, colour) for y in (-w / 2 + r, w / 2 - r)]
    rungs = [_rod((xc, -w / 2 + r, z), (xc, w / 2 - r, z), 0.7 * r, colour)
             for z in np.linspace(0.12 * h, 0.95 * h, _count(h, 0.1, 3, 9))]
    parts = posts + rungs + _rail_brackets(xc, w, h, r, colour)
    if style == 2:
        parts += [_blk(xc - 2.5 * r, xc - r, -0.3 * w, 0.3 * w, 0.45 * h, 0.97 * h, 'fabric_teal'),
                  _blk(xc + r, xc + 1.5 * r, -0.3 * w, 0.3 * w, 0.3 * h, 0.97 * h, 'fabric_teal'),
                  _blk(xc - 2.5 * r, xc + 1.5 * r, -0.3 * w, 0.3 * w, 0.95 * h, h, 'fabric_teal')]
    return parts


def _rail_brackets(xc: float, w: float, h: float, r: float, colour: str) -> Parts:
    return [_blk(0.0, xc, y - r / 2, y + r / 2, z - r / 2, z + r / 2, colour)
            for y in (-w / 2 + r, w / 2 - r) for z in (0.2 * h, 0.85 * h)]


def _cup(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Mug with its handle on the +y side."""
    hw = 0.25 * w
    r, cy = min(d / 2, (w - hw) / 2), -hw / 2
    t = 0.2 * hw
    y1 = cy + r + hw
    return [_disc(d / 2, cy, 0.0, 0.97 * h, r, r, 'ceramic', 12),
            _disc(d / 2, cy, 0.97 * h - 0.01 * h, h, 0.8 * r, 0.8 * r, 'coffee', 12),
            _blk(d / 2 - t, d / 2 + t, y1 - t, y1, 0.25 * h, 0.8 * h, 'ceramic'),
            _blk(d / 2 - t, d / 2 + t, cy + 0.9 * r, y1, 0.7 * h, 0.8 * h, 'ceramic'),
            _blk(d / 2 - t, d / 2 + t, cy + 0.9 * r, y1, 0.25 * h, 0.35 * h, 'ceramic')]


def _toothbrush(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Brushes in a tumbler when the box is upright, else one brush lying along y."""
    if h < 0.6 * max(d, w):
        t = 0.5 * min(d, h)
        return [_blk(d / 2 - t / 2, d / 2 + t / 2, -w / 2, 0.3 * w, 0.0, 0.5 * h, 'art_blue'),
                _blk(d / 2 - t / 2, d / 2 + t / 2, 0.3 * w, w / 2, 0.0, 0.4 * h, 'white'),
                _blk(d / 2 - 0.4 * t, d / 2 + 0.4 * t, 0.3 * w, w / 2, 0.4 * h, h, 'sky')]
    r = min(d / 2, w / 2)
    parts = [_disc(d / 2, 0.0, 0.0, 0.55 * h, 0.9 * r, 0.9 * r, 'glass', 8, top=1.1)]
    for side, colour in ((-1.0, 'art_blue'), (1.0, 'art_green')):
        top = (d / 2, side * (w / 2 - 0.2 * r), 0.85 * h)
        parts += [_beam((d / 2, side * 0.3 * r, 0.1 * h), top, 0.12 * r, colour),
                  _beam(top, (d / 2, top[1], h), 0.14 * r, 'white', 0.3 * r)]
    return parts


def _brush(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Toilet brush in its holder."""
    r = min(d, w) / 2
    return [_disc(d / 2, 0.0, 0.0, 0.4 * h, 0.85 * r, 0.85 * r, 'white', 8, top=1 / 0.85),
            _disc(d / 2, 0.0, 0.4 * h, 0.42 * h, r, r, 'chrome', 8),
            _post(d / 2, 0.0, 0.42 * h, 0.93 * h, 0.12 * r, 'grey_light'),
            _ell(d / 2 - 0.18 * r, d / 2 + 0.18 * r, -0.18 * r, 0.18 * r, 0.9 * h, h, 'chrome')]


# --- lighting -----------------------------------------------------------------------

def _lamp(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    style = v % 4
    rx, ry, cx = d / 2, w / 2, d / 2
    if style == 0:  # table lamp with a conical shade
        return [_disc(cx, 0.0, 0.0, 0.08 * h, 0.4 * rx, 0.4 * ry, 'ceramic_blue', 8),
                _disc(cx, 0.0, 0.08 * h, 0.45 * h, 0.3 * rx, 0.3 * ry, 'ceramic_blue', 8, top=0.5),
                _post(cx, 0.0, 0.45 * h, 0.6 * h, 0.05 * min(rx, ry), 'brass'),
                _disc(cx, 0.0, 0.55 * h, h, rx, ry, 'lamp_shade', 12, top=0.6)]
    if style == 1:  # standing lamp with a drum shade
        return [_disc(cx, 0.0, 0.0, 0.03 * h, 0.6 * rx, 0.6 * ry, 'charcoal', 12),
                _post(cx, 0.0, 0.03 * h, 0.75 * h, 0.06 * min(rx, ry), 'metal'),
                _disc(cx, 0.0, 0.7 * h, h, rx, ry, 'cream', 12)]
    if style == 2:  # desk lamp: base, two arms, head
        elbow, head = (0.1 * d, -0.2 * w, 0.75 * h), (0.85 * d, 0.2 * ry, 0.85 * h)
        t = 0.05 * min(d, w, h)
        return [_blk(0.0, 0.45 * d, -ry, 0.0, 0.0, 0.05 * h, 'black'),
                _beam((0.22 * d, -0.5 * ry, 0.05 * h), elbow, t, 'black'),
                _beam(elbow, head, t, 'black'),
                _disc(0.85 * d, 0.2 * ry, 0.6 * h, h, 0.3 * rx, 0.8 * ry, 'black', 8, top=0.4),
                _disc(0.85 * d, 0.2 * ry, 0.58 * h, 0.6 * h, 0.25 * rx, 0.6 * ry, 'bulb', 8)]
    globe = min(0.85 * h, 1.3 * max(d, w))  # globe lamp, on a stem when the box is tall
    base = min(0.15 * h, h - globe)
    parts = [_disc(cx, 0.0, 0.0, base, 0.5 * rx, 0.5 * ry, 'wood_light', 8, top=0.8), _ell(0.0, d, -ry, ry, h - globe, h, 'bulb')]
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
    """Ceiling fixture hanging below z = h."""
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


# --- screens, wall art, electronics -------------------------------------------------

def _tv(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Flat screen facing +x, on a stand unless the box is wall-thin."""
    bezel, stand = _pick([('charcoal', 'pedestal'), ('metal', 'feet'), ('white', 'bar')], v)
    wall = d < 0.08
    st = min(0.05, 0.6 * d) if wall else min(0.05, 0.3 * d)
    x0 = 0.0 if wall else d / 2 - st / 2
    z0 = 0.0 if wall else 0.15 * h
    frame = min(0.02, 0.03 * w)
    parts = [_blk(x0, x0 + st, -w / 2, w / 2, z0, h, bezel),
             _blk(x0 + st, x0 + st + 0.003, -w / 2 + frame, w / 2 - frame, z0 + frame, h - frame, 'screen')]
    if wall:
        return parts
    if stand == 'pedestal':
        return parts + [_blk(0.0, d, -0.2 * w, 0.2 * w, 0.0, 0.02 * h, bezel),
                        _blk(d / 2 - st, d / 2, -0.05 * w, 0.05 * w, 0.02 * h, 0.3 * h, bezel)]
    if stand == 'feet':
        return parts + [_beam((x, y, 0.01 * h), (d / 2, y * 0.9, z0), 0.02 * h, bezel)
                        for x in (0.0, d) for y in (-0.4 * w, 0.4 * w)]
    return parts + [_blk(0.0, d, -0.35 * w, 0.35 * w, 0.0, 0.02 * h, bezel),
                    _blk(d / 2 - st / 2, d / 2 + st / 2, -0.3 * w, 0.3 * w, 0.02 * h, z0, bezel)]


_ART = (('wood_medium', 'landscape'), ('black', 'blocks'), ('white', 'sea'), ('brass', 'circles'))


def _picture(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Framed canvas hanging on a wall at x = 0."""
    frame, art = _pick(_ART, v)
    f = min(0.05, 0.08 * min(w, h))
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.0, f, frame), _blk(0.0, d, -w / 2, w / 2, h - f, h, frame),
             _blk(0.0, d, -w / 2, -w / 2 + f, f, h - f, frame), _blk(0.0, d, w / 2 - f, w / 2, f, h - f, frame)]
    return parts + _canvas(0.5 * d, 0.7 * d, -w / 2 + f, w / 2 - f, f, h - f, art)


def _canvas(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, art: str) -> Parts:
    """A simple painting: background bands plus a few motifs slightly in front."""
    cw, ch, step = y1 - y0, z1 - z0, 0.15 * (x1 - x0)

    def at(a: float, b: float, c: float, e: float, colour: str, layer: int = 1) -> Mesh:
        """Layer 0 is the canvas itself; motifs on higher layers stand further forward."""
        return _blk(x0 if layer == 0 else x1, x1 + layer * step, y0 + a * cw, y0 + b * cw, z0 + c * ch, z0 + e * ch, colour)

    if art == 'landscape':
        return [at(0, 1, 0.45, 1, 'sky', 0), at(0, 1, 0, 0.45, 'art_green', 0),
                at(0.1, 0.55, 0.3, 0.55, 'plant_dark'), at(0.7, 0.82, 0.65, 0.85, 'sun')]
    if art == 'blocks':
        return [at(0, 1, 0, 1, 'white', 0), at(0, 0.4, 0.55, 1, 'art_red'), at(0.7, 1, 0, 0.3, 'art_blue'),
                at(0.45, 0.65, 0, 0.25, 'art_yellow'), at(0.4, 0.44, 0, 1, 'black', 2), at(0, 1, 0.5, 0.54, 'black', 2)]
    if art == 'sea':
        return [at(0, 1, 0.5, 1, 'sky', 0), at(0, 1, 0.2, 0.5, 'sea', 0), at(0, 1, 0, 0.2, 'sand', 0),
                at(0.55, 0.62, 0.5, 0.78, 'white'), at(0.15, 0.3, 0.75, 0.82, 'white')]
    discs = [_rod((x1, y0 + a * cw, z0 + b * ch), (x1 + step, y0 + a * cw, z0 + b * ch), r * min(cw, ch), colour, 10)
             for a, b, r, colour in ((0.3, 0.6, 0.22, 'art_red'), (0.65, 0.35, 0.2, 'art_yellow'),
                                     (0.72, 0.75, 0.12, 'sun'))]
    return [at(0, 1, 0, 1, 'grey_dark', 0)] + discs


def _mirror(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    style = v % 3
    if style == 2:  # oval with brass frame
        return [_oval(0.0, 0.6 * d, w / 2, h, 'brass'), _oval(0.0, d, 0.9 * w / 2, 0.9 * h, 'mirror')]
    frame = 'wood_medium' if style == 0 else 'black'
    f = min(0.06 if style == 0 else 0.02, 0.1 * min(w, h))
    return [_blk(0.0, d, -w / 2, w / 2, 0.0, f, frame), _blk(0.0, d, -w / 2, w / 2, h - f, h, frame),
            _blk(0.0, d, -w / 2, -w / 2 + f, f, h - f, frame), _blk(0.0, d, w / 2 - f, w / 2, f, h - f, frame),
            _blk(0.0, 0.7 * d, -w / 2 + f, w / 2 - f, f, h - f, 'mirror')]


def _oval(x0: float, x1: float, ry: float, height: float, colour: str) -> Mesh:
    """Elliptic slab facing +x, centred on y = 0 and on a box of the given height."""
    unit = frustum((0.0, 0.0, 0.0), 1.0, 1.0, max(x1 - x0, 1e-6), _c(colour), 12, axis='x')
    return unit.scaled((1.0, ry, height / 2)).transformed(0.0, ((x0 + x1) / 2, 0.0, height / 2))


def _keyboard(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Keys face up, rows run along y; the front edge is +x."""
    parts = [_soft(0.0, d, -w / 2, w / 2, 0.0, 0.6 * h, 'charcoal', 0.2 * h)]
    rows = _split(0.08 * d, 0.92 * d, 5)
    for i, (a, b) in enumerate(rows):
        pad = 0.12 * (b - a)
        blocks = ((0.03, 0.27), (0.32, 0.68), (0.73, 0.97)) if i == 4 else ((0.03, 0.76), (0.8, 0.97))
        parts += [_blk(a + pad, b - pad, -w / 2 + p * w, -w / 2 + q * w, 0.6 * h, h, 'grey_dark') for p, q in blocks]
    return parts


def _laptop(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Open laptop: base on the table, screen leaning back at the hinge (x = 0 side)."""
    shell, keys = _pick([('steel', 'black'), ('charcoal', 'black'), ('white', 'grey')], v)
    bt = min(0.02, 0.08 * h)
    lid = min(0.008, 0.05 * d)
    tilt = np.radians(12.0)
    length = h - bt
    hinge_x = length * np.sin(tilt) + lid
    screen = Mesh.merged([_blk(-lid, 0.0, -w / 2, w / 2, 0.0, length, shell),
                          _blk(0.0, 0.002, -0.46 * w, 0.46 * w, 0.05 * length, 0.95 * length, 'screen')])
    screen = screen.transformed(rotation_y(-tilt), (hinge_x, 0.0, bt))
    return [_blk(hinge_x - lid, d, -w / 2, w / 2, 0.0, bt, shell),
            _blk(hinge_x + 0.05 * d, hinge_x + 0.5 * (d - hinge_x), -0.44 * w, 0.44 * w, bt, bt + 0.002, keys),
            _blk(hinge_x + 0.62 * (d - hinge_x), hinge_x + 0.92 * (d - hinge_x), -0.15 * w, 0.15 * w, bt, bt + 0.001,
                 'grey'), screen]


def _station(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Robot charging pad: the robot docks from +x onto contacts near the back."""
    return [_blk(0.0, d, -w / 2, w / 2, 0.0, 0.7 * h, 'grey_dark'),
            _blk(0.05 * d, 0.25 * d, -0.3 * w, -0.1 * w, 0.7 * h, h, 'brass'),
            _blk(0.05 * d, 0.25 * d, 0.1 * w, 0.3 * w, 0.7 * h, h, 'brass'),
            _blk(0.02 * d, 0.06 * d, -0.03 * w, 0.03 * w, 0.7 * h, h, 'led'),
            _blk(0.9 * d, d, -w / 2, w / 2, 0.7 * h, h, 'art_yellow')]


# --- openings -------------------------------------------------------------------------

def _door(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Frame through the wall (x is the wall's thickness) and a closed leaf with handles on both sides."""
    leaf_colour, frame, style = _pick([('wood_medium', 'white', 'plain'), ('off_white', 'white', 'panels'),
                                       ('wood_dark', 'wood_dark', 'glass')], v)
    fw = min(0.07, 0.08 * w, 0.08 * h)
    lt = min(0.045, 0.4 * d)
    x0, x1 = d / 2 - lt / 2, d / 2 + lt / 2
    y0, y1, top = -w / 2 + fw, w / 2 - fw, h - fw
    parts = [_blk(0.0, d, -w / 2, y0, 0.0, h, frame), _blk(0.0, d, y1, w / 2, 0.0, h, frame),
             _blk(0.0, d, y0, y1, top, h, frame), _blk(x0, x1, y0, y1, 0.0, top, leaf_colour)]
    if style == 'panels':
        parts += [_blk(x0 - 0.004, x1 + 0.004, y0 + 0.15 * (y1 - y0), y1 - 0.15 * (y1 - y0), a * top, b * top, 'white')
                  for a, b in ((0.08, 0.42), (0.52, 0.92))]
    if style == 'glass':
        parts += [_blk(x0 - 0.002, x1 + 0.002, y0 + 0.2 * (y1 - y0), y1 - 0.2 * (y1 - y0), a * top, b * top, 'glass')
                  for a, b in ((0.45, 0.6), (0.64, 0.78), (0.82, 0.94))]
    return parts + _door_handles(x0, x1, y1 - min(0.08, 0.12 * (y1 - y0)), min(1.0, 0.42 * h))


def _door_handles(x0: float, x1: float, y: float, z: float) -> Parts:
    """Lever handles on both faces of a leaf spanning [x0, x1] (frame from x = 0); levers point to -y."""
    reach = max(min(0.06, 0.45 * x0), 1e-4)
    parts = []
    for face, out in ((x0, -1.0), (x1, 1.0)):
        tip = face + out * reach
        parts += [_blk(face, face + out * 0.3 * reach, y - 0.025, y + 0.025, z - 0.07, z + 0.07, 'chrome'),
                  _blk(tip - out * 0.3 * reach, tip, y - 0.12, y + 0.01, z - 0.012, z + 0.012, 'chrome')]
    return parts


def _window(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Window set in the wall (x is the wall's thickness): lining, sashes, mullions, glass, sill."""
    frame, layout = _pick([('white', 'casement'), ('wood_medium', 'cross'), ('grey_dark', 'transom')], v)
    fw = min(0.07, 0.1 * min(w, h))
    xm = d / 2
    sash = min(0.04, 0.5 * fw)
    sill = 'white' if frame != 'white' else 'grey_light'
    parts = [_blk(0.0, d, -w / 2, w / 2, 0.0, fw, sill), _blk(0.0, d, -w / 2, w / 2, h - fw, h, frame),
             _blk(0.0, d, -w / 2, -w / 2 + fw, fw, h - fw, frame), _blk(0.0, d, w / 2 - fw, w / 2, fw, h - fw, frame),
             _blk(xm - 0.004, xm + 0.004, -w / 2 + fw, w / 2 - fw, fw, h - fw, 'glass')]
    mullions = []
    if layout in ('casement', 'cross'):
        mullions.append(('v', 0.0))
    if layout == 'cross':
        mullions.append(('h', fw + 0.55 * (h - 2 * fw)))
    if layout == 'transom':
        mullions.append(('h', fw + 0.72 * (h - 2 * fw)))
        mullions.append(('v', 0.0))
    for kind, at in mullions:
        if kind == 'v':
            top = h - fw if layout != 'transom' else fw + 0.72 * (h - 2 * fw)
            parts.append(_blk(xm - 2 * sash, xm + 2 * sash, at - sash, at + sash, fw, top, frame))
        else:
            parts.append(_blk(xm - 2 * sash, xm + 2 * sash, -w / 2 + fw, w / 2 - fw, at - sash, at + sash, frame))
    return parts


# --- decoration -------------------------------------------------------------------------

def _decoration(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    """Flat boxes get a plate, tray or books; upright ones a plant, flowers or grasses."""
    style = v % 3
    if h < 0.4 * min(d, w):
        return _flat_decoration(d, w, h, style)
    rx, ry = d / 2, w / 2
    if style == 0:  # potted plant
        return [_disc(rx, 0.0, 0.0, 0.35 * h, 0.35 * rx, 0.35 * ry, 'terracotta', 8, top=1.3),
                _disc(rx, 0.0, 0.33 * h, 0.36 * h, 0.42 * rx, 0.42 * ry, 'soil', 8),
                _ell(0.05 * d, 0.75 * d, -0.95 * ry, 0.2 * ry, 0.35 * h, 0.8 * h, 'plant_green'),
                _ell(0.3 * d, d, -0.1 * ry, ry, 0.4 * h, 0.85 * h, 'plant_dark'),
                _ell(0.2 * d, 0.8 * d, -0.5 * ry, 0.5 * ry, 0.6 * h, h, 'plant_green')]
    if style == 1:  # vase with flowers
        parts = [_disc(rx, 0.0, 0.0, 0.25 * h, 0.3 * rx, 0.3 * ry, 'ceramic_blue', 8, top=1.5),
                 _disc(rx, 0.0, 0.25 * h, 0.5 * h, 0.45 * rx, 0.45 * ry, 'ceramic_blue', 8, top=0.45)]
        for i, a in enumerate(np.arange(5) * 2 * np.pi / 5):
            tip = (rx + 0.7 * rx * np.cos(a), 0.7 * ry * np.sin(a), 0.9 * h - 0.05 * h * (i % 2))
            parts += [_beam((rx, 0.0, 0.45 * h), tip, 0.05 * min(rx, ry), 'plant_green'),
                      _ell(tip[0] - 0.3 * rx, tip[0] + 0.3 * rx, tip[1] - 0.3 * ry, tip[1] + 0.3 * ry, tip[2] - 0.05 * h,
                           tip[2] + 0.1 * h, ('art_red', 'art_yellow', 'fabric_pink')[i % 3])]
        return parts
    parts = [_disc(rx, 0.0, 0.0, 0.45 * h, 0.35 * rx, 0.35 * ry, 'white', 8, top=0.6)]  # grasses in a slim vase
    return parts + [_beam((rx, 0.0, 0.4 * h), (rx + 0.9 * rx * np.cos(a), 0.9 * ry * np.sin(a), h), 0.04 * min(rx, ry),
                          'sand') for a in np.arange(7) * 2 * np.pi / 7]


def _flat_decoration(d: float, w: float, h: float, style: int) -> Parts:
    rx, ry = d / 2, w / 2
    if style == 0:  # decorative plate
        return [_disc(rx, 0.0, 0.0, 0.6 * h, 0.6 * rx, 0.6 * ry, 'ceramic_blue', 12, top=1 / 0.6),
                _disc(rx, 0.0, 0.6 * h, h, 0.7 * rx, 0.7 * ry, 'white', 12)]
    if style == 1:  # fruit bowl
        return [_disc(rx, 0.0, 0.0, 0.5 * h, 0.6 * rx, 0.6 * ry, 'wood_medium', 12, top=1 / 0.6)] + [
            _ell(x - 0.25 * d, x + 0.25 * d, y - 0.25 * w, y + 0.25 * w, 0.3 * h, h, colour)
            for x, y, colour in ((0.35 * d, -0.2 * w, 'fruit_orange'), (0.65 * d, -0.1 * w, 'fruit_red'),
                                 (0.45 * d, 0.22 * w, 'fruit_green'))]
    return [_blk(0.05 * d, 0.95 * d, -0.45 * w, 0.4 * w, 0.0, 0.33 * h, 'fabric_red'),  # stack of books
            _blk(0.0, 0.9 * d, -0.5 * w, 0.45 * w, 0.33 * h, 0.66 * h, 'fabric_navy'),
            _blk(0.1 * d, d, -0.4 * w, 0.5 * w, 0.66 * h, h, 'cream')]


def _generic(d: float, w: float, h: float, v: int, prefab: str) -> Parts:
    return [_soft(0.0, d, -w / 2, w / 2, 0.0, h, 'grey_light', 0.1 * min(d, w, h))]


# --- registry and entry points ------------------------------------------------------------

@dataclass(frozen=True)
class _Spec:
    build: Builder
    variants: int
    front: str = 'any'  # which box axis the front may look along: 'short' | 'long' | 'any'


_SPECS: dict[str, _Spec] = {
    'Armchair': _Spec(_armchair, 4), 'Bathtub': _Spec(_bathtub, 1, 'short'), 'Bed': _Spec(_bed, 5, 'long'),
    'Brush': _Spec(_brush, 1), 'Burner': _Spec(_burner, 1), 'Cabinet': _Spec(_cabinet, 4, 'short'),
    'Chair': _Spec(_chair, 4), 'Closet': _Spec(_closet, 4, 'short'), 'Counter': _Spec(_counter, 4),
    'Cup': _Spec(_cup, 1), 'Decoration': _Spec(_decoration, 3), 'Desk': _Spec(_desk, 3, 'short'),
    'Dishwasher': _Spec(_dishwasher, 1), 'Door': _Spec(_door, 3, 'short'), 'Dresser': _Spec(_dresser, 3, 'short'),
    'Drying': _Spec(_drying, 3, 'short'), 'Keyboard': _Spec(_keyboard, 1, 'short'),
    'KitchenFurniture': _Spec(_kitchen, 4), 'Lamp': _Spec(_lamp, 4), 'Laptop': _Spec(_laptop, 3, 'short'),
    'Light': _Spec(_light, 3), 'Lighter': _Spec(_lighter, 1, 'short'), 'Microwave': _Spec(_microwave, 1, 'short'),
    'Mirror': _Spec(_mirror, 3, 'short'), 'Nightstand': _Spec(_nightstand, 3), 'Oven': _Spec(_oven, 1),
    'Picture': _Spec(_picture, 4, 'short'), 'Pouf': _Spec(_pouf, 4), 'Refrigerator': _Spec(_fridge, 3),
    'Shelf': _Spec(_shelf, 3, 'short'), 'ShowerCabin': _Spec(_shower, 1), 'Sink': _Spec(_sink, 3),
    'Sofa': _Spec(_sofa, 4, 'short'), 'Standard': _Spec(_standard, 4, 'short'), 'Station': _Spec(_station, 1),
    'Stool': _Spec(_stool, 4), 'Table': _Spec(_table, 4), 'Toilet': _Spec(_toilet, 1, 'long'),
    'Toothbrush': _Spec(_toothbrush, 1), 'Towel': _Spec(_towel, 4, 'short'), 'Tv': _Spec(_tv, 3, 'short'),
    'Wall': _Spec(_window, 3, 'short'), 'Washbasin': _Spec(_washbasin, 3, 'short'),
    'WashingMachine': _Spec(_washing_machine, 1),
}
_GENERIC = _Spec(_generic, 1)

OBJECT_TYPES: tuple[str, ...] = tuple(sorted(_SPECS))
"""Every type with a dedicated model; any other type string gets a generic bevelled box."""


def variant_count(object_type: str) -> int:
    """How many visibly different models ``build_model`` offers for a type."""
    return _SPECS.get(object_type, _GENERIC).variants


def build_model(object_type: str, size: Sequence[float], variant: int, facing: int = 0, prefab: str = '') -> Mesh:
    """Model of ``object_type`` filling the upright box ``size`` centred at the origin.

    ``variant`` is taken modulo ``variant_count``; ``facing`` (0..3) makes the
    front look along local +x, +y, -x, -y.  Types whose front belongs on a
    particular box axis (a bed's foot on its long axis, a wardrobe's doors on
    its long side) turn a quarter when ``facing`` contradicts the box shape.
    """
    spec = _SPECS.get(object_type, _GENERIC)
    extents = _clean_size(size)
    facing = _resolve_facing(spec.front, extents, int(facing) % 4)
    d, w, h = (extents[0], extents[1], extents[2]) if facing % 2 == 0 else (extents[1], extents[0], extents[2])
    mesh = Mesh.merged(spec.build(d, w, h, int(variant) % spec.variants, prefab or ''))
    return _fit(mesh, (d, w, h)).transformed(facing * np.pi / 2)


def _clean_size(size: Sequence[float]) -> np.ndarray:
    values = np.abs(np.asarray(size, np.float64).reshape(3))
    return np.maximum(np.where(np.isfinite(values), values, MIN_EXTENT), MIN_EXTENT)


def _resolve_facing(front: str, size: np.ndarray, facing: int) -> int:
    depth, width = (size[0], size[1]) if facing % 2 == 0 else (size[1], size[0])
    if (front == 'short' and depth > SWAP_RATIO * width) or (front == 'long' and width > SWAP_RATIO * depth):
        return (facing + 1) % 4
    return facing


def _fit(mesh: Mesh, size: Sequence[float]) -> Mesh:
    """Map the mesh's bounding box exactly onto a box of ``size`` centred at the origin."""
    lo, hi = mesh.bounds()
    scale = np.asarray(size, np.float64) / np.maximum(hi - lo, 1e-12)
    return Mesh((mesh.vertices - (lo + hi) / 2) * scale, mesh.faces, mesh.colours)
