"""Top-down architectural plan of a house, drawn with OpenCV only.

:func:`draw_plan` returns a BGR picture of one house; :func:`write_plan` saves it. :func:`render_plan`
returns the same picture with its :class:`PlanFrame` (world -> pixel mapping) and the pixel centre of
each room label, for callers that draw more on top or check what was drawn.

Layers, bottom to top:

* room floors, a pastel colour per room *type* (:data:`ROOM_COLORS`, RGB);
* the optional free-space overlay (translucent green over FREE cells of a :class:`Grid`);
* objects as yawed boxes (outline + light fill) coloured by category group (:data:`OBJECT_GROUPS`,
  :data:`GROUP_COLORS`); overhead items (bottom above :data:`OVERHEAD_Z`, e.g. wall cabinets,
  pictures) are dashed and unfilled; doors, windows, ceiling lights and the station are symbols;
* walls dark at their true thickness, lintels over doorways as thin dashed lines, columns grey;
* windows as double thin blue lines in the wall;
* doors: open = green leaf swung into the more private room (a bedroom rather than a corridor)
  with its swing arc, closed = red bar across the gap (the doorway found from its lintels);
* ceiling lights (yellow circle with a cross), lamps (yellow dot), wall lights (yellow diamond);
* the station (circle with an arrow along the robot's start heading), then the optional path
  (thick polyline, green start, red goal) and poses (small arrows);
* labels, the title, the legend, a scale bar and the +x/+y (north) axes.

Labels: a room is named where its label fits farthest from walls and furniture (a distance
transform over the room minus obstacles, the pole of inaccessibility among the spots where the
text fits), shrinking or turning the text vertical in narrow rooms. Doors, the station and objects
(largest first) get small labels placed greedily at the first candidate spot that overlaps no
earlier label, wall or other object; an abbreviation (``KitchenFurniture_4`` -> ``KF4``) is tried
before a label is dropped.

Frame: world metres (x right, y up) map to pixels with y flipped; see :class:`PlanFrame`.
"""
from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ravh_sim.files import write_image
from ravh_sim.nav.grid import FREE, Grid
from ravh_sim.world.geometry import box_corners
from ravh_sim.world.house import Door, House, HouseObject, ModelBox, Room, Window

RGB = tuple[int, int, int]
XY = Sequence[float] | np.ndarray          # a point (x, y), as a sequence or an array

#: Floor colour (RGB) per room type; types not listed use :data:`DEFAULT_ROOM_COLOR`.
ROOM_COLORS: dict[str, RGB] = {
    "Bedroom": (206, 204, 250),            # lavender
    "Bathroom": (184, 224, 250),           # sky blue
    "LivingRoom": (204, 238, 190),         # pale green
    "Kitchen": (255, 204, 170),            # apricot
    "KitchenLivingRoom": (250, 236, 160),  # pale gold
    "Corridor": (230, 230, 230),           # light grey
    "Hall": (240, 224, 192),               # sand
    "Office": (252, 200, 210),             # pink
    "UtilityRoom": (176, 234, 220),        # aqua
    "Standard": (200, 212, 208),           # grey-green
    "Balcony": (220, 250, 150),            # lime
    "DressingRoom": (242, 196, 242),       # orchid
}
DEFAULT_ROOM_COLOR: RGB = (238, 238, 238)

#: Category group of each object type; types not listed are "other".
OBJECT_GROUPS: dict[str, str] = {
    **dict.fromkeys(("Chair", "Table", "Bed", "Nightstand", "Closet", "Dresser", "Cabinet", "Shelf",
                     "Desk", "Armchair", "Sofa", "Stool", "Pouf", "Standard", "KitchenFurniture",
                     "Counter"), "furniture"),
    **dict.fromkeys(("Tv", "Refrigerator", "Microwave", "Oven", "Burner", "Dishwasher",
                     "WashingMachine", "Laptop", "Keyboard"), "appliances"),
    **dict.fromkeys(("Toilet", "Washbasin", "Sink", "ShowerCabin", "Bathtub", "Towel", "Drying",
                     "Toothbrush", "Brush"), "bathroom"),
    **dict.fromkeys(("Picture", "Decoration", "Mirror", "Cup"), "decoration"),
    **dict.fromkeys(("Lamp", "Light", "Lighter"), "lights"),
}
#: (outline, fill) RGB per object group.
GROUP_COLORS: dict[str, tuple[RGB, RGB]] = {
    "furniture": ((139, 94, 52), (236, 222, 204)),
    "appliances": ((84, 84, 168), (214, 214, 244)),
    "bathroom": ((24, 128, 150), (208, 238, 244)),
    "decoration": ((176, 60, 120), (246, 214, 230)),
    "lights": ((184, 134, 0), (255, 240, 176)),
    "other": ((110, 110, 110), (226, 226, 226)),
}
#: Object types drawn as symbols instead of boxes ("Wall" objects are the windows).
SYMBOL_TYPES = frozenset({"Door", "Wall", "Light", "Station"})
#: Objects whose bottom is this high above their floor are overhead (dashed, unfilled).
OVERHEAD_Z = 1.2

WALL_RGB: RGB = (44, 44, 48)
COLUMN_RGB: RGB = (128, 128, 132)
LINTEL_RGB: RGB = (120, 120, 120)
WINDOW_RGB: RGB = (30, 110, 230)
WINDOW_FILL_RGB: RGB = (226, 240, 255)
DOOR_OPEN_RGB: RGB = (40, 160, 80)
DOOR_CLOSED_RGB: RGB = (214, 48, 48)
DOOR_CLOSED_EDGE_RGB: RGB = (150, 20, 20)
LIGHT_RGB: RGB = (255, 210, 0)
LIGHT_EDGE_RGB: RGB = (150, 105, 0)
STATION_RGB: RGB = (130, 50, 170)
STATION_FILL_RGB: RGB = (245, 225, 245)
FREE_RGB: RGB = (60, 200, 90)
FREE_ALPHA = 0.3
PATH_RGB: RGB = (245, 130, 20)
START_RGB: RGB = (30, 160, 60)
GOAL_RGB: RGB = (210, 30, 60)
POSE_RGB: RGB = (30, 60, 170)
TEXT_RGB: RGB = (40, 40, 44)
SUBTEXT_RGB: RGB = (96, 96, 104)

MARGIN = 36          # px around the plan and the legend
TITLE_BAND = 92      # px above the plan for the title
PLAN_PAD_M = 0.25    # m added around house.bounds (wall thickness, windows)
MAX_SIDE = 2400      # px; px_per_m is lowered so the image's long side stays within it
WIDE_ASPECT = 2.0    # plans wider than this (w/h) get the legend below instead of beside

SHIFT = 4            # fractional bits for sub-pixel OpenCV drawing
SIMPLEX, DUPLEX, AA = cv2.FONT_HERSHEY_SIMPLEX, cv2.FONT_HERSHEY_DUPLEX, cv2.LINE_AA


def _bgr(rgb: RGB) -> tuple[int, int, int]:
    return (rgb[2], rgb[1], rgb[0])


def room_color(room_type: str) -> RGB:
    """The floor colour (RGB) of a room type."""
    return ROOM_COLORS.get(room_type, DEFAULT_ROOM_COLOR)


def object_group(obj_type: str) -> str:
    return OBJECT_GROUPS.get(obj_type, "other")


# --------------------------------------------------------------------------- frame and layout

@dataclass(frozen=True)
class PlanFrame:
    """Where the house lies in the picture: world (x, y) -> pixel (u, v), y flipped."""
    scale: float                   # pixels per metre
    xmin: float                    # world x at the plan area's left edge
    ymax: float                    # world y at the plan area's top edge
    left: int                      # plan area's left pixel column
    top: int                       # plan area's top pixel row
    plan_w: int
    plan_h: int
    width: int                     # whole image
    height: int
    legend_below: bool             # legend blocks in a row below the plan (else a column beside)

    def to_px(self, x: float, y: float) -> tuple[float, float]:
        return (self.left + (x - self.xmin) * self.scale, self.top + (self.ymax - y) * self.scale)

    def to_world(self, u: float, v: float) -> tuple[float, float]:
        return (self.xmin + (u - self.left) / self.scale, self.ymax - (v - self.top) / self.scale)

    def to_px_array(self, points: np.ndarray | Sequence[XY]) -> np.ndarray:
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        return np.column_stack((self.left + (p[:, 0] - self.xmin) * self.scale,
                                self.top + (self.ymax - p[:, 1]) * self.scale))


@dataclass(frozen=True)
class _Block:
    """A legend block: its size and how to draw it with its top-left corner at (x, y)."""
    w: int
    h: int
    draw: Callable[[np.ndarray, int, int, PlanFrame], None]


def plan_frame(house: House, px_per_m: float = 80, legend: Sequence[tuple[int, int]] = ()) -> PlanFrame:
    """The frame of the plan picture, given the (w, h) of the legend blocks (none: no legend)."""
    xmin, ymin, xmax, ymax = house.bounds
    wm, hm = xmax - xmin + 2 * PLAN_PAD_M, ymax - ymin + 2 * PLAN_PAD_M
    below = wm / hm > WIDE_ASPECT
    lw, lh = _legend_extent(legend, below)
    if below:
        extra_w, extra_h = 2 * MARGIN, TITLE_BAND + 2 * MARGIN + lh
    else:
        extra_w, extra_h = 3 * MARGIN + lw, TITLE_BAND + MARGIN
    scale = min(px_per_m, (MAX_SIDE - extra_w) / wm, (MAX_SIDE - extra_h) / hm)
    plan_w, plan_h = math.ceil(wm * scale), math.ceil(hm * scale)
    if below:
        width = 2 * MARGIN + max(plan_w, lw)
        height = TITLE_BAND + plan_h + (MARGIN + lh if legend else 0) + MARGIN
    else:
        width = 2 * MARGIN + plan_w + (MARGIN + lw if legend else 0)
        height = TITLE_BAND + max(plan_h, lh) + MARGIN
    return PlanFrame(scale, xmin - PLAN_PAD_M, ymax + PLAN_PAD_M, MARGIN, TITLE_BAND,
                     plan_w, plan_h, width, height, below)


def _legend_extent(sizes: Sequence[tuple[int, int]], below: bool) -> tuple[int, int]:
    if not sizes:
        return 0, 0
    gap = MARGIN // 2
    if below:
        return sum(w for w, _ in sizes) + gap * (len(sizes) - 1), max(h for _, h in sizes)
    return max(w for w, _ in sizes), sum(h for _, h in sizes) + gap * (len(sizes) - 1)


def _legend_origins(frame: PlanFrame, blocks: Sequence[_Block]) -> list[tuple[int, int]]:
    below = frame.legend_below
    x, y = (frame.left, frame.top + frame.plan_h + MARGIN) if below else (
        frame.left + frame.plan_w + MARGIN, frame.top)
    origins = []
    for b in blocks:
        origins.append((x, y))
        x, y = (x + b.w + MARGIN // 2, y) if below else (x, y + b.h + MARGIN // 2)
    return origins


# --------------------------------------------------------------------------- text

_SPECIAL = re.compile("([—²])")


def _text_size(text: str, font: int, scale: float, thick: int = 1) -> tuple[int, int]:
    """(width, ascent) in px of one line; '—' and '²' are drawn by hand (Hershey fonts lack them)."""
    width = 0
    for seg in filter(None, _SPECIAL.split(text)):
        shown, s = {"²": ("2", scale * 0.6), "—": ("M", scale)}.get(seg, (seg, scale))
        width += cv2.getTextSize(shown, font, s, thick)[0][0]
    return width, cv2.getTextSize("A", font, scale, thick)[0][1]


def _put_text(img: np.ndarray, text: str, org: tuple[int, int], font: int, scale: float,
              color: tuple[int, ...], thick: int = 1) -> None:
    """cv2.putText that also draws '—' and a superscript '²'; org is the left baseline point."""
    x, y = org
    ascent = cv2.getTextSize("A", font, scale, thick)[0][1]
    for seg in filter(None, _SPECIAL.split(text)):
        if seg == "²":
            cv2.putText(img, "2", (x, y - int(ascent * 0.45)), font, scale * 0.6, color, thick, AA)
        elif seg == "—":
            w = cv2.getTextSize("M", font, scale, thick)[0][0]
            yy = y - int(ascent * 0.4)
            cv2.line(img, (x + 2, yy), (x + w - 2, yy), color, max(1, thick), AA)
        else:
            cv2.putText(img, seg, (x, y), font, scale, color, thick, AA)
        x += _text_size(seg, font, scale, thick)[0]


def _beneath(img: np.ndarray, x0: int, y0: int, x1: int, y1: int) -> tuple[int, int, int]:
    """The median colour (BGR) of an image rectangle: the background a label is written on."""
    region = img[max(y0, 0):max(y1, 0), max(x0, 0):max(x1, 0)].reshape(-1, 3)
    if not region.size:
        return 255, 255, 255
    b, g, r = (int(v) for v in np.median(region, axis=0))
    return b, g, r


def _halo_text(img: np.ndarray, text: str, center: XY, font: int, scale: float,
               rgb: RGB) -> tuple[int, int, int, int]:
    """Centred one-line text over a halo of the colour beneath it; returns its rectangle."""
    w, h = _text_size(text, font, scale)
    x0, y0 = int(round(center[0] - w / 2)), int(round(center[1] - h / 2))
    _put_text(img, text, (x0, y0 + h), font, scale, _beneath(img, x0, y0, x0 + w, y0 + h + 2), 3)
    _put_text(img, text, (x0, y0 + h), font, scale, _bgr(rgb), 1)
    return x0, y0, x0 + w, y0 + h


@dataclass(frozen=True)
class _Line:
    """One line of a multi-line label."""
    text: str
    font: int
    scale: float
    rgb: RGB


def _block_size(lines: Sequence[_Line]) -> tuple[int, int]:
    sizes = [_text_size(ln.text, ln.font, ln.scale) for ln in lines]
    return max(w for w, _ in sizes), sum(int(h * 1.45) for _, h in sizes)


def _stamp_lines(img: np.ndarray, lines: Sequence[_Line], center: tuple[int, int], vertical: bool
                 ) -> tuple[int, int, int, int]:
    """Draw centred lines (turned 90° ccw when vertical) over a halo of the colour beneath them;
    returns their rectangle."""
    w, h = _block_size(lines)
    pad = 3
    masks, y = [], pad
    for ln in lines:
        lw, lh = _text_size(ln.text, ln.font, ln.scale)
        m = np.zeros((h + 2 * pad, w + 2 * pad), np.uint8)
        _put_text(m, ln.text, (pad + (w - lw) // 2, y + lh), ln.font, ln.scale, (255,))
        masks.append(m)
        y += int(lh * 1.45)
    halo_mask = cv2.dilate(np.max(masks, axis=0), np.ones((3, 3), np.uint8))
    if vertical:
        masks, halo_mask = [np.rot90(m).copy() for m in masks], np.rot90(halo_mask).copy()
    mh, mw = halo_mask.shape
    x0, y0 = center[0] - mw // 2, center[1] - mh // 2
    _composite(img, x0, y0, halo_mask, _beneath(img, x0, y0, x0 + mw, y0 + mh))
    for m, ln in zip(masks, lines):
        _composite(img, x0, y0, m, _bgr(ln.rgb))
    return x0 + pad, y0 + pad, x0 + mw - pad, y0 + mh - pad


def _composite(img: np.ndarray, x0: int, y0: int, mask: np.ndarray, bgr: tuple[int, int, int]) -> None:
    """Blend a BGR colour into img through an 8-bit coverage mask placed at (x0, y0), clipped."""
    H, W = img.shape[:2]
    mh, mw = mask.shape
    ax0, ay0, ax1, ay1 = max(x0, 0), max(y0, 0), min(x0 + mw, W), min(y0 + mh, H)
    if ax0 >= ax1 or ay0 >= ay1:
        return
    a = mask[ay0 - y0:ay1 - y0, ax0 - x0:ax1 - x0, None].astype(np.float32) / 255.0
    region = img[ay0:ay1, ax0:ax1]
    region[:] = (region * (1 - a) + np.array(bgr, np.float32) * a + 0.5).astype(np.uint8)


def _abbreviation(object_id: str) -> str:
    """A short form of an object id: 'KitchenFurniture_4' -> 'KF4', 'Door_3' -> 'D3',
    'Chair_12' -> 'Cha12'."""
    kind, _, number = object_id.rpartition("_")
    caps = "".join(c for c in kind if c.isupper())
    short = caps if len(caps) >= 2 else ("D" if kind == "Door" else kind[:3])
    return short + number


# --------------------------------------------------------------------------- drawing primitives

def _fix(points: np.ndarray) -> np.ndarray:
    """Pixel coordinates -> OpenCV fixed-point int32 (N, 1, 2)."""
    return np.round(np.asarray(points, float) * (1 << SHIFT)).astype(np.int32).reshape(-1, 1, 2)


def _fixp(point: XY) -> tuple[int, int]:
    return (_fixr(point[0]), _fixr(point[1]))


def _fixr(length: float) -> int:
    """A pixel length (radius, coordinate) in OpenCV fixed point."""
    return int(round(length * (1 << SHIFT)))


def _rect(a: np.ndarray, b: np.ndarray, thickness: float) -> np.ndarray:
    """The 4 corners of a segment a->b widened to ``thickness`` (same units as a, b)."""
    d = b - a
    n = np.array([-d[1], d[0]]) / max(float(np.hypot(*d)), 1e-9) * thickness / 2
    return np.array([a + n, b + n, b - n, a - n])


def _dashed(img: np.ndarray, pts: np.ndarray, rgb: RGB, closed: bool, dash: float = 6,
            gap: float = 4, thick: int = 1) -> None:
    """A dashed polyline through pixel points."""
    seq = list(pts) + ([pts[0]] if closed else [])
    for p, q in zip(seq, seq[1:]):
        length = float(np.hypot(*(q - p)))
        t = 0.0
        while t < length:
            t1 = min(t + dash, length)
            a, b = p + (q - p) * t / length, p + (q - p) * t1 / length
            cv2.line(img, _fixp(a), _fixp(b), _bgr(rgb), thick, AA, SHIFT)
            t = t1 + gap


def _arrow(img: np.ndarray, tail: XY, head: XY, rgb: RGB, thick: int,
           tip: float = 0.35) -> None:
    cv2.arrowedLine(img, _fixp(tail), _fixp(head), _bgr(rgb), thick, AA, SHIFT, tip)


# --------------------------------------------------------------------------- the plan

@dataclass
class Plan:
    """A drawn plan: the BGR image, its frame and each room label's pixel centre (u, v)."""
    image: np.ndarray
    frame: PlanFrame
    room_labels: dict[str, tuple[int, int]]


def draw_plan(house: House, door_open: Mapping[str, bool] | None = None,
              models: Mapping[str, int] | None = None, free_space: Grid | None = None,
              path: Sequence[tuple[float, float]] | None = None,
              poses: Sequence[tuple[float, float, float]] | None = None, px_per_m: float = 80,
              title: str | None = None) -> np.ndarray:
    """The plan picture of ``house`` (BGR uint8); see :func:`render_plan` for the arguments."""
    return render_plan(house, door_open, models, free_space, path, poses, px_per_m, title).image


def render_plan(house: House, door_open: Mapping[str, bool] | None = None,
                models: Mapping[str, int] | None = None, free_space: Grid | None = None,
                path: Sequence[tuple[float, float]] | None = None,
                poses: Sequence[tuple[float, float, float]] | None = None, px_per_m: float = 80,
                title: str | None = None) -> Plan:
    """Draw the plan of ``house``.

    door_open: door id -> open (missing doors use their ``default_open``); models: object id ->
    model variant (missing: the default box); free_space: FREE cells are tinted green; path: world
    (x, y) points; poses: world (x, y, yaw) arrows; px_per_m: scale, lowered so the long side stays
    within :data:`MAX_SIDE`; title: defaults to 'House N — R rooms, O objects'.
    """
    doors = {d.id: bool((door_open or {}).get(d.id, d.default_open)) for d in house.doors}
    blocks = _legend_blocks(house, (free_space is not None, bool(path), bool(poses)))
    frame = plan_frame(house, px_per_m, [(b.w, b.h) for b in blocks])
    painter = _Painter(house, frame, models or {})
    painter.floors()
    if free_space is not None:
        painter.free_space(free_space)
    painter.objects()
    painter.walls()
    painter.windows()
    painter.doors(doors)
    painter.lights()
    painter.station()
    labels = painter.room_labels()
    painter.small_labels(doors)
    if path:
        painter.path(path)
    if poses:
        painter.poses(poses)
    painter.title(title, doors)
    for block, (x, y) in zip(blocks, _legend_origins(frame, blocks)):
        block.draw(painter.img, x, y, frame)
    return Plan(painter.img, frame, labels)


def write_plan(path: str | Path, image: np.ndarray) -> None:
    """Save a plan picture (format from the suffix, e.g. .png), creating parent folders."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_image(path, image)


@dataclass(frozen=True)
class _DoorGeometry:
    """A doorway: centre, unit width direction u, unit normal n into the swing room, the hinge end
    (+1 or -1 along u), and the gap's width and depth (metres, from the lintels over it)."""
    centre: np.ndarray
    u: np.ndarray
    n: np.ndarray
    hinge: int
    width: float
    depth: float


# Room label passes: (tolerated share of the label over furniture, (text scale, vertical) in order).
_ROOM_LABEL_FITS = ((1.0, False), (0.85, False), (1.0, True), (0.72, False), (0.85, True), (0.72, True))
_ROOM_LABEL_PASSES = ((0.0, _ROOM_LABEL_FITS), (0.12, _ROOM_LABEL_FITS), (0.35, _ROOM_LABEL_FITS),
                      (1.0, _ROOM_LABEL_FITS + ((0.6, False), (0.6, True), (0.5, False), (0.5, True))))
# How private a room type is (default 2): a door swings into the more private of its rooms.
_PRIVACY = {"Corridor": 0, "Hall": 0, "Balcony": 0, "LivingRoom": 1, "Kitchen": 1,
            "KitchenLivingRoom": 1, "Standard": 1}
# Light symbol radius per kind: (minimum px, metres).
_LIGHT_RADIUS = {"ceiling": (5.0, 0.09), "lamp": (3.5, 0.055), "wall": (4.5, 0.07)}
_SMALL_TEXT = 0.36                  # object, door and station label scale (times the size factor)


class _Painter:
    """Draws one house's layers onto an image and remembers what covers each pixel.

    Masks (uint8, image-sized): ``floor`` (rooms), where small labels must lie; ``wall_mask``,
    ``symbols`` (doors, lights, the station), ``furniture`` (object footprints) and ``taken``
    (labels), which labels keep clear of. ``owner`` holds, per pixel, the index of the topmost
    filled object box drawn there (-1: none).
    """

    def __init__(self, house: House, frame: PlanFrame, models: Mapping[str, int]) -> None:
        self.house, self.f, self.models = house, frame, models
        self.img = np.full((frame.height, frame.width, 3), 255, np.uint8)
        shape = (frame.height, frame.width)
        self.floor, self.wall_mask, self.symbols, self.furniture, self.taken = (
            np.zeros(shape, np.uint8) for _ in range(5))
        self.owner = np.full(shape, -1, np.int32)
        self.k = float(np.clip(frame.scale / 80, 0.75, 1.4))   # text size factor
        self.boxed = [o for o in house.objects if o.type not in SYMBOL_TYPES]
        self.door_geo = {d.id: self._door_geometry(d) for d in house.doors}

    def px(self, x: float, y: float) -> np.ndarray:
        return np.array(self.f.to_px(x, y))

    def poly(self, pts: np.ndarray, rgb: RGB, edge: RGB | None = None,
             mask: np.ndarray | None = None) -> None:
        """Fill a pixel polygon (with a 1 px edge), also marking it in ``mask``."""
        cv2.fillPoly(self.img, [_fix(pts)], _bgr(rgb), AA, SHIFT)
        if edge is not None:
            cv2.polylines(self.img, [_fix(pts)], True, _bgr(edge), 1, AA, SHIFT)
        if mask is not None:
            cv2.fillPoly(mask, [_fix(pts)], 255, cv2.LINE_8, SHIFT)

    # ----------------------------------------------------------------- layers

    def floors(self) -> None:
        for room in self.house.rooms:
            for poly in (room.floor, *room.extra_floors):
                self.poly(self.f.to_px_array(poly), room_color(room.type), mask=self.floor)

    def free_space(self, grid: Grid) -> None:
        s, res = self.f.scale, grid.resolution
        ox, oy = grid.origin
        m = np.array([[res * s, 0, self.f.left + (ox + res / 2 - self.f.xmin) * s],
                      [0, -res * s, self.f.top + (self.f.ymax - oy - res / 2) * s]], np.float64)
        free = (grid.data == FREE).astype(np.uint8) * int(round(255 * FREE_ALPHA))
        _composite(self.img, 0, 0, cv2.warpAffine(free, m, (self.f.width, self.f.height),
                                                  flags=cv2.INTER_NEAREST), _bgr(FREE_RGB))

    def objects(self) -> None:
        """Object boxes, lowest top first so what lies on top stays visible."""
        for i in sorted(range(len(self.boxed)), key=lambda i: (self._top(self.boxed[i]), i)):
            obj = self.boxed[i]
            outline, fill = GROUP_COLORS[object_group(obj.type)]
            pts = self._footprint(obj)
            cv2.fillPoly(self.furniture, [_fix(pts)], 255, cv2.LINE_8, SHIFT)
            if self._overhead(obj):
                _dashed(self.img, pts, outline, closed=True, dash=5, gap=3)
                cv2.polylines(self.owner, [_fix(pts)], True, i, 2, cv2.LINE_8, SHIFT)
            else:
                self.poly(pts, fill, outline)
                cv2.fillPoly(self.owner, [_fix(pts)], i, cv2.LINE_8, SHIFT)

    def walls(self) -> None:
        cover = np.zeros(self.wall_mask.shape, np.uint8)
        for w in self.house.walls:
            if w.kind == "wall" and w.length > 1e-6:
                pts = _rect(self.px(*w.a), self.px(*w.b), w.thickness * self.f.scale)
                cv2.fillPoly(cover, [_fix(pts)], 255, AA, SHIFT)
        _composite(self.img, 0, 0, cover, _bgr(WALL_RGB))
        self.wall_mask |= (cover > 0).astype(np.uint8) * 255
        for w in self.house.walls:
            a, b = self.px(*w.a), self.px(*w.b)
            if w.kind == "column":
                pts = _rect(a, b, max(w.thickness * self.f.scale, 2))
                self.poly(pts, COLUMN_RGB, WALL_RGB, self.wall_mask)
            elif w.kind == "lintel":
                _dashed(self.img, np.array([a, b]), LINTEL_RGB, closed=False, dash=5, gap=4)

    def windows(self) -> None:
        for win in self.house.windows:
            centre, thickness = self._window_seat(win)
            u = np.array([math.cos(win.yaw), math.sin(win.yaw)])
            pa, pb = self.px(*(centre - u * win.width / 2)), self.px(*(centre + u * win.width / 2))
            t = thickness * self.f.scale
            self.poly(_rect(pa, pb, t), WINDOW_FILL_RGB, WALL_RGB)
            for side in (-0.2, 0.2):
                off = _rect(pa, pb, 2 * side * t)[0] - pa
                cv2.line(self.img, _fixp(pa + off), _fixp(pb + off), _bgr(WINDOW_RGB), 1, AA, SHIFT)

    def doors(self, state: Mapping[str, bool]) -> None:
        for door in self.house.doors:
            (self._open_door if state[door.id] else self._closed_door)(self.door_geo[door.id])

    def lights(self) -> None:
        for light in self.house.lights:
            c = self.px(light.position[0], light.position[1])
            least, metres = _LIGHT_RADIUS[light.kind]
            r = max(least, metres * self.f.scale)
            _light_symbol(self.img, c, r, light.kind)
            cv2.circle(self.symbols, _fixp(c), _fixr(r + 2), 255, -1, cv2.LINE_8, SHIFT)

    def station(self) -> None:
        st = self.house.station
        c = self.px(st.position[0], st.position[1])
        r = self._station_radius()
        _station_symbol(self.img, c, r, st.yaw)
        cv2.circle(self.symbols, _fixp(c), _fixr(r * 2.3), 255, -1, cv2.LINE_8, SHIFT)

    def path(self, points: Sequence[tuple[float, float]]) -> None:
        pts = self.f.to_px_array(points)
        t = max(3, int(round(0.05 * self.f.scale)))
        cv2.polylines(self.img, [_fix(pts)], False, (255, 255, 255), t + 4, AA, SHIFT)
        cv2.polylines(self.img, [_fix(pts)], False, _bgr(PATH_RGB), t, AA, SHIFT)
        r = _fixr(max(6.0, 0.12 * self.f.scale))
        for p, rgb in ((pts[0], START_RGB), (pts[-1], GOAL_RGB)):
            cv2.circle(self.img, _fixp(p), r, _bgr(rgb), -1, AA, SHIFT)
            cv2.circle(self.img, _fixp(p), r, (255, 255, 255), 2, AA, SHIFT)

    def poses(self, poses: Sequence[tuple[float, float, float]]) -> None:
        length = max(14.0, 0.3 * self.f.scale)
        for x, y, yaw in poses:
            c = self.px(x, y)
            _arrow(self.img, c, c + length * np.array([math.cos(yaw), -math.sin(yaw)]), POSE_RGB, 2)
            cv2.circle(self.img, _fixp(c), _fixr(3), _bgr(POSE_RGB), -1, AA, SHIFT)

    def title(self, title: str | None, doors: Mapping[str, bool]) -> None:
        h = self.house
        text = title or f"House {h.number} — {len(h.rooms)} rooms, {len(h.objects)} objects"
        _put_text(self.img, text, (MARGIN, 46), DUPLEX, 1.0, _bgr(TEXT_RGB), 1)
        n_open = sum(doors.values())
        sub = (f"Robot@VirtualHome house {h.number:02d}   |   {self.f.scale:.0f} px/m   |   "
               f"doors: {n_open} open, {len(doors) - n_open} closed   |   {len(h.lights)} lights")
        _put_text(self.img, sub, (MARGIN, 72), SIMPLEX, 0.48, _bgr(SUBTEXT_RGB), 1)

    # ----------------------------------------------------------------- labels

    def room_labels(self) -> dict[str, tuple[int, int]]:
        centres = {}
        grow = np.ones((5, 5), np.uint8)
        hard, soft = cv2.dilate(self.wall_mask | self.symbols, grow), cv2.dilate(self.furniture, grow)
        for room in self.house.rooms:
            centre, vertical, lines = self._fit_room_label(room, hard, soft)
            self._take(_stamp_lines(self.img, lines, centre, vertical))
            centres[room.id] = centre
        return centres

    def small_labels(self, doors: Mapping[str, bool]) -> None:
        st = self.house.station
        r = self._station_radius() * 2.3
        self._place(self._around("Station", self.px(st.position[0], st.position[1]), np.array([r, r])),
                    STATION_RGB)
        for door in self.house.doors:
            self._door_label(door, doors[door.id])
        def area(i: int) -> float:
            return math.prod(self._box(self.boxed[i]).size[:2])

        for i in sorted(range(len(self.boxed)), key=lambda i: (-area(i), self.boxed[i].id)):
            self._object_label(i)

    # ----------------------------------------------------------------- object helpers

    def _box(self, obj: HouseObject) -> ModelBox:
        return obj.box(self.models.get(obj.id))

    def _footprint(self, obj: HouseObject) -> np.ndarray:
        box = self._box(obj)
        return self.f.to_px_array(box_corners(box.position[:2], box.size[:2], obj.yaw))

    def _top(self, obj: HouseObject) -> float:
        box = self._box(obj)
        return box.position[2] + box.size[2] / 2

    def _overhead(self, obj: HouseObject) -> bool:
        box = self._box(obj)
        return box.position[2] - box.size[2] / 2 - self.house.room(obj.room).floor_z > OVERHEAD_Z

    def _station_radius(self) -> float:
        return max(7.0, 0.2 * self.f.scale)

    def _window_seat(self, win: Window) -> tuple[np.ndarray, float]:
        """The window's centre projected onto the wall it sits in, and that wall's thickness."""
        c = np.array(win.position[:2])
        best: tuple[float, np.ndarray, float] | None = None
        for w in self.house.walls:
            a, d = np.array(w.a), np.subtract(w.b, w.a)
            parallel = abs(math.sin(math.atan2(d[1], d[0]) - win.yaw)) < 0.1
            if w.kind != "wall" or w.length < 1e-6 or not parallel:
                continue
            p = a + float(np.clip(np.dot(c - a, d) / w.length**2, 0, 1)) * d
            dist = float(np.hypot(*(c - p)))
            if dist < 0.3 and (best is None or dist < best[0]):
                best = (dist, p, w.thickness)
        return (best[1], best[2]) if best else (c, win.thickness)

    # ----------------------------------------------------------------- doors

    def _door_geometry(self, door: Door) -> _DoorGeometry:
        """The doorway under the door's lintels; the leaf swings into the more private room
        (:data:`_PRIVACY`), hinged at the end that has a wall beside it."""
        c, u, width, depth = self._door_gap(door)
        n = np.array([-u[1], u[0]])
        rooms = [self.house.room(r) for r in door.rooms]
        swing = min(rooms, key=lambda r: (-_PRIVACY.get(r.type, 2), r.id != door.rooms[0]))
        reach = depth / 2 + 0.3
        if not swing.contains(*(c + reach * n)) and swing.contains(*(c - reach * n)):
            n = -n
        beside = [c + e * (width / 2 + 0.3) * u + reach * n for e in (1, -1)]
        hinge = next((e for e, p in zip((1, -1), beside) if not swing.contains(*p)), 1)
        return _DoorGeometry(c, u, n, hinge, width, depth)

    def _door_gap(self, door: Door) -> tuple[np.ndarray, np.ndarray, float, float]:
        """Centre, width direction, width and depth of the gap spanned by the door's lintels."""
        c = np.array(door.position[:2])
        u = np.array([math.cos(door.yaw), math.sin(door.yaw)])
        n = np.array([-u[1], u[0]])
        along, across = [], []
        for w in self.house.walls:
            a, b = np.array(w.a) - c, np.array(w.b) - c
            mid = (a + b) / 2
            if (w.kind != "lintel" or abs(float(np.dot(b - a, n))) > 0.1 * w.length
                    or abs(float(np.dot(mid, u))) > door.width / 2 or abs(float(np.dot(mid, n))) > 0.3):
                continue
            along += [float(np.dot(a, u)), float(np.dot(b, u))]
            across += [float(np.dot(mid, n)) - w.thickness / 2, float(np.dot(mid, n)) + w.thickness / 2]
        if not along:
            return c, u, door.leaf[0], door.leaf[1]
        centre = c + u * (min(along) + max(along)) / 2 + n * (min(across) + max(across)) / 2
        return centre, u, max(along) - min(along), max(across) - min(across)

    def _open_door(self, g: _DoorGeometry) -> None:
        hinge = g.centre + g.hinge * g.width / 2 * g.u + g.depth / 2 * g.n
        angles = np.linspace(0, math.pi / 2, 24)
        arc = self.f.to_px_array([hinge + g.width * (-g.hinge * math.cos(a) * g.u + math.sin(a) * g.n)
                                  for a in angles])
        cv2.polylines(self.img, [_fix(arc)], False, _bgr(DOOR_OPEN_RGB), 1, AA, SHIFT)
        leaf = _rect(self.px(*hinge), self.px(*(hinge + g.width * g.n)), max(3.0, 0.04 * self.f.scale))
        self.poly(leaf, DOOR_OPEN_RGB)
        sweep = np.vstack([self.px(*hinge)[None], arc])
        cv2.fillPoly(self.symbols, [_fix(sweep)], 255, cv2.LINE_8, SHIFT)

    def _closed_door(self, g: _DoorGeometry) -> None:
        a, b = self.px(*(g.centre - g.u * g.width / 2)), self.px(*(g.centre + g.u * g.width / 2))
        self.poly(_rect(a, b, max(6.0, g.depth * self.f.scale)), DOOR_CLOSED_RGB, DOOR_CLOSED_EDGE_RGB,
                  self.symbols)

    # ----------------------------------------------------------------- room labels

    def _fit_room_label(self, room: Room, hard: np.ndarray, soft: np.ndarray
                        ) -> tuple[tuple[int, int], bool, list[_Line]]:
        """Centre, orientation and lines of the room's label: the largest text that fits clear of
        furniture (then over as little furniture as possible), at the most open such spot."""
        inside, (x0, y0, x1, y1) = self._room_mask(room)
        region, furniture = inside & ~hard[y0:y1, x0:x1], soft[y0:y1, x0:x1]
        dist = cv2.distanceTransform(region & ~furniture, cv2.DIST_L2, 5)
        share = (furniture > 0).astype(np.float32)
        for tolerated, fits_to_try in _ROOM_LABEL_PASSES:
            for scale, vertical in fits_to_try:
                lines = self._room_lines(room, scale)
                w, h = _block_size(lines)
                kernel = (h + 7 | 1, w + 7 | 1) if vertical else (w + 7 | 1, h + 7 | 1)
                fits = cv2.erode(region, np.ones(kernel[::-1], np.uint8)) > 0
                over = cv2.boxFilter(share, -1, kernel, borderType=cv2.BORDER_CONSTANT)
                ok = fits & (over <= tolerated + 1e-6)
                if ok.any():
                    score = np.where(ok, dist - 1000 * over, -np.inf)
                    v, u = np.unravel_index(np.argmax(score), ok.shape)
                    return (int(u) + x0, int(v) + y0), vertical, lines
        v, u = np.unravel_index(np.argmax(cv2.distanceTransform(inside, cv2.DIST_L2, 5)), inside.shape)
        return (int(u) + x0, int(v) + y0), False, self._room_lines(room, 0.5)

    def _room_mask(self, room: Room) -> tuple[np.ndarray, tuple[int, int, int, int]]:
        """The room's floor as a mask over its pixel bounding box (x0, y0, x1, y1)."""
        polys = [self.f.to_px_array(poly) for poly in (room.floor, *room.extra_floors)]
        pts = np.vstack(polys)
        x0, y0 = (max(int(math.floor(v)) - 2, 0) for v in pts.min(axis=0))
        x1, y1 = int(math.ceil(pts[:, 0].max())) + 2, int(math.ceil(pts[:, 1].max())) + 2
        x1, y1 = min(x1, self.f.width), min(y1, self.f.height)
        inside = np.zeros((y1 - y0, x1 - x0), np.uint8)
        for p in polys:
            cv2.fillPoly(inside, [_fix(p - (x0, y0))], 255, cv2.LINE_8, SHIFT)
        return inside, (x0, y0, x1, y1)

    def _room_lines(self, room: Room, scale: float) -> list[_Line]:
        k = self.k * scale
        detail = f"{room.area:.1f} m²"
        if not room.id.startswith(room.type):
            detail = f"{room.type}, {detail}"
        return [_Line(room.id, DUPLEX, 0.6 * k, TEXT_RGB), _Line(detail, SIMPLEX, 0.46 * k, SUBTEXT_RGB)]

    # ----------------------------------------------------------------- small labels

    def _take(self, rect: tuple[int, int, int, int], pad: int = 2) -> None:
        x0, y0, x1, y1 = rect
        self.taken[max(y0 - pad, 0):y1 + pad, max(x0 - pad, 0):x1 + pad] = 255

    def _rect_of(self, text: str, centre: XY) -> tuple[int, int, int, int]:
        w, h = _text_size(text, SIMPLEX, _SMALL_TEXT * self.k)
        x0, y0 = int(round(centre[0] - w / 2)), int(round(centre[1] - h / 2))
        return x0, y0, x0 + w, y0 + h + 2

    def _clear(self, rect: tuple[int, int, int, int], masks: Sequence[np.ndarray]) -> bool:
        """Whether a label rectangle lies on the floor and clear of every mask."""
        x0, y0, x1, y1 = rect
        if x0 < 1 or y0 < 1 or not self.floor[y0:y1, x0:x1].all():
            return False
        return not any(m[y0 - 1:y1 + 1, x0 - 1:x1 + 1].any() for m in masks)

    def _place(self, candidates: Sequence[tuple[str, XY, int | None]], rgb: RGB) -> None:
        """Draw the first free candidate (text, centre, owner), if any; owner None: the spot must be
        clear of all furniture, else it must lie on that object's own visible box."""
        for text, centre, owner in candidates:
            rect = self._rect_of(text, centre)
            if owner is None:
                ok = self._clear(rect, (self.taken, self.wall_mask, self.symbols, self.furniture))
            else:
                x0, y0, x1, y1 = rect
                ok = (self._clear(rect, (self.taken, self.wall_mask, self.symbols))
                      and bool((self.owner[y0 - 1:y1 + 1, x0 - 1:x1 + 1] == owner).all()))
            if ok:
                self._take(_halo_text(self.img, text, centre, SIMPLEX, _SMALL_TEXT * self.k, rgb))
                return

    def _around(self, text: str, centre: np.ndarray, half: np.ndarray, gap: float = 3
                ) -> list[tuple[str, XY, int | None]]:
        """Candidates just below, above, right and left of a box of half extents ``half`` (px)."""
        w, h = _text_size(text, SIMPLEX, _SMALL_TEXT * self.k)
        dy, dx = half[1] + gap + h / 2 + 1, half[0] + gap + w / 2
        return [(text, centre + (ox, oy), None) for ox, oy in ((0, dy), (0, -dy), (dx, 0), (-dx, 0))]

    def _door_label(self, door: Door, is_open: bool) -> None:
        g = self.door_geo[door.id]
        centre, n_px = self.px(*g.centre), np.array([g.n[0], -g.n[1]])
        rgb = _shade(DOOR_OPEN_RGB if is_open else DOOR_CLOSED_RGB, 0.75)
        candidates = []
        for text in (door.id, _abbreviation(door.id)):
            w, h = _text_size(text, SIMPLEX, _SMALL_TEXT * self.k)
            reach = g.depth / 2 * self.f.scale + 4 + abs(n_px[0]) * w / 2 + abs(n_px[1]) * h / 2
            candidates += [(text, centre - side * reach * n_px, None) for side in (1, -1)]
        self._place(candidates, rgb)

    def _object_label(self, i: int) -> None:
        obj = self.boxed[i]
        pts = self._footprint(obj)
        centre, half = pts.mean(axis=0), (pts.max(axis=0) - pts.min(axis=0)) / 2
        texts = (obj.id, _abbreviation(obj.id))
        on_box = [(t, centre, i) for t in texts]
        around = [c for t in texts for c in self._around(t, centre, half)]
        self._place(on_box + around, _shade(GROUP_COLORS[object_group(obj.type)][0], 0.8))


def _shade(rgb: RGB, factor: float) -> RGB:
    return (int(rgb[0] * factor), int(rgb[1] * factor), int(rgb[2] * factor))


def _light_symbol(img: np.ndarray, c: np.ndarray, r: float, kind: str) -> None:
    """Ceiling light: circle with a cross; lamp: dot; wall light: diamond (yellow, dark edge)."""
    edge, fill = _bgr(LIGHT_EDGE_RGB), _bgr(LIGHT_RGB)
    if kind == "wall":
        pts = _fix(c + np.array([[0, -r], [r, 0], [0, r], [-r, 0]]))
        cv2.fillPoly(img, [pts], fill, AA, SHIFT)
        cv2.polylines(img, [pts], True, edge, 1, AA, SHIFT)
        return
    cv2.circle(img, _fixp(c), _fixr(r), fill, -1, AA, SHIFT)
    cv2.circle(img, _fixp(c), _fixr(r), edge, 1, AA, SHIFT)
    if kind == "ceiling":
        d = r * 0.7
        for s in (-1, 1):
            cv2.line(img, _fixp(c + (-d, -d * s)), _fixp(c + (d, d * s)), edge, 1, AA, SHIFT)


def _station_symbol(img: np.ndarray, c: np.ndarray, r: float, yaw: float) -> None:
    """A ringed disc with an arrow along the robot's start heading (yaw in the world frame)."""
    cv2.circle(img, _fixp(c), _fixr(r), _bgr(STATION_FILL_RGB), -1, AA, SHIFT)
    cv2.circle(img, _fixp(c), _fixr(r), _bgr(STATION_RGB), 2, AA, SHIFT)
    _arrow(img, c, c + 2.2 * r * np.array([math.cos(yaw), -math.sin(yaw)]), STATION_RGB, 2, 0.3)


# --------------------------------------------------------------------------- legend

ROW_H, ICON_W = 22, 34           # legend row height and icon width, px
_SCALE_SIZE = (190, 120)         # the scale-and-axes legend block, px
_Row = tuple[str, Callable[[np.ndarray, int, int], None]]    # text, icon drawer(img, x, y_mid)


def _legend_rows(house: House, overlays: tuple[bool, bool, bool]) -> list[tuple[str, list[_Row]]]:
    """Legend sections: (title, [(text, icon drawer(img, x, y_mid))])."""
    counts: dict[str, int] = {}
    for r in house.rooms:
        counts[r.type] = counts.get(r.type, 0) + 1
    rooms = [(f"{t} ({n})" if n > 1 else t, _swatch(room_color(t), (150, 150, 150)))
             for t, n in sorted(counts.items())]
    groups = sorted({object_group(o.type) for o in house.objects if o.type not in SYMBOL_TYPES},
                    key=list(GROUP_COLORS).index)
    objects = [(g, _swatch(GROUP_COLORS[g][1], GROUP_COLORS[g][0])) for g in groups]
    objects.append((f"overhead (> {OVERHEAD_Z:g} m)", _icon_overhead))
    walls: list[_Row] = [("wall", _icon_wall), ("lintel over doorway", _icon_lintel), ("window", _icon_window),
             ("door, open", _icon_open_door), ("door, closed", _icon_closed_door)]
    if any(w.kind == "column" for w in house.walls):
        walls.insert(1, ("column", _swatch(COLUMN_RGB, WALL_RGB)))
    kinds = {lt.kind for lt in house.lights}
    symbols: list[_Row] = [(name, icon) for kind, name, icon in (
        ("ceiling", "ceiling light", _icon_ceiling), ("lamp", "lamp", _icon_lamp),
        ("wall", "wall light", _icon_wall_light)) if kind in kinds]
    symbols.append(("robot station", _icon_station))
    extra = [row for on, row in zip(overlays, (("free space", _swatch(FREE_RGB, FREE_RGB, FREE_ALPHA)),
                                               ("path (start, goal)", _icon_path),
                                               ("pose", _icon_pose))) if on]
    sections = [("ROOMS", rooms), ("OBJECTS", objects), ("WALLS & DOORS", walls), ("SYMBOLS", symbols)]
    return sections + ([("OVERLAYS", extra)] if extra else [])


def _section_size(title: str, rows: Sequence[tuple[str, Callable]]) -> tuple[int, int]:
    w = max([_text_size(title, DUPLEX, 0.5)[0]] + [ICON_W + 8 + _text_size(t, SIMPLEX, 0.46)[0]
                                                   for t, _ in rows])
    return w, 26 + ROW_H * len(rows)


def _legend_blocks(house: House, overlays: tuple[bool, bool, bool]) -> list[_Block]:
    blocks = [_Block(*_section_size(title, rows), _section_drawer(title, rows))
              for title, rows in _legend_rows(house, overlays)]
    return blocks + [_Block(*_SCALE_SIZE, _draw_scale)]


def _section_drawer(title: str, rows: Sequence[tuple[str, Callable]]
                    ) -> Callable[[np.ndarray, int, int, PlanFrame], None]:
    def draw(img: np.ndarray, x: int, y: int, frame: PlanFrame) -> None:
        _put_text(img, title, (x, y + 14), DUPLEX, 0.5, _bgr(TEXT_RGB))
        for i, (text, icon) in enumerate(rows):
            mid = y + 26 + ROW_H * i + ROW_H // 2
            icon(img, x, mid)
            _put_text(img, text, (x + ICON_W + 8, mid + 5), SIMPLEX, 0.46, _bgr(TEXT_RGB))
    return draw


def _swatch(fill: RGB, edge: RGB, alpha: float = 1.0) -> Callable[[np.ndarray, int, int], None]:
    def icon(img: np.ndarray, x: int, y: int) -> None:
        region = img[y - 7:y + 8, x + 2:x + ICON_W - 2]
        region[:] = (region * (1 - alpha) + np.array(_bgr(fill)) * alpha).astype(np.uint8)
        cv2.rectangle(img, (x + 2, y - 7), (x + ICON_W - 3, y + 7), _bgr(edge), 1, AA)
    return icon


def _icon_overhead(img: np.ndarray, x: int, y: int) -> None:
    x1 = x + ICON_W - 3
    pts = np.array([[x + 2, y - 7], [x1, y - 7], [x1, y + 7], [x + 2, y + 7]], float)
    _dashed(img, pts, GROUP_COLORS["furniture"][0], closed=True, dash=5, gap=3)


def _icon_wall(img: np.ndarray, x: int, y: int) -> None:
    cv2.rectangle(img, (x + 2, y - 4), (x + ICON_W - 3, y + 4), _bgr(WALL_RGB), -1)


def _icon_lintel(img: np.ndarray, x: int, y: int) -> None:
    _dashed(img, np.array([[x + 2, y], [x + ICON_W - 3, y]], float), LINTEL_RGB, False, 5, 4)


def _icon_window(img: np.ndarray, x: int, y: int) -> None:
    cv2.rectangle(img, (x + 2, y - 4), (x + ICON_W - 3, y + 4), _bgr(WALL_RGB), 1)
    for dy in (-2, 2):
        cv2.line(img, (x + 3, y + dy), (x + ICON_W - 4, y + dy), _bgr(WINDOW_RGB), 1, AA)


def _icon_open_door(img: np.ndarray, x: int, y: int) -> None:
    hinge = (x + 8, y + 8)
    cv2.ellipse(img, hinge, (16, 16), 0, -90, 0, _bgr(DOOR_OPEN_RGB), 1, AA)
    cv2.line(img, hinge, (hinge[0], hinge[1] - 16), _bgr(DOOR_OPEN_RGB), 3, AA)
    cv2.line(img, (x + 2, y + 8), (x + ICON_W - 3, y + 8), _bgr(WALL_RGB), 1, AA)


def _icon_closed_door(img: np.ndarray, x: int, y: int) -> None:
    cv2.rectangle(img, (x + 6, y - 4), (x + ICON_W - 7, y + 4), _bgr(DOOR_CLOSED_RGB), -1)
    cv2.rectangle(img, (x + 6, y - 4), (x + ICON_W - 7, y + 4), (20, 20, 150), 1)


def _icon_ceiling(img: np.ndarray, x: int, y: int) -> None:
    c, r = (x + ICON_W // 2, y), 6
    cv2.circle(img, c, r, _bgr(LIGHT_RGB), -1, AA)
    cv2.circle(img, c, r, _bgr(LIGHT_EDGE_RGB), 1, AA)
    for s in (-1, 1):
        cv2.line(img, (c[0] - 4, c[1] - 4 * s), (c[0] + 4, c[1] + 4 * s), _bgr(LIGHT_EDGE_RGB), 1, AA)


def _icon_lamp(img: np.ndarray, x: int, y: int) -> None:
    cv2.circle(img, (x + ICON_W // 2, y), 4, _bgr(LIGHT_RGB), -1, AA)
    cv2.circle(img, (x + ICON_W // 2, y), 4, _bgr(LIGHT_EDGE_RGB), 1, AA)


def _icon_wall_light(img: np.ndarray, x: int, y: int) -> None:
    c = x + ICON_W // 2
    pts = np.array([[c, y - 5], [c + 5, y], [c, y + 5], [c - 5, y]], np.int32)
    cv2.fillPoly(img, [pts], _bgr(LIGHT_RGB), AA)
    cv2.polylines(img, [pts], True, _bgr(LIGHT_EDGE_RGB), 1, AA)


def _icon_station(img: np.ndarray, x: int, y: int) -> None:
    c = (x + 10, y)
    cv2.circle(img, c, 7, (245, 225, 245), -1, AA)
    cv2.circle(img, c, 7, _bgr(STATION_RGB), 2, AA)
    cv2.arrowedLine(img, c, (x + ICON_W - 2, y), _bgr(STATION_RGB), 2, AA, 0, 0.35)


def _icon_path(img: np.ndarray, x: int, y: int) -> None:
    cv2.line(img, (x + 4, y), (x + ICON_W - 5, y), _bgr(PATH_RGB), 3, AA)
    cv2.circle(img, (x + 4, y), 4, _bgr(START_RGB), -1, AA)
    cv2.circle(img, (x + ICON_W - 5, y), 4, _bgr(GOAL_RGB), -1, AA)


def _icon_pose(img: np.ndarray, x: int, y: int) -> None:
    cv2.circle(img, (x + 6, y), 3, _bgr(POSE_RGB), -1, AA)
    cv2.arrowedLine(img, (x + 6, y), (x + ICON_W - 4, y), _bgr(POSE_RGB), 2, AA, 0, 0.35)


def _draw_scale(img: np.ndarray, x: int, y: int, frame: PlanFrame) -> None:
    """A black/white scale bar of a round length and the +x / +y (north) axes."""
    scale = frame.scale
    metres = next(m for m in (1, 2, 5, 10) if m * scale >= 50)
    _put_text(img, "SCALE & AXES", (x, y + 14), DUPLEX, 0.5, _bgr(TEXT_RGB))
    y0, length = y + 34, metres * scale
    for i in range(2):
        x0 = x + 2 + i * length / 2
        pts = np.array([[x0, y0], [x0 + length / 2, y0], [x0 + length / 2, y0 + 7], [x0, y0 + 7]])
        cv2.fillPoly(img, [_fix(pts)], _bgr(TEXT_RGB) if i == 0 else (255, 255, 255), AA, SHIFT)
    cv2.rectangle(img, _fixp((x + 2, y0)), _fixp((x + 2 + length, y0 + 7)), _bgr(TEXT_RGB), 1, AA, SHIFT)
    _put_text(img, f"{metres} m", (int(x + length + 10), y0 + 8), SIMPLEX, 0.46, _bgr(TEXT_RGB))
    o = np.array([x + 14.0, y + 108.0])
    _arrow(img, o, o + (46, 0), (200, 40, 40), 2, 0.22)
    _arrow(img, o, o - (0, 46), (30, 150, 60), 2, 0.22)
    _put_text(img, "+x", (int(o[0] + 52), int(o[1] + 5)), SIMPLEX, 0.46, _bgr((200, 40, 40)))
    _put_text(img, "+y  N", (int(o[0] + 8), int(o[1] - 40)), SIMPLEX, 0.46, _bgr((30, 150, 60)))
