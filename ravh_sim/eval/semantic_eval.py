"""Semantic-map evaluation against the dataset's ground truth (paper §5.4, Table 3, Fig. 9).

Ground truth is every object of the dataset's footprint (kind ``object``: not doors, windows or room
surfaces), as a box (position, size, yaw of the model it had). Rules:

* **match**: a map box and a ground-truth object match when their types are equal and their overlap
  reaches the threshold (``--iou``, default :data:`DEFAULT_THRESHOLD`). Overlap is the 3-D
  intersection over the *smaller* of the two volumes, with the object's box grown by
  :data:`TOLERANCE` m on every side (depth-built boxes sit on the object's surface). So a box built
  from a partial view (it lies inside the object) matches, and so does a box over several chairs
  (each chair lies inside it);
* **precision** (per type): share of the map's boxes of that type that match some object;
* **detectable**: an object covering at least N = :data:`~ravh_sim.dataset.api.MIN_PIXELS` pixels
  of the instance mask in at least one capture (what the robot could have seen);
* **recall** (per type): share of the detectable objects of that type matched by at least one box;
* **covered by one box**: found objects whose matching box also matches another object;
  **found by several**: objects matched by two or more boxes.

House rows pool all types; "mean" rows average the houses (Table 3's last row).
"""
from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ravh_sim.dataset.api import MIN_PIXELS, Dataset
from ravh_sim.errors import UserError
from ravh_sim.eval.semantic_map import LabelledBox, SemanticMap, intersection_volume, read_map
from ravh_sim.viz.plan import render_plan, write_plan

DEFAULT_THRESHOLD = 0.5
TOLERANCE = 0.05            # m


@dataclass(frozen=True)
class GroundTruthObject:
    id: int
    name: str
    box: LabelledBox
    max_pixels: int                  # most pixels it covers in one capture

    @property
    def detectable(self) -> bool:
        return self.max_pixels >= MIN_PIXELS


def ground_truth(dataset: Dataset) -> list[GroundTruthObject]:
    """The dataset's objects as boxes, with how well the captures saw each."""
    ids = [i for i, r in sorted(dataset.instances.items()) if r["kind"] == "object"]
    seen = np.zeros(max(dataset.instances, default=0) + 1, np.int64)
    for sample in dataset:
        counts = np.bincount(sample.instance.ravel(), minlength=len(seen))[:len(seen)]
        np.maximum(seen, counts, out=seen)
    out = []
    for i in ids:
        r = dataset.instances[i]
        box = LabelledBox(r["type"], tuple(r["position"]), tuple(max(s, 1e-3) for s in r["size"]), r["yaw"])
        out.append(GroundTruthObject(i, r["name"], box, int(seen[i])))
    return out


def overlap(box: LabelledBox, truth: LabelledBox) -> float:
    """Intersection volume over the smaller volume, the truth grown by TOLERANCE (module rules)."""
    grown = truth.grown(TOLERANCE)
    inter = intersection_volume(box, grown)
    return inter / min(box.volume, grown.volume) if inter > 0 else 0.0


@dataclass
class Counts:
    boxes: int = 0
    correct: int = 0
    detectable: int = 0
    found: int = 0
    covered_by_one_box: int = 0
    found_by_several: int = 0

    @property
    def precision(self) -> float | None:
        return self.correct / self.boxes if self.boxes else None

    @property
    def recall(self) -> float | None:
        return self.found / self.detectable if self.detectable else None

    def add(self, other: Counts) -> None:
        for k in self.__dataclass_fields__:
            setattr(self, k, getattr(self, k) + getattr(other, k))

    def to_dict(self) -> dict[str, Any]:
        return {**{k: getattr(self, k) for k in self.__dataclass_fields__},
                "precision": _round(self.precision), "recall": _round(self.recall)}


@dataclass
class HouseResult:
    house: int
    total: Counts
    by_type: dict[str, Counts]
    box_correct: list[bool]                       # per map box
    object_found: dict[int, bool]                 # detectable object id -> found
    detections: int | None = None                 # detections fused into the map (when counted)

    def to_dict(self) -> dict[str, Any]:
        return {"house": self.house, "detections": self.detections, **self.total.to_dict(),
                "by_type": {t: c.to_dict() for t, c in sorted(self.by_type.items())}}


def evaluate(semantic_map: SemanticMap, truth: Sequence[GroundTruthObject], house: int,
             threshold: float = DEFAULT_THRESHOLD) -> HouseResult:
    """Precision, recall and the one-box / several-boxes counts of ``semantic_map`` (module rules)."""
    if semantic_map.house != house:
        raise UserError(f"the map is of house {semantic_map.house}, the dataset of house {house}")
    matches: list[list[int]] = []                 # per box: indices into truth it matches
    for box in semantic_map.boxes:
        matches.append([j for j, obj in enumerate(truth)
                        if obj.box.type == box.type and overlap(box, obj.box) >= threshold])
    boxes_of = defaultdict(list)                  # truth index -> boxes matching it
    for b, js in enumerate(matches):
        for j in js:
            boxes_of[j].append(b)
    by_type: dict[str, Counts] = defaultdict(Counts)
    for box, js in zip(semantic_map.boxes, matches):
        by_type[box.type].boxes += 1
        by_type[box.type].correct += bool(js)
    found = {}
    for j, obj in enumerate(truth):
        if not obj.detectable:
            continue
        c = by_type[obj.box.type]
        c.detectable += 1
        hits = boxes_of.get(j, [])
        found[obj.id] = bool(hits)
        c.found += bool(hits)
        c.covered_by_one_box += any(len(matches[b]) > 1 for b in hits)
        c.found_by_several += len(hits) > 1
    total = Counts()
    for c in by_type.values():
        total.add(c)
    return HouseResult(house, total, dict(by_type), [bool(js) for js in matches], found, semantic_map.detections)


def table(results: Sequence[HouseResult]) -> dict[str, Any]:
    """Table 3 as JSON: a row per house, the mean of the houses, and per type over all houses."""
    by_type: dict[str, Counts] = defaultdict(Counts)
    for r in results:
        for t, c in r.by_type.items():
            by_type[t].add(c)
    precisions = [r.total.precision for r in results if r.total.precision is not None]
    recalls = [r.total.recall for r in results if r.total.recall is not None]
    return {"houses": [r.to_dict() for r in results],
            "mean": {"precision": _round(float(np.mean(precisions))) if precisions else None,
                     "recall": _round(float(np.mean(recalls))) if recalls else None},
            "by_type": {t: c.to_dict() for t, c in sorted(by_type.items())},
            "rules": {"overlap": "intersection volume / smaller volume", "tolerance_m": TOLERANCE,
                      "detectable_pixels": MIN_PIXELS}}


def format_table(doc: dict[str, Any]) -> str:
    """Table 3 as text."""
    head = f"{'':<18}{'boxes':>6}{'correct':>8}{'precision':>10}{'detectable':>11}{'found':>6}{'recall':>8}" \
           f"{'1 box/many':>11}{'many boxes':>11}"
    lines = [head]

    def row(name: str, c: dict[str, Any]) -> str:
        return (f"{name:<18}{c['boxes']:>6}{c['correct']:>8}{_fmt(c['precision']):>10}{c['detectable']:>11}"
                f"{c['found']:>6}{_fmt(c['recall']):>8}{c['covered_by_one_box']:>11}{c['found_by_several']:>11}")
    for h in doc["houses"]:
        lines.append(row(f"house {h['house']}", h))
    lines.append(f"{'mean of houses':<18}{'':>14}{_fmt(doc['mean']['precision']):>10}{'':>17}"
                 f"{_fmt(doc['mean']['recall']):>8}")
    lines.append("")
    lines.append("by type (all houses)")
    lines.extend(row(t, c) for t, c in doc["by_type"].items())
    return "\n".join(lines)


PAPER_COLUMNS = ("CNN detections", "boxes", "detected objects", "precision %", "recall %")


def paper_columns(row: dict[str, Any]) -> tuple[Any, ...]:
    """One of our house rows as Table 3's columns (detected objects: the objects a box found)."""
    return (row.get("detections"), row["boxes"], row["found"], _pct(row["precision"]), _pct(row["recall"]))


def format_beside_paper(doc: dict[str, Any], paper: dict[int, dict[str, str]], label: str = "ours") -> str:
    """Table 3's columns per house, our row and the paper's (``paper``: house -> its TSV row) beside it,
    then over the houses in both: the mean of each, ours over the paper's, and the range (lowest-highest
    house) of each."""
    head = f"{'house':<7}{'':<16}" + "".join(f"{c:>17}" for c in PAPER_COLUMNS)
    lines = [head]
    ours_rows, theirs_rows = [], []
    for h in doc["houses"]:
        ours = paper_columns(h)
        lines.append(f"{h['house']:<7}{label:<16}" + "".join(f"{_cell(v):>17}" for v in ours))
        row = paper.get(int(h["house"]))
        if row is not None:
            theirs = (int(row["cnn_detections"]), int(row["detection_boxes"]), int(row["detected_objects"]),
                      float(row["precision_pct"]), float(row["recall_pct"]))
            lines.append(f"{'':<7}{'paper':<16}" + "".join(f"{_cell(v):>17}" for v in theirs))
            ours_rows.append(ours)
            theirs_rows.append(theirs)
    means = {}
    for name, rows in ((label, ours_rows), ("paper", theirs_rows)):
        means[name] = [_mean([r[k] for r in rows]) for k in range(len(PAPER_COLUMNS))]
        lines.append(f"{'mean':<7}{name:<16}" + "".join(f"{_cell(v):>17}" for v in means[name]))
    ratios = [None if a is None or not b else f"{a / b:.2f}x" for a, b in zip(means[label], means["paper"])]
    lines.append(f"{'ratio':<7}{label + ' / paper':<16}" + "".join(f"{_cell(v):>17}" for v in ratios))
    for name, rows in ((label, ours_rows), ("paper", theirs_rows)):
        spans = [_span([r[k] for r in rows]) for k in range(len(PAPER_COLUMNS))]
        lines.append(f"{'range':<7}{name:<16}" + "".join(f"{_cell(v):>17}" for v in spans))
    return "\n".join(lines)


def _span(values: list[Any]) -> str | None:
    """'lowest-highest' of the known values."""
    known = [v for v in values if v is not None]
    return f"{_cell(min(known))}-{_cell(max(known))}" if known else None


def _pct(v: float | None) -> float | None:
    return None if v is None else round(100 * v, 1)


def _mean(values: list[Any]) -> float | None:
    known = [v for v in values if v is not None]
    return round(float(np.mean(known)), 1) if known else None


def _cell(v: Any) -> str:
    return "-" if v is None else f"{v:.1f}" if isinstance(v, float) else str(v)


# --------------------------------------------------------------------------- Fig. 9

CORRECT, WRONG, MISSED, FOUND = (60, 160, 40), (40, 40, 220), (200, 40, 200), (60, 60, 60)   # BGR
LEGEND = ("map boxes: green = correct, red = wrong type or place;  "
          "ground truth: grey = found, magenta = missed (detectable)")
LEGEND_BAND = 34                 # px added under the plan for the legend line


def draw_result(dataset: Dataset, semantic_map: SemanticMap, result: HouseResult,
                truth: Sequence[GroundTruthObject]) -> np.ndarray:
    """The plan with the map's boxes filled by correctness and the detectable ground-truth objects
    outlined by whether they were found, like the paper's Fig. 9 (BGR)."""
    settings = dataset.settings
    t = result.total
    title = f"House {result.house} semantic map: precision {_fmt(t.precision)}, recall {_fmt(t.recall)}"
    plan = render_plan(dataset.house, door_open=settings.doors, models=settings.models, title=title)
    img, frame = plan.image, plan.frame
    outlines = [np.round(frame.to_px_array(b.corners_xy())).astype(np.int32) for b in semantic_map.boxes]
    layer = img.copy()
    for pts, ok in zip(outlines, result.box_correct):
        cv2.fillPoly(layer, [pts], CORRECT if ok else WRONG)
    cv2.addWeighted(layer, 0.4, img, 0.6, 0, dst=img)
    for obj in truth:
        if obj.id in result.object_found:
            found = result.object_found[obj.id]
            pts = np.round(frame.to_px_array(obj.box.corners_xy())).astype(np.int32)
            cv2.polylines(img, [pts], True, FOUND if found else MISSED, 1 if found else 3, cv2.LINE_AA)
    for pts, ok in zip(outlines, result.box_correct):
        cv2.polylines(img, [pts], True, CORRECT if ok else WRONG, 2, cv2.LINE_AA)
    band = np.full((LEGEND_BAND, img.shape[1], 3), 255, np.uint8)
    cv2.putText(band, LEGEND, (12, 22), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (40, 40, 40), 1, cv2.LINE_AA)
    return np.vstack((img, band))


def evaluate_datasets(pairs: Sequence[tuple[Path, Path]], threshold: float = DEFAULT_THRESHOLD,
                      picture_dir: Path | None = None) -> dict[str, Any]:
    """Evaluate each (dataset folder, map file) pair; Table 3 as JSON, pictures if asked."""
    results = []
    for dataset_dir, map_path in pairs:
        dataset = Dataset(dataset_dir)
        semantic_map = read_map(map_path)
        truth = ground_truth(dataset)
        result = evaluate(semantic_map, truth, int(dataset.meta["house"]), threshold)
        results.append(result)
        if picture_dir is not None:
            write_plan(picture_dir / f"{map_path.stem}_house{result.house:02d}.png",
                       draw_result(dataset, semantic_map, result, truth))
    doc = table(results)
    doc["rules"]["threshold"] = threshold
    return doc


def _round(v: float | None) -> float | None:
    return None if v is None else round(float(v), 4)


def _fmt(v: float | None) -> str:
    return "-" if v is None else f"{v:.3f}"

