"""A raid at a glance: the trajectory and capture points over the house plan, beside a contact sheet.

One picture answers "where did the robot go and what did it see": the plan (rooms, furniture, doors
as recorded) with the capture poses joined in order, and sample captures spread over the raid, each
as RGB, colourised depth and the instance mask, headed by its room. Every sheet tile has a numbered
marker on the plan at the pose it was taken from, so picture and place can be matched.
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path

import cv2
import numpy as np

from ravh_sim.dataset.api import Dataset, Sample
from ravh_sim.viz.plan import Plan, render_plan, room_color, write_plan

COLS, ROWS = 4, 3                      # contact sheet tiles
TILE_W, TILE_H = 320, 240              # RGB size in a tile; depth and mask are half that, side by side
HEAD_H = 46                            # tile header band: number, room, capture, objects in view
GAP = 14
SHEET_HEAD = 64                        # band above the tiles: the sheet's title and the depth scale
DEPTH_RANGE_M = (0.0, 8.0)             # colour scale of the depth tiles (turbo, black = no depth)
MAX_POSES = 150                        # capture arrows drawn on the plan at most (every k-th beyond)
PLAN_PX_PER_M = (40.0, 160.0)          # the plan is scaled to fit the sheet within these bounds
WIDE = 1.25                            # a plan this much wider than tall goes above the sheet
FONT, BOLD, AA = cv2.FONT_HERSHEY_SIMPLEX, cv2.FONT_HERSHEY_DUPLEX, cv2.LINE_AA
INK, SUBINK, PAPER = (44, 40, 40), (104, 96, 96), (255, 255, 255)     # BGR
MARKER_BGR = (40, 40, 200)


def render_summary(dataset: Dataset) -> np.ndarray:
    """The summary picture (BGR uint8) of ``dataset``."""
    picks = pick_samples(dataset, COLS * ROWS)
    sheet = _contact_sheet(dataset, picks)
    plan, beside = _plan(dataset, picks, sheet.shape[:2])
    if beside:
        height = max(plan.shape[0], sheet.shape[0])
        return np.hstack([_pad(plan, height, 0), _pad(sheet, height, 0)])
    width = max(plan.shape[1], sheet.shape[1])
    return np.vstack([_pad(plan, width, 1), _pad(sheet, width, 1)])


def write_summary(dataset: Dataset, path: str | Path) -> None:
    write_plan(path, render_summary(dataset))


def pick_samples(dataset: Dataset, count: int) -> list[Sample]:
    """``count`` samples spread evenly over the raid (all of them if there are fewer)."""
    if len(dataset) == 0:
        return []
    indices = np.unique(np.linspace(0, len(dataset) - 1, min(count, len(dataset))).round().astype(int))
    return [dataset[int(i)] for i in indices]


# --------------------------------------------------------------------------- the plan

def _plan(dataset: Dataset, picks: list[Sample], sheet_hw: tuple[int, int]) -> tuple[np.ndarray, bool]:
    """The house plan with the trajectory, capture arrows and the picks' numbered markers, and
    whether it goes beside the sheet (scaled to its height) or, for a wide plan, above it (scaled
    to its width)."""
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
    image = plan.image
    for number, sample in enumerate(picks, start=1):
        u, v = plan.frame.to_px(sample.pose[0], sample.pose[1])
        _marker(image, (int(round(u)), int(round(v))), number)
    return image, beside


def _marker(img: np.ndarray, centre: tuple[int, int], number: int) -> None:
    """A red disc with a white number, offset up-right of the pose with a leader line."""
    text = str(number)
    (w, h), _ = cv2.getTextSize(text, BOLD, 0.55, 1)
    r = max(w, h) // 2 + 6
    at = (centre[0] + r + 6, centre[1] - r - 6)
    cv2.line(img, centre, at, MARKER_BGR, 2, AA)
    cv2.circle(img, at, r + 2, PAPER, -1, AA)
    cv2.circle(img, at, r, MARKER_BGR, -1, AA)
    cv2.putText(img, text, (at[0] - w // 2, at[1] + h // 2), BOLD, 0.55, PAPER, 1, AA)


# --------------------------------------------------------------------------- the contact sheet

def _contact_sheet(dataset: Dataset, picks: list[Sample]) -> np.ndarray:
    tile_h = HEAD_H + TILE_H + TILE_H // 2
    width = COLS * TILE_W + (COLS + 1) * GAP
    height = SHEET_HEAD + ROWS * tile_h + (ROWS + 1) * GAP
    sheet = np.full((height, width, 3), PAPER, np.uint8)
    cv2.putText(sheet, f"{len(picks)} of {len(dataset)} captures: RGB, depth, instances", (GAP, 36),
                BOLD, 0.8, INK, 1, AA)
    _depth_scale(sheet, (width - GAP - 300, 22))
    if not picks:
        cv2.putText(sheet, "no complete captures", (GAP, SHEET_HEAD + 60), FONT, 0.8, SUBINK, 1, AA)
    for number, sample in enumerate(picks, start=1):
        row, col = divmod(number - 1, COLS)
        x, y = GAP + col * (TILE_W + GAP), SHEET_HEAD + GAP + row * (tile_h + GAP)
        sheet[y:y + tile_h, x:x + TILE_W] = _tile(sample, number, dataset.objects_in(sample))
    return sheet


def _tile(sample: Sample, number: int, seen: Counter[str]) -> np.ndarray:
    """Header (number, room on its plan colour, capture, objects in view), RGB, then depth | mask
    at half size."""
    half = (TILE_W // 2, TILE_H // 2)
    tile = np.full((HEAD_H + TILE_H + half[1], TILE_W, 3), PAPER, np.uint8)
    swatch = room_color(sample.room_type or "")
    tile[:HEAD_H] = swatch[::-1]
    centre = (18, HEAD_H // 2)
    cv2.circle(tile, centre, 13, MARKER_BGR, -1, AA)
    (w, h), _ = cv2.getTextSize(str(number), BOLD, 0.55, 1)
    cv2.putText(tile, str(number), (centre[0] - w // 2, centre[1] + h // 2), BOLD, 0.55, PAPER, 1, AA)
    when = f"#{sample.index}  {sample.stamp:.1f} s"
    when_w = cv2.getTextSize(when, FONT, 0.42, 1)[0][0]
    cv2.putText(tile, when, (TILE_W - 8 - when_w, 20), FONT, 0.42, SUBINK, 1, AA)
    cv2.putText(tile, _fit(sample.room or "outside the rooms", TILE_W - 60 - when_w, BOLD, 0.52), (38, 20),
                BOLD, 0.52, INK, 1, AA)
    objects = ", ".join(k if c == 1 else f"{c} {k}" for k, c in seen.most_common()) or "no objects in view"
    cv2.putText(tile, _fit(objects, TILE_W - 46, FONT, 0.42), (38, 39), FONT, 0.42, SUBINK, 1, AA)
    tile[HEAD_H:HEAD_H + TILE_H] = cv2.resize(cv2.cvtColor(sample.rgb, cv2.COLOR_RGB2BGR), (TILE_W, TILE_H),
                                              interpolation=cv2.INTER_AREA)
    bottom = HEAD_H + TILE_H
    tile[bottom:, :half[0]] = cv2.resize(colourise_depth(sample.depth), half, interpolation=cv2.INTER_NEAREST)
    tile[bottom:, half[0]:] = cv2.resize(cv2.cvtColor(sample.mask, cv2.COLOR_RGB2BGR), half,
                                         interpolation=cv2.INTER_NEAREST)
    cv2.line(tile, (half[0], bottom), (half[0], tile.shape[0]), PAPER, 1)
    cv2.rectangle(tile, (0, 0), (TILE_W - 1, tile.shape[0] - 1), (200, 200, 200), 1)
    return tile


def _fit(text: str, width: int, font: int, scale: float) -> str:
    """``text``, cut and ended with an ellipsis if it is wider than ``width`` pixels."""
    if cv2.getTextSize(text, font, scale, 1)[0][0] <= width:
        return text
    while text and cv2.getTextSize(text + "...", font, scale, 1)[0][0] > width:
        text = text[:-1]
    return text.rstrip(", ") + "..."


def colourise_depth(metres: np.ndarray) -> np.ndarray:
    """BGR picture of a depth image: turbo over :data:`DEPTH_RANGE_M`, black where there is no depth."""
    lo, hi = DEPTH_RANGE_M
    scaled = np.nan_to_num((metres - lo) / (hi - lo), nan=0.0)
    image = cv2.applyColorMap((np.clip(scaled, 0, 1) * 255).astype(np.uint8), cv2.COLORMAP_TURBO)
    image[~np.isfinite(metres)] = 0
    return image


def _depth_scale(img: np.ndarray, origin: tuple[int, int]) -> None:
    """The depth colour bar with its end labels."""
    x, y = origin
    bar = cv2.applyColorMap(np.tile(np.linspace(0, 255, 200).astype(np.uint8), (12, 1)), cv2.COLORMAP_TURBO)
    img[y:y + 12, x + 50:x + 250] = bar
    lo, hi = DEPTH_RANGE_M
    cv2.putText(img, "depth", (x, y + 11), FONT, 0.45, SUBINK, 1, AA)
    cv2.putText(img, f"{lo:g}", (x + 46, y + 30), FONT, 0.42, SUBINK, 1, AA)
    cv2.putText(img, f"{hi:g} m", (x + 238, y + 30), FONT, 0.42, SUBINK, 1, AA)


def _pad(img: np.ndarray, size: int, axis: int) -> np.ndarray:
    """``img`` extended with white to ``size`` rows (axis 0, below) or columns (axis 1, centred)."""
    extra = size - img.shape[axis]
    if extra <= 0:
        return img
    before = 0 if axis == 0 else extra // 2
    pad = [(0, 0)] * 3
    pad[axis] = (before, extra - before)
    return np.pad(img, pad, constant_values=255)
