"""Top-down architectural plan of a house, drawn with matplotlib.

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
* the station (circle with an arrow along the robot's start heading);
* labels, then the optional path (thick polyline, green start, red goal) and poses (small arrows);
* the title, the legend, a scale bar and the +x/+y (north) axes.

Labels: a room is named at the most open spot of its floor clear of walls, symbols and furniture
(shapely's pole of inaccessibility of that area shrunk by the text's size), shrinking or turning
the text vertical in narrow rooms. Doors, the station and objects (largest first) get small labels
placed greedily at the first candidate spot that overlaps no earlier label, wall or other object;
an abbreviation (``KitchenFurniture_4`` -> ``KF4``) is tried before a label is dropped. Every label
has a halo of the colour it is written on.

Frame: world metres (x right, y up) map to pixels with y flipped; see :class:`PlanFrame`. The
plan's axes fill exactly the frame's plan area, so callers can draw on the picture in pixels.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely
import shapely.affinity
from matplotlib import patheffects
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.legend import Legend
from matplotlib.legend_handler import HandlerTuple
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, FancyArrowPatch, Patch, PathPatch
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.path import Path as MplPath
from matplotlib.transforms import IdentityTransform
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar
from shapely.ops import polylabel

from ravh_sim.files import write_image
from ravh_sim.nav.grid import FREE, Grid
from ravh_sim.viz.figure import DPI, figure_bgr, new_figure, rgb
from ravh_sim.world.geometry import box_corners, shape
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
PX = 72 / DPI        # points per pixel: matplotlib sizes lines and fonts in points


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
    """A legend block: its size (px) and how to draw it with its top-left corner at pixel (x, y)."""
    w: int
    h: int
    draw: Callable[[Figure, int, int, PlanFrame], None]


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
        block.draw(painter.figure, x, y, frame)
    return Plan(figure_bgr(painter.figure), frame, labels)


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


# Room label fits, in order: (text scale, vertical); tried clear of furniture, then over it.
_ROOM_LABEL_FITS = ((1.0, False), (0.85, False), (1.0, True), (0.72, False), (0.85, True), (0.72, True),
                    (0.6, False), (0.6, True))
# How private a room type is (default 2): a door swings into the more private of its rooms.
_PRIVACY = {"Corridor": 0, "Hall": 0, "Balcony": 0, "LivingRoom": 1, "Kitchen": 1,
            "KitchenLivingRoom": 1, "Standard": 1}
# Light symbol radius per kind: (minimum px, metres).
_LIGHT_RADIUS = {"ceiling": (5.0, 0.09), "lamp": (3.5, 0.055), "wall": (4.5, 0.07)}
_ROOM_TEXT_PT, _DETAIL_TEXT_PT = 11.0, 8.0   # room label lines (times the size factor)
_SMALL_TEXT_PT = 6.5                          # object, door and station labels (times the size factor)
_LINE_GAP = 1.3                               # line pitch of a room label, times the font size


class _Painter:
    """Draws one house's layers onto a figure whose axes are the plan area, in world metres.

    It also keeps, as shapely geometry, what labels must avoid: ``walls_shape`` and ``symbols`` (doors,
    lights, the station), ``footprints`` (object boxes, and of each filled box the part no later
    box covers, ``visible``) and ``taken`` (labels already placed); small labels lie on ``floor``.
    """

    def __init__(self, house: House, frame: PlanFrame, models: Mapping[str, int]) -> None:
        self.house, self.f, self.models = house, frame, models
        self.figure = new_figure(frame.width, frame.height)
        self.ax: Axes = self.figure.add_axes((frame.left / frame.width,
                                              1 - (frame.top + frame.plan_h) / frame.height,
                                              frame.plan_w / frame.width, frame.plan_h / frame.height))
        self.ax.set_axis_off()
        self._limits()
        self.renderer = self.figure.canvas.get_renderer()   # type: ignore[attr-defined]
        self.k = float(np.clip(frame.scale / 80, 0.75, 1.4))   # text size factor
        self.boxed = [o for o in house.objects if o.type not in SYMBOL_TYPES]
        self.door_geo = {d.id: self._door_geometry(d) for d in house.doors}
        self.floor = shapely.union_all([shape(p) for r in house.rooms for p in (r.floor, *r.extra_floors)])
        self.walls_shape = shapely.Polygon()
        self.symbols: list[shapely.Geometry] = []
        self.footprints: list[shapely.Polygon] = []
        self.visible: dict[int, shapely.Geometry] = {}
        self.taken: list[shapely.Polygon] = []

    def _limits(self) -> None:
        """The axes span exactly the frame's plan area, so world metres land on the frame's pixels."""
        self.ax.set_xlim(self.f.xmin, self.f.xmin + self.f.plan_w / self.f.scale)
        self.ax.set_ylim(self.f.ymax - self.f.plan_h / self.f.scale, self.f.ymax)

    def metres(self, px: float) -> float:
        return px / self.f.scale

    def patch(self, pts: np.ndarray, fill: RGB | None, edge: RGB | None = None, z: float = 1.0,
              width_px: float = 1.0, dashed: bool = False) -> None:
        """A world polygon, filled and/or outlined (``width_px`` wide)."""
        self.ax.add_patch(PolygonPatch(pts, closed=True, zorder=z, facecolor=rgb(fill) if fill else "none",
                                       edgecolor=rgb(edge) if edge else "none", linewidth=width_px * PX,
                                       linestyle=(0, (5 / width_px, 3 / width_px)) if dashed else "solid"))

    def line(self, pts: np.ndarray, colour: RGB, width_px: float, z: float, dashed: bool = False) -> None:
        pts = np.asarray(pts, float)
        self.ax.plot(pts[:, 0], pts[:, 1], color=rgb(colour), linewidth=width_px * PX, zorder=z,
                     solid_capstyle="butt", linestyle=(0, (5, 4)) if dashed else "solid")

    def arrow(self, tail: np.ndarray, head: np.ndarray, colour: RGB, width_px: float, z: float) -> None:
        self.ax.add_patch(FancyArrowPatch(tuple(tail), tuple(head), arrowstyle="-|>", color=rgb(colour),
                                          linewidth=width_px * PX, mutation_scale=8 + 3 * width_px,
                                          shrinkA=0, shrinkB=0, zorder=z))

    # ----------------------------------------------------------------- layers

    def floors(self) -> None:
        for room in self.house.rooms:
            for poly in (room.floor, *room.extra_floors):
                self.patch(np.array(poly), room_color(room.type), z=1)

    def free_space(self, grid: Grid) -> None:
        rows, cols = grid.shape
        ox, oy = grid.origin
        tint = np.zeros((rows, cols, 4))
        tint[grid.data == FREE] = (*rgb(FREE_RGB), FREE_ALPHA)
        self.ax.imshow(tint, origin="lower", interpolation="nearest", zorder=2, aspect="auto",
                       extent=(ox, ox + cols * grid.resolution, oy, oy + rows * grid.resolution))
        self._limits()                       # imshow widens the axes to the picture

    def objects(self) -> None:
        """Object boxes, lowest top first so what lies on top stays visible."""
        order = sorted(range(len(self.boxed)), key=lambda i: (self._top(self.boxed[i]), i))
        self.footprints = [shapely.Polygon(self._footprint(o)) for o in self.boxed]
        for rank, i in enumerate(order):
            obj = self.boxed[i]
            outline, fill = GROUP_COLORS[object_group(obj.type)]
            z = 3 + rank / (len(order) + 1)
            if self._overhead(obj):
                self.patch(self._footprint(obj), None, outline, z, dashed=True)
            else:
                self.patch(self._footprint(obj), fill, outline, z)
                above = [self.footprints[j] for j in order[rank + 1:]]
                self.visible[i] = self.footprints[i].difference(shapely.union_all(above))

    def walls(self) -> None:
        solid = [shapely.LineString([w.a, w.b]).buffer(w.thickness / 2, cap_style="flat")
                 for w in self.house.walls if w.kind == "wall" and w.length > 1e-6]
        self.walls_shape = shapely.union_all(solid)
        for part in shapely.get_parts(self.walls_shape):
            self._shape_patch(part, WALL_RGB, z=4)
        for w in self.house.walls:
            if w.kind == "column":
                pts = _rect(np.array(w.a), np.array(w.b), max(w.thickness, self.metres(2)))
                self.patch(pts, COLUMN_RGB, WALL_RGB, z=4.1)
                self.walls_shape = self.walls_shape.union(shapely.Polygon(pts))
            elif w.kind == "lintel":
                self.line(np.array([w.a, w.b]), LINTEL_RGB, 1, z=4.2, dashed=True)

    def windows(self) -> None:
        for win in self.house.windows:
            centre, thickness = self._window_seat(win)
            u = np.array([math.cos(win.yaw), math.sin(win.yaw)])
            a, b = centre - u * win.width / 2, centre + u * win.width / 2
            self.patch(_rect(a, b, thickness), WINDOW_FILL_RGB, WALL_RGB, z=5)
            for side in (-0.2, 0.2):
                off = _rect(a, b, 2 * side * thickness)[0] - a
                self.line(np.array([a + off, b + off]), WINDOW_RGB, 1, z=5.1)

    def doors(self, state: Mapping[str, bool]) -> None:
        for door in self.house.doors:
            (self._open_door if state[door.id] else self._closed_door)(self.door_geo[door.id])

    def lights(self) -> None:
        for light in self.house.lights:
            c = np.array(light.position[:2], float)
            least, metres = _LIGHT_RADIUS[light.kind]
            r = max(self.metres(least), metres)
            self._light_symbol(c, r, light.kind)
            self.symbols.append(shapely.Point(c).buffer(r + self.metres(2)))

    def station(self) -> None:
        st = self.house.station
        c, r = np.array(st.position[:2], float), self._station_radius()
        self.ax.add_patch(Circle(tuple(c), r, facecolor=rgb(STATION_FILL_RGB), edgecolor=rgb(STATION_RGB),
                                 linewidth=2 * PX, zorder=8))
        self.arrow(c, c + 2.2 * r * np.array([math.cos(st.yaw), math.sin(st.yaw)]), STATION_RGB, 2, 8.1)
        self.symbols.append(shapely.Point(c).buffer(r * 2.3))

    def path(self, points: Sequence[tuple[float, float]]) -> None:
        pts = np.asarray(points, float)
        t = max(3, int(round(0.05 * self.f.scale)))
        self.ax.plot(pts[:, 0], pts[:, 1], color=rgb(PATH_RGB), linewidth=t * PX, zorder=10,
                     solid_capstyle="round", solid_joinstyle="round",
                     path_effects=[patheffects.Stroke(linewidth=(t + 4) * PX, foreground="white"),
                                   patheffects.Normal()])
        r = max(6.0, 0.12 * self.f.scale)
        for p, colour in ((pts[0], START_RGB), (pts[-1], GOAL_RGB)):
            self.ax.add_patch(Circle(tuple(p), self.metres(r), facecolor=rgb(colour), edgecolor="white",
                                     linewidth=2 * PX, zorder=10.1))

    def poses(self, poses: Sequence[tuple[float, float, float]]) -> None:
        length = self.metres(max(14.0, 0.3 * self.f.scale))
        for x, y, yaw in poses:
            c = np.array([x, y])
            self.arrow(c, c + length * np.array([math.cos(yaw), math.sin(yaw)]), POSE_RGB, 2, 11)
            self.ax.add_patch(Circle((x, y), self.metres(3), color=rgb(POSE_RGB), zorder=11))

    def title(self, title: str | None, doors: Mapping[str, bool]) -> None:
        h = self.house
        name = f"House {h.number} ({h.name})" if h.name else f"House {h.number}"
        text = title or f"{name} — {len(h.rooms)} rooms, {len(h.objects)} objects"
        _figure_text(self.figure, MARGIN, 46, text, 19, TEXT_RGB, weight="bold")
        n_open = sum(doors.values())
        origin = (f"{h.source.get('file', '')}{' ' + h.source['level'] if h.source.get('level') else ''} by "
                  f"{h.source.get('author') or 'its author'}" if h.name else f"Robot@VirtualHome house {h.number:02d}")
        sub = (f"{origin}   |   {self.f.scale:.0f} px/m   |   "
               f"doors: {n_open} open, {len(doors) - n_open} closed   |   {len(h.lights)} lights")
        _figure_text(self.figure, MARGIN, 72, sub, 9, SUBTEXT_RGB)

    # ----------------------------------------------------------------- labels

    def room_labels(self) -> dict[str, tuple[int, int]]:
        """Each room's name and area at the most open spot its text fits; returns the pixel centres."""
        hard = shapely.union_all([self.walls_shape, *self.symbols]).buffer(self.metres(3))
        furniture = shapely.union_all(self.footprints).buffer(self.metres(3))
        centres = {}
        for room in self.house.rooms:
            (x, y), vertical, scale = self._fit_room_label(room, hard, furniture)
            lines = self._room_lines(room, scale)
            pitch = self.metres(_LINE_GAP * max(size for _, size, _, _ in lines) / PX)
            for k, (text, size, colour, weight) in enumerate(lines):
                offset = (0.5 - k) * pitch
                at = (x - offset, y) if vertical else (x, y + offset)
                self._text(at, text, size, colour, room_color(room.type), rotation=90 if vertical else 0,
                           weight=weight)
            w, h = self._block_size(lines)
            self.taken.append(_box((x, y), (h, w) if vertical else (w, h)))
            u, v = self.f.to_px(x, y)
            centres[room.id] = (int(round(u)), int(round(v)))
        return centres

    def small_labels(self, doors: Mapping[str, bool]) -> None:
        st = self.house.station
        r = self._station_radius() * 2.3
        self._place(self._around("Station", np.array(st.position[:2]), np.array([r, r])), STATION_RGB)
        for door in self.house.doors:
            self._door_label(door, doors[door.id])

        def area(i: int) -> float:
            return math.prod(self._box(self.boxed[i]).size[:2])

        for i in sorted(range(len(self.boxed)), key=lambda i: (-area(i), self.boxed[i].id)):
            self._object_label(i)

    def _text(self, at: XY, text: str, size: float, colour: RGB, halo: RGB,
              rotation: float = 0, weight: str = "normal") -> None:
        self.ax.text(at[0], at[1], text, fontsize=size, color=rgb(colour), ha="center", va="center",
                     rotation=rotation, weight=weight, zorder=9, rotation_mode="anchor",
                     path_effects=[patheffects.withStroke(linewidth=3 * PX, foreground=rgb(halo))])

    def _text_size(self, text: str, size: float, weight: str = "normal") -> tuple[float, float]:
        """(width, height) in metres of one line of text."""
        w, h, _ = self.renderer.get_text_width_height_descent(text, FontProperties(size=size, weight=weight),
                                                              ismath=False)
        return self.metres(w), self.metres(h)

    def _room_lines(self, room: Room, scale: float) -> list[tuple[str, float, RGB, str]]:
        """(text, size in points, colour, weight) of a room label's lines."""
        detail = f"{room.area:.1f} m²"
        if not room.id.startswith(room.type):
            detail = f"{room.type}, {detail}"
        k = self.k * scale
        return [(room.id, _ROOM_TEXT_PT * k, TEXT_RGB, "bold"), (detail, _DETAIL_TEXT_PT * k, SUBTEXT_RGB, "normal")]

    def _block_size(self, lines: Sequence[tuple[str, float, RGB, str]]) -> tuple[float, float]:
        sizes = [self._text_size(text, size, weight) for text, size, _, weight in lines]
        pitch = self.metres(_LINE_GAP * max(size for _, size, _, _ in lines) / PX)
        return max(w for w, _ in sizes), pitch * (len(lines) - 1) + max(h for _, h in sizes)

    def _fit_room_label(self, room: Room, hard: shapely.Geometry, furniture: shapely.Geometry
                        ) -> tuple[tuple[float, float], bool, float]:
        """Centre, orientation and scale of the room's label: the largest text that fits clear of
        furniture (else over it), at the most open such spot."""
        floor = shapely.union_all([shape(p) for p in (room.floor, *room.extra_floors)])
        free = floor.difference(hard)
        for region in (free.difference(furniture), free):
            for scale, vertical in _ROOM_LABEL_FITS:
                w, h = self._block_size(self._room_lines(room, scale))
                spot = _open_spot(region, *((h, w) if vertical else (w, h)), pad=self.metres(4))
                if spot is not None:
                    return spot, vertical, scale
        return _open_spot(floor, 0.0, 0.0, 0.0) or room.floor[0], False, 0.5

    def _place(self, candidates: Sequence[tuple[str, np.ndarray, int | None]], colour: RGB) -> None:
        """Draw the first free candidate (text, centre, owner), if any; owner None: the spot must be
        clear of all furniture, else it must lie on the visible part of that object's own box."""
        size = _SMALL_TEXT_PT * self.k
        for text, centre, owner in candidates:
            w, h = self._text_size(text, size)
            rect = _box(centre, (w + self.metres(2), h + self.metres(3)))
            blocked = [self.walls_shape, *self.symbols, *self.taken]
            if owner is None:
                blocked += self.footprints
            elif not rect.within(self.visible.get(owner, shapely.Polygon())):
                continue
            if rect.within(self.floor) and not shapely.intersects(rect, blocked).any():
                halo = (GROUP_COLORS[object_group(self.boxed[owner].type)][1] if owner is not None
                        else self._floor_colour(centre))
                self._text(centre, text, size, colour, halo)
                self.taken.append(rect)
                return

    def _floor_colour(self, at: np.ndarray) -> RGB:
        room = self.house.room_at(float(at[0]), float(at[1]))
        return room_color(room.type) if room is not None else (255, 255, 255)

    def _around(self, text: str, centre: np.ndarray, half: np.ndarray, gap_px: float = 3
                ) -> list[tuple[str, np.ndarray, int | None]]:
        """Candidates just below, above, right and left of a box of half extents ``half`` (m)."""
        w, h = self._text_size(text, _SMALL_TEXT_PT * self.k)
        gap = self.metres(gap_px)
        dy, dx = half[1] + gap + h / 2, half[0] + gap + w / 2
        return [(text, centre + (ox, oy), None) for ox, oy in ((0, -dy), (0, dy), (dx, 0), (-dx, 0))]

    def _door_label(self, door: Door, is_open: bool) -> None:
        g = self.door_geo[door.id]
        candidates = []
        for text in (door.id, _abbreviation(door.id)):
            w, h = self._text_size(text, _SMALL_TEXT_PT * self.k)
            reach = g.depth / 2 + self.metres(4) + abs(g.n[0]) * w / 2 + abs(g.n[1]) * h / 2
            candidates += [(text, g.centre - side * reach * g.n, None) for side in (1, -1)]
        self._place(candidates, _shade(DOOR_OPEN_RGB if is_open else DOOR_CLOSED_RGB, 0.75))

    def _object_label(self, i: int) -> None:
        pts = self._footprint(self.boxed[i])
        centre, half = pts.mean(axis=0), (pts.max(axis=0) - pts.min(axis=0)) / 2
        texts = (self.boxed[i].id, _abbreviation(self.boxed[i].id))
        on_box: list[tuple[str, np.ndarray, int | None]] = [(t, centre, i) for t in texts]
        around = [c for t in texts for c in self._around(t, centre, half)]
        self._place(on_box + around, _shade(GROUP_COLORS[object_group(self.boxed[i].type)][0], 0.8))

    # ----------------------------------------------------------------- symbols

    def _shape_patch(self, polygon: shapely.Polygon, colour: RGB, z: float) -> None:
        """A shapely polygon (holes included) as one filled patch."""
        rings = [np.asarray(polygon.exterior.coords)] + [np.asarray(r.coords) for r in polygon.interiors]
        codes = np.concatenate([[MplPath.MOVETO] + [MplPath.LINETO] * (len(r) - 2) + [MplPath.CLOSEPOLY]
                                for r in rings])
        self.ax.add_patch(PathPatch(MplPath(np.concatenate(rings), codes), facecolor=rgb(colour),
                                    edgecolor="none", zorder=z))

    def _light_symbol(self, c: np.ndarray, r: float, kind: str) -> None:
        """Ceiling light: circle with a cross; lamp: dot; wall light: diamond (yellow, dark edge)."""
        if kind == "wall":
            self.patch(c + np.array([[0, -r], [r, 0], [0, r], [-r, 0]]), LIGHT_RGB, LIGHT_EDGE_RGB, z=7)
            return
        self.ax.add_patch(Circle(tuple(c), r, facecolor=rgb(LIGHT_RGB), edgecolor=rgb(LIGHT_EDGE_RGB),
                                 linewidth=PX, zorder=7))
        if kind == "ceiling":
            d = r * 0.7
            for s in (-1, 1):
                self.line(np.array([c + (-d, -d * s), c + (d, d * s)]), LIGHT_EDGE_RGB, 1, z=7.1)

    # ----------------------------------------------------------------- object helpers

    def _box(self, obj: HouseObject) -> ModelBox:
        return obj.box(self.models.get(obj.id))

    def _footprint(self, obj: HouseObject) -> np.ndarray:
        box = self._box(obj)
        return box_corners(box.position[:2], box.size[:2], obj.yaw)

    def _top(self, obj: HouseObject) -> float:
        box = self._box(obj)
        return box.position[2] + box.size[2] / 2

    def _overhead(self, obj: HouseObject) -> bool:
        box = self._box(obj)
        return box.position[2] - box.size[2] / 2 - self.house.room(obj.room).floor_z > OVERHEAD_Z

    def _station_radius(self) -> float:
        return self.metres(max(7.0, 0.2 * self.f.scale))

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
        arc = np.array([hinge + g.width * (-g.hinge * math.cos(a) * g.u + math.sin(a) * g.n) for a in angles])
        self.line(arc, DOOR_OPEN_RGB, 1, z=6)
        self.patch(_rect(hinge, hinge + g.width * g.n, max(self.metres(3), 0.04)), DOOR_OPEN_RGB, z=6.1)
        self.symbols.append(shapely.Polygon(np.vstack([hinge[None], arc])))

    def _closed_door(self, g: _DoorGeometry) -> None:
        a, b = g.centre - g.u * g.width / 2, g.centre + g.u * g.width / 2
        bar = _rect(a, b, max(self.metres(6), g.depth))
        self.patch(bar, DOOR_CLOSED_RGB, DOOR_CLOSED_EDGE_RGB, z=6)
        self.symbols.append(shapely.Polygon(bar))


def _rect(a: np.ndarray, b: np.ndarray, thickness: float) -> np.ndarray:
    """The 4 corners of a segment a->b widened to ``thickness`` (same units as a, b)."""
    d = b - a
    n = np.array([-d[1], d[0]]) / max(float(np.hypot(*d)), 1e-9) * thickness / 2
    return np.array([a + n, b + n, b - n, a - n])


def _box(centre: XY, size: Sequence[float]) -> shapely.Polygon:
    """An axis-aligned rectangle of ``size`` (w, h) around ``centre``."""
    return shapely.box(centre[0] - size[0] / 2, centre[1] - size[1] / 2, centre[0] + size[0] / 2,
                       centre[1] + size[1] / 2)


def _open_spot(region: shapely.Geometry, w: float, h: float, pad: float) -> tuple[float, float] | None:
    """The centre of the most open spot of ``region`` where a w x h box (plus ``pad``) fits: the
    pole of inaccessibility of the region shrunk by the box (None if the box fits nowhere)."""
    w, h = w + pad, h + pad
    if w > 0 and h > 0:                  # shrink by a w x h box: squash to a square, shrink, unsquash
        square = shapely.affinity.scale(region, 1.0, w / h, origin=(0, 0))
        region = shapely.affinity.scale(square.buffer(-w / 2, join_style="mitre"), 1.0, h / w, origin=(0, 0))
    parts = [p for p in shapely.get_parts(region) if isinstance(p, shapely.Polygon) and not p.is_empty]
    if not parts:
        return None
    spot = polylabel(max(parts, key=lambda p: p.area), tolerance=0.01)
    return spot.x, spot.y


def _abbreviation(object_id: str) -> str:
    """A short form of an object id: 'KitchenFurniture_4' -> 'KF4', 'Door_3' -> 'D3',
    'Chair_12' -> 'Cha12'."""
    kind, _, number = object_id.rpartition("_")
    caps = "".join(c for c in kind if c.isupper())
    short = caps if len(caps) >= 2 else ("D" if kind == "Door" else kind[:3])
    return short + number


def _shade(colour: RGB, factor: float) -> RGB:
    return (int(colour[0] * factor), int(colour[1] * factor), int(colour[2] * factor))


def _figure_text(figure: Figure, x: float, v: float, text: str, size: float, colour: RGB, **style) -> None:
    """Text with its left baseline point at pixel (x, v), v counted from the top."""
    figure.text(x, figure.bbox.height - v, text, fontsize=size, color=rgb(colour), transform=IdentityTransform(),
                va="baseline", **style)


# --------------------------------------------------------------------------- legend

_SCALE_SIZE = (190, 120)         # the scale-and-axes legend block, px
_LEGEND_TEXT_PT, _LEGEND_TITLE_PT = 8.5, 9.0
_Row = tuple[str, object]        # text, legend handle (an artist or a tuple of artists)


class _Overlaid(tuple):
    """Legend handles drawn on top of one another (a tuple of artists is drawn side by side)."""


def _legend_rows(house: House, overlays: tuple[bool, bool, bool]) -> list[tuple[str, list[_Row]]]:
    """Legend sections: (title, [(text, handle)])."""
    counts: dict[str, int] = {}
    for r in house.rooms:
        counts[r.type] = counts.get(r.type, 0) + 1
    rooms: list[_Row] = [(f"{t} ({n})" if n > 1 else t, _swatch(room_color(t), (150, 150, 150)))
                         for t, n in sorted(counts.items())]
    groups = sorted({object_group(o.type) for o in house.objects if o.type not in SYMBOL_TYPES},
                    key=list(GROUP_COLORS).index)
    objects: list[_Row] = [(g, _swatch(GROUP_COLORS[g][1], GROUP_COLORS[g][0])) for g in groups]
    objects.append((f"overhead (> {OVERHEAD_Z:g} m)", Patch(facecolor="none", linestyle="--", linewidth=PX,
                                                            edgecolor=rgb(GROUP_COLORS["furniture"][0]))))
    walls: list[_Row] = [("wall", _swatch(WALL_RGB, WALL_RGB)),
                         ("lintel over doorway", Line2D([], [], color=rgb(LINTEL_RGB), linestyle="--", linewidth=PX)),
                         ("window", _swatch(WINDOW_FILL_RGB, WINDOW_RGB)),
                         ("door, open", (Line2D([], [], color=rgb(DOOR_OPEN_RGB), linewidth=3 * PX),
                                         Line2D([], [], color=rgb(WALL_RGB), linewidth=PX))),
                         ("door, closed", _swatch(DOOR_CLOSED_RGB, DOOR_CLOSED_EDGE_RGB))]
    if any(w.kind == "column" for w in house.walls):
        walls.insert(1, ("column", _swatch(COLUMN_RGB, WALL_RGB)))
    kinds = {lt.kind for lt in house.lights}
    symbols: list[_Row] = [(name, icon) for kind, name, icon in (
        ("ceiling", "ceiling light", _Overlaid((_marker("o", 10, LIGHT_RGB, LIGHT_EDGE_RGB),
                                                _marker("x", 5, None, LIGHT_EDGE_RGB)))),
        ("lamp", "lamp", _marker("o", 6, LIGHT_RGB, LIGHT_EDGE_RGB)),
        ("wall", "wall light", _marker("D", 7, LIGHT_RGB, LIGHT_EDGE_RGB))) if kind in kinds]
    symbols.append(("robot station", (_marker("o", 11, STATION_FILL_RGB, STATION_RGB, 2),
                                      _marker(r"$\rightarrow$", 14, STATION_RGB, STATION_RGB))))
    extra = [row for on, row in zip(overlays, (
        ("free space", Patch(facecolor=(*rgb(FREE_RGB), FREE_ALPHA), edgecolor=rgb(FREE_RGB), linewidth=PX)),
        ("path (start, goal)", (Line2D([], [], color=rgb(PATH_RGB), linewidth=3 * PX),
                                _marker("o", 6, START_RGB, START_RGB), _marker("o", 6, GOAL_RGB, GOAL_RGB))),
        ("pose", _marker(r"$\rightarrow$", 14, POSE_RGB, POSE_RGB)))) if on]
    sections = [("ROOMS", rooms), ("OBJECTS", objects), ("WALLS & DOORS", walls), ("SYMBOLS", symbols)]
    return sections + ([("OVERLAYS", extra)] if extra else [])


def _swatch(fill: RGB, edge: RGB) -> Patch:
    return Patch(facecolor=rgb(fill), edgecolor=rgb(edge), linewidth=PX)


def _marker(marker: str, size: float, fill: RGB | None, edge: RGB, width_px: float = 1) -> Line2D:
    return Line2D([], [], linestyle="none", marker=marker, markersize=size, markeredgewidth=width_px * PX,
                  markerfacecolor=rgb(fill) if fill else "none", markeredgecolor=rgb(edge))


def _section(figure: Figure, title: str, rows: Sequence[_Row], x: float, v: float) -> Legend:
    """The legend of one section with its top-left corner at pixel (x, v), v counted from the top."""
    handles: list[Any] = [h for _, h in rows]
    texts = [t for t, _ in rows]
    legend = figure.legend(handles, texts, loc="upper left", bbox_to_anchor=(x, figure.bbox.height - v),
                           bbox_transform=IdentityTransform(), frameon=False, borderpad=0, borderaxespad=0,
                           handlelength=2.4, handletextpad=0.8, labelspacing=0.7, alignment="left",
                           fontsize=_LEGEND_TEXT_PT, title=title,
                           title_fontproperties={"weight": "bold", "size": _LEGEND_TITLE_PT},
                           handler_map={tuple: HandlerTuple(ndivide=None, pad=0),
                                        _Overlaid: HandlerTuple(ndivide=1)})
    for text in legend.get_texts():
        text.set_color(rgb(TEXT_RGB))
    return legend


def _legend_blocks(house: House, overlays: tuple[bool, bool, bool]) -> list[_Block]:
    """The legend's blocks, each sized by laying its legend out on a scratch figure."""
    sections = _legend_rows(house, overlays)
    scratch = new_figure(800, 800)
    renderer = scratch.canvas.get_renderer()     # type: ignore[attr-defined]
    blocks = []
    for title, rows in sections:
        box = _section(scratch, title, rows, 0, 0).get_window_extent(renderer)
        blocks.append(_Block(math.ceil(box.width), math.ceil(box.height), _section_drawer(title, rows)))
    return blocks + [_Block(*_SCALE_SIZE, _draw_scale)]


def _section_drawer(title: str, rows: Sequence[_Row]) -> Callable[[Figure, int, int, PlanFrame], None]:
    def draw(figure: Figure, x: int, y: int, frame: PlanFrame) -> None:
        _section(figure, title, rows, x, y)
    return draw


def _draw_scale(figure: Figure, x: int, y: int, frame: PlanFrame) -> None:
    """A scale bar of a round length and the +x / +y (north) axes."""
    metres = next(m for m in (1, 2, 5, 10) if m * frame.scale >= 50)
    _figure_text(figure, x, y + 12, "SCALE & AXES", _LEGEND_TITLE_PT, TEXT_RGB, weight="bold")
    axes = figure.axes[0]
    figure.add_artist(AnchoredSizeBar(axes.transData, metres, f"{metres} m", loc="upper left",
                                      bbox_to_anchor=(x, figure.bbox.height - y - 24),
                                      bbox_transform=IdentityTransform(), borderpad=0, pad=0, sep=4,
                                      frameon=False, size_vertical=7 / frame.scale, color=rgb(TEXT_RGB),
                                      fontproperties={"size": _LEGEND_TEXT_PT}))
    ox, oy = x + 14.0, figure.bbox.height - (y + 108.0)
    for (dx, dy), colour, text, at in (((46, 0), (200, 40, 40), "+x", (ox + 52, oy - 4)),
                                       ((0, 46), (30, 150, 60), "+y  N", (ox + 8, oy + 40))):
        figure.add_artist(FancyArrowPatch((ox, oy), (ox + dx, oy + dy), arrowstyle="-|>", color=rgb(colour),
                                          linewidth=2 * PX, mutation_scale=14, transform=IdentityTransform()))
        figure.text(*at, text, fontsize=_LEGEND_TEXT_PT, color=rgb(colour), transform=IdentityTransform())
