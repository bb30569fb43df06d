"""A raid at a glance: the trajectory and capture points over the house plan, beside a contact sheet.

One picture answers "where did the robot go and what did it see": the plan (rooms, furniture, doors
as recorded) with the capture poses joined in order, and sample captures spread over the raid, each
as RGB, colourised depth and the instance mask, headed by its room. Every sheet tile has a numbered
marker on the plan at the pose it was taken from, so picture and place can be matched. The picture
is one matplotlib figure: the plan and the captures are placed in it pixel for pixel.
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path

import cv2
import matplotlib
import numpy as np
from matplotlib.colorbar import Colorbar
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.patches import Circle, Rectangle
from matplotlib.transforms import IdentityTransform

from ravh_sim.dataset.api import Dataset, Sample
from ravh_sim.viz.figure import figure_bgr, new_figure, rgb
from ravh_sim.viz.plan import Plan, render_plan, room_color, write_plan

COLS, ROWS = 4, 3                      # contact sheet tiles
TILE_W, TILE_H = 320, 240              # RGB size in a tile; depth and mask are half that, side by side
HEAD_H = 46                            # tile header band: number, room, capture, objects in view
GAP = 14
SHEET_HEAD = 64                        # band above the tiles: the sheet's title and the depth scale
DEPTH_RANGE_M = (0.0, 8.0)             # colour scale of the depth tiles (turbo, black = no depth)
DEPTH_MAP = matplotlib.colormaps["turbo"]
MAX_POSES = 150                        # capture arrows drawn on the plan at most (every k-th beyond)
PLAN_PX_PER_M = (40.0, 160.0)          # the plan is scaled to fit the sheet within these bounds
WIDE = 1.25                            # a plan this much wider than tall goes above the sheet
INK, SUBINK = (40, 40, 44), (96, 96, 104)                            # RGB
MARKER_RGB = (200, 40, 40)
NUMBER_PT, TEXT_PT, SMALL_PT = 10.0, 9.5, 7.5                       # font sizes
TILE_H_ALL = HEAD_H + TILE_H + TILE_H // 2
SHEET_W = COLS * TILE_W + (COLS + 1) * GAP
SHEET_H = SHEET_HEAD + ROWS * TILE_H_ALL + (ROWS + 1) * GAP


def render_summary(dataset: Dataset) -> np.ndarray:
    """The summary picture (BGR uint8) of ``dataset``."""
    picks = pick_samples(dataset, COLS * ROWS)
    plan, beside = _plan(dataset, (SHEET_H, SHEET_W))
    plan_h, plan_w = plan.image.shape[:2]
    if beside:
        width, height = plan_w + SHEET_W, max(plan_h, SHEET_H)
        plan_at, sheet_at = (0, 0), (plan_w, 0)
    else:
        width, height = max(plan_w, SHEET_W), plan_h + SHEET_H
        plan_at, sheet_at = ((width - plan_w) // 2, 0), ((width - SHEET_W) // 2, plan_h)
    figure = new_figure(width, height)
    _image(figure, cv2.cvtColor(plan.image, cv2.COLOR_BGR2RGB), *plan_at)
    for number, sample in enumerate(picks, start=1):
        u, v = plan.frame.to_px(sample.pose[0], sample.pose[1])
        _marker(figure, plan_at[0] + u, plan_at[1] + v, number)
    _contact_sheet(figure, dataset, picks, *sheet_at)
    return figure_bgr(figure)


def write_summary(dataset: Dataset, path: str | Path) -> None:
    write_plan(path, render_summary(dataset))


def pick_samples(dataset: Dataset, count: int) -> list[Sample]:
    """``count`` samples spread evenly over the raid (all of them if there are fewer)."""
    if len(dataset) == 0:
        return []
    indices = np.unique(np.linspace(0, len(dataset) - 1, min(count, len(dataset))).round().astype(int))
    return [dataset[int(i)] for i in indices]


# --------------------------------------------------------------------------- the plan

def _plan(dataset: Dataset, sheet_hw: tuple[int, int]) -> tuple[Plan, bool]:
    """The house plan with the trajectory and capture arrows, and whether it goes beside the sheet
    (scaled to its height) or, for a wide plan, above it (scaled to its width)."""
    house, settings = dataset.house, dataset.settings
    samples = list(dataset)
    first = samples[0].agent if samples else None
    path = [s.pose[:2] for s in samples if s.agent == first]
    poses = [s.pose for s in samples][::max(1, -(-len(samples) // MAX_POSES))]
    t0, t1 = (samples[0].stamp, samples[-1].stamp) if samples else (0.0, 0.0)
    title = (f"House {house.number} raid — {len(samples)} captures, "
             f"{len(dataset.rooms_visited())}/{dataset.count_rooms()} rooms, {t1 - t0:.0f} s")

    def draw(px_per_m: float) -> Plan:
        return render_plan(house, door_open=settings.doors, models=settings.models,
                           path=path if len(path) >= 2 else None, poses=poses or None,
                           px_per_m=px_per_m, title=title)

    plan = draw(80.0)
    h, w = plan.image.shape[:2]
    beside = w < WIDE * h
    ratio = sheet_hw[0] / h if beside else sheet_hw[1] / w
    scale = float(np.clip(80.0 * ratio, *PLAN_PX_PER_M))
    if abs(scale - 80.0) > 4.0:
        plan = draw(scale)
    return plan, beside


def _marker(figure: Figure, u: float, v: float, number: int) -> None:
    """A red disc with a white number, offset up-right of the pose (pixel u, v) with a leader line."""
    r = 13.0
    at = (u + r + 6, v - r - 6)
    figure.add_artist(matplotlib.lines.Line2D([u, at[0]], [_y(figure, v), _y(figure, at[1])], linewidth=1.5,
                                              color=rgb(MARKER_RGB), transform=IdentityTransform()))
    _disc(figure, at[0], at[1], r, str(number), ring=True)


def _disc(figure: Figure, u: float, v: float, r: float, text: str, ring: bool = False) -> None:
    figure.add_artist(Circle((u, _y(figure, v)), r, facecolor=rgb(MARKER_RGB), transform=IdentityTransform(),
                             edgecolor="white" if ring else "none", linewidth=1.5))
    figure.text(u, _y(figure, v), text, fontsize=NUMBER_PT, weight="bold", color="white", ha="center",
                va="center_baseline", transform=IdentityTransform())


# --------------------------------------------------------------------------- the contact sheet

def _contact_sheet(figure: Figure, dataset: Dataset, picks: list[Sample], x0: int, y0: int) -> None:
    """The sheet with its top-left corner at pixel (x0, y0)."""
    _text(figure, x0 + GAP, y0 + 36, f"{len(picks)} of {len(dataset)} captures: RGB, depth, instances", 15,
          INK, weight="bold")
    _depth_scale(figure, x0 + SHEET_W - GAP - 250, y0 + 22)
    if not picks:
        _text(figure, x0 + GAP, y0 + SHEET_HEAD + 60, "no complete captures", 14, SUBINK)
    for number, sample in enumerate(picks, start=1):
        row, col = divmod(number - 1, COLS)
        x, y = x0 + GAP + col * (TILE_W + GAP), y0 + SHEET_HEAD + GAP + row * (TILE_H_ALL + GAP)
        _tile(figure, sample, number, dataset.objects_in(sample), x, y)


def _tile(figure: Figure, sample: Sample, number: int, seen: Counter[str], x: int, y: int) -> None:
    """Header (number, room on its plan colour, capture, objects in view), RGB, then depth | mask
    at half size, with the top-left corner at pixel (x, y)."""
    half = (TILE_W // 2, TILE_H // 2)
    _box(figure, x, y, TILE_W, HEAD_H, fill=room_color(sample.room_type or ""))
    _disc(figure, x + 18, y + HEAD_H / 2, 13, str(number))
    when = f"#{sample.index}  {sample.stamp:.1f} s"
    when_w = _width(figure, when, SMALL_PT)
    _text(figure, x + TILE_W - 8 - when_w, y + 20, when, SMALL_PT, SUBINK)
    room = _fit(figure, sample.room or "outside the rooms", TILE_W - 60 - when_w, TEXT_PT, "bold")
    _text(figure, x + 38, y + 20, room, TEXT_PT, INK, weight="bold")
    objects = ", ".join(k if c == 1 else f"{c} {k}" for k, c in seen.most_common()) or "no objects in view"
    _text(figure, x + 38, y + 39, _fit(figure, objects, TILE_W - 46, SMALL_PT), SMALL_PT, SUBINK)
    _image(figure, cv2.resize(sample.rgb, (TILE_W, TILE_H), interpolation=cv2.INTER_AREA), x, y + HEAD_H)
    bottom = y + HEAD_H + TILE_H
    depth = cv2.cvtColor(colourise_depth(sample.depth), cv2.COLOR_BGR2RGB)
    _image(figure, cv2.resize(depth, half, interpolation=cv2.INTER_NEAREST), x, bottom)
    _image(figure, cv2.resize(sample.mask, half, interpolation=cv2.INTER_NEAREST), x + half[0], bottom)
    _box(figure, x, y, TILE_W, TILE_H_ALL, edge=(200, 200, 200))


def colourise_depth(metres: np.ndarray) -> np.ndarray:
    """BGR picture of a depth image: turbo over :data:`DEPTH_RANGE_M`, black where there is no depth."""
    lo, hi = DEPTH_RANGE_M
    scaled = np.nan_to_num((metres - lo) / (hi - lo), nan=0.0)
    image = DEPTH_MAP(np.clip(scaled, 0, 1), bytes=True)[..., 2::-1].copy()
    image[~np.isfinite(metres)] = 0
    return image


def _depth_scale(figure: Figure, x: int, y: int) -> None:
    """The depth colour bar (200 x 12 px) with its range, its left end at pixel (x, y)."""
    axes = figure.add_axes((x / figure.bbox.width, 1 - (y + 12) / figure.bbox.height,
                            200 / figure.bbox.width, 12 / figure.bbox.height))
    bar = Colorbar(axes, cmap=DEPTH_MAP, norm=Normalize(*DEPTH_RANGE_M), orientation="horizontal")
    bar.outline.set_visible(False)
    bar.set_ticks(DEPTH_RANGE_M, labels=[f"{DEPTH_RANGE_M[0]:g}", f"{DEPTH_RANGE_M[1]:g} m"])
    axes.tick_params(labelsize=SMALL_PT, colors=rgb(SUBINK), length=2)
    _text(figure, x - 46, y + 11, "depth", SMALL_PT, SUBINK)


# --------------------------------------------------------------------------- pixel placement

def _y(figure: Figure, v: float) -> float:
    """matplotlib's pixel y (up from the bottom) of a picture row v (down from the top)."""
    return figure.bbox.height - v


def _image(figure: Figure, picture: np.ndarray, x: int, y: int) -> None:
    """An RGB picture, unscaled, with its top-left corner at pixel (x, y)."""
    figure.figimage(picture, xo=x, yo=int(_y(figure, y + picture.shape[0])), origin="upper")


def _box(figure: Figure, x: float, y: float, w: float, h: float, fill: tuple[int, int, int] | None = None,
         edge: tuple[int, int, int] | None = None) -> None:
    figure.add_artist(Rectangle((x, _y(figure, y + h)), w, h, transform=IdentityTransform(), linewidth=1,
                                facecolor=rgb(fill) if fill else "none", edgecolor=rgb(edge) if edge else "none",
                                zorder=0 if fill else 3))


def _text(figure: Figure, x: float, y: float, text: str, size: float, colour: tuple[int, int, int],
          weight: str = "normal") -> None:
    """One line with its left baseline point at pixel (x, y)."""
    figure.text(x, _y(figure, y), text, fontsize=size, color=rgb(colour), weight=weight,
                transform=IdentityTransform())


def _width(figure: Figure, text: str, size: float, weight: str = "normal") -> float:
    renderer = figure.canvas.get_renderer()      # type: ignore[attr-defined]
    return renderer.get_text_width_height_descent(text, FontProperties(size=size, weight=weight), ismath=False)[0]


def _fit(figure: Figure, text: str, width: float, size: float, weight: str = "normal") -> str:
    """``text``, cut and ended with an ellipsis if it is wider than ``width`` pixels."""
    if _width(figure, text, size, weight) <= width:
        return text
    while text and _width(figure, text + "...", size, weight) > width:
        text = text[:-1]
    return text.rstrip(", ") + "..."
