"""The semantic-map format: labelled 3-D boxes in the house (map) frame, and how two boxes overlap.

A semantic map is a JSON file (``ravh_sim/semantic_map@1``)::

    {"format": "ravh_sim/semantic_map@1", "house": 20, "detections": 212,
     "boxes": [{"type": "Chair", "center": [x, y, z], "size": [sx, sy, sz], "yaw": 0.3,
                "score": 0.9, "captures": [12, 13]}, ...]}

``detections`` (optional) is how many detections the mapper fused into the boxes (Table 3's "CNN
detections"). ``center`` is the box centre in metres in the house/map frame (z up, the floor of the ground storey
at z = 0 as in the footprint); ``size`` the full extents along the box's own x, y, z axes; ``yaw`` the
rotation of the box's x axis about +z (radians). ``score`` (default 1) and ``captures`` (the dataset
capture indices the box came from, default []) are optional. ``type`` uses the footprint's object
types (``ravh houses`` lists them). Ground-truth objects are boxes of the same kind, read from the
dataset's footprint, so maps and ground truth compare on equal terms.
"""
from __future__ import annotations

import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ravh_sim.errors import FileFieldError, UserError
from ravh_sim.world.geometry import box_corners

FORMAT = "ravh_sim/semantic_map@1"


@dataclass(frozen=True)
class LabelledBox:
    type: str
    center: tuple[float, float, float]
    size: tuple[float, float, float]
    yaw: float = 0.0
    score: float = 1.0
    captures: tuple[int, ...] = field(default=())

    @property
    def volume(self) -> float:
        return float(np.prod(self.size))

    def grown(self, margin: float) -> LabelledBox:
        """The same box with ``margin`` added on every side."""
        sx, sy, sz = self.size
        return LabelledBox(self.type, self.center, (sx + 2 * margin, sy + 2 * margin, sz + 2 * margin), self.yaw,
                           self.score, self.captures)

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(N,) bool: which of the (N, 3) points lie inside the box."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        d = np.asarray(points, float) - self.center
        local = np.column_stack((d[:, 0] * c + d[:, 1] * s, -d[:, 0] * s + d[:, 1] * c, d[:, 2]))
        return np.all(np.abs(local) <= np.asarray(self.size) / 2, axis=1)

    def corners_xy(self) -> np.ndarray:
        """(4, 2) counter-clockwise corners of the box seen from above."""
        return box_corners(self.center[:2], self.size[:2], self.yaw)

    def to_dict(self) -> dict[str, Any]:
        return {"type": self.type, "center": [round(v, 4) for v in self.center],
                "size": [round(v, 4) for v in self.size], "yaw": round(self.yaw, 4),
                "score": round(self.score, 4), "captures": list(self.captures)}


@dataclass
class SemanticMap:
    house: int
    boxes: list[LabelledBox]
    detections: int | None = None          # detections fused into the boxes, when the mapper counted them

    def to_dict(self) -> dict[str, Any]:
        counted = {} if self.detections is None else {"detections": self.detections}
        return {"format": FORMAT, "house": self.house, **counted, "boxes": [b.to_dict() for b in self.boxes]}


def write_map(semantic_map: SemanticMap, path: str | Path) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(semantic_map.to_dict(), indent=1) + "\n")


def read_map(path: str | Path) -> SemanticMap:
    """Read and check a semantic-map file; a bad field raises FileFieldError naming it."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UserError(f"{path}: no such semantic-map file") from None
    except (OSError, ValueError) as e:
        raise FileFieldError(path, "-", f"cannot read: {e}") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise FileFieldError(path, "format", f"expected {FORMAT!r}")
    if not isinstance(data.get("house"), int):
        raise FileFieldError(path, "house", "expected the house number (integer)")
    if not isinstance(data.get("boxes"), list):
        raise FileFieldError(path, "boxes", "expected a list of boxes")
    detections = data.get("detections")
    if detections is not None and (not isinstance(detections, int) or isinstance(detections, bool) or detections < 0):
        raise FileFieldError(path, "detections", "expected a count (integer >= 0)")
    return SemanticMap(data["house"], [_box(path, f"boxes[{i}]", b) for i, b in enumerate(data["boxes"])],
                       detections)


def _box(path: str | Path, where: str, b: Any) -> LabelledBox:
    if not isinstance(b, dict):
        raise FileFieldError(path, where, "expected an object")
    if not isinstance(b.get("type"), str) or not b["type"]:
        raise FileFieldError(path, f"{where}.type", "expected an object type name")

    def vector(key: str, positive: bool) -> tuple[float, float, float]:
        v = b.get(key)
        if (not isinstance(v, list) or len(v) != 3 or not all(_finite(x) for x in v)
                or (positive and not all(x > 0 for x in v))):
            raise FileFieldError(path, f"{where}.{key}", f"expected 3 {'positive ' if positive else ''}numbers")
        return float3(v)

    def number(key: str, default: float) -> float:
        v = b.get(key, default)
        if not _finite(v):
            raise FileFieldError(path, f"{where}.{key}", "expected a number")
        return float(v)

    captures = b.get("captures", [])
    if not isinstance(captures, list) or not all(isinstance(c, int) for c in captures):
        raise FileFieldError(path, f"{where}.captures", "expected a list of capture indices")
    return LabelledBox(b["type"], vector("center", False), vector("size", True), number("yaw", 0.0),
                       number("score", 1.0), tuple(captures))


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


# --------------------------------------------------------------------------- overlap

def intersection_volume(a: LabelledBox, b: LabelledBox) -> float:
    """Volume shared by two yawed boxes: the overlap of their footprints times their z overlap."""
    dz = (min(a.center[2] + a.size[2] / 2, b.center[2] + b.size[2] / 2)
          - max(a.center[2] - a.size[2] / 2, b.center[2] - b.size[2] / 2))
    if dz <= 0:
        return 0.0
    return convex_overlap_area(a.corners_xy(), b.corners_xy()) * dz


def iou(a: LabelledBox, b: LabelledBox) -> float:
    """3-D intersection over union."""
    inter = intersection_volume(a, b)
    return inter / (a.volume + b.volume - inter) if inter > 0 else 0.0


def convex_overlap_area(p: np.ndarray, q: np.ndarray) -> float:
    """Area of the intersection of two convex counter-clockwise polygons (Sutherland-Hodgman)."""
    out: list[np.ndarray] = list(np.asarray(p, float))
    q = np.asarray(q, float)
    for i in range(len(q)):
        a, b = q[i], q[(i + 1) % len(q)]
        edge = b - a
        side = [edge[0] * (v[1] - a[1]) - edge[1] * (v[0] - a[0]) for v in out]   # >= 0: inside
        clipped: list[np.ndarray] = []
        for j in range(len(out)):
            cur, nxt, s_cur, s_nxt = out[j], out[(j + 1) % len(out)], side[j], side[(j + 1) % len(out)]
            if s_cur >= 0:
                clipped.append(cur)
            if (s_cur >= 0) != (s_nxt >= 0):
                clipped.append(cur + (nxt - cur) * (s_cur / (s_cur - s_nxt)))
        out = clipped
        if len(out) < 3:
            return 0.0
    return _area(np.array(out))


def _area(poly: np.ndarray) -> float:
    x, y = poly[:, 0], poly[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2)


def float3(values: Iterable[Any]) -> tuple[float, float, float]:
    """Three numbers (a box's centre or size) as the float 3-tuple a box holds."""
    x, y, z = (float(v) for v in values)
    return x, y, z


def box_of_points(type_: str, points: np.ndarray, min_size: float, score: float = 1.0,
                  captures: Sequence[int] = ()) -> LabelledBox:
    """The tightest yawed box (minimum-area rectangle from above, z from min to max) around
    (N, 3) points, each extent at least ``min_size`` (a flat surface still has a volume)."""
    (cx, cy), (w, h), angle = cv2.minAreaRect(points[:, :2].astype(np.float32))
    z0, z1 = float(points[:, 2].min()), float(points[:, 2].max())
    size = (max(float(w), min_size), max(float(h), min_size), max(z1 - z0, min_size))
    return LabelledBox(type_, (float(cx), float(cy), (z0 + z1) / 2), size, math.radians(angle), score,
                       tuple(sorted(set(captures))))
