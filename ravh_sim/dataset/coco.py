"""``ravh dataset export DIR --format coco``: datasets as detectors train on them.

Writes, for every dataset folder under DIR (one raid, or a ``ravh dataset build`` root):

- ``OUT/instances.json``: COCO instance annotations, one per object seen in a capture (boxes, areas and
  RLE masks from pycocotools, so they agree with its evaluator to the pixel), our object types as
  categories, and per annotation ``attributes``: the object's room and room type, object id and
  instance id. Dressing objects (:mod:`ravh_sim.world.dressing`, ``kind: dressing``) are not annotated:
  the export keeps the paper's object list, as the evaluations do; the semantic images give them their
  own class ids (their types appended after the paper's, :data:`DRESSING_CLASSES`). Images point at
  the datasets' RGB files (``file_name`` relative to DIR).
- ``semantic/NNNNNN.png`` beside each dataset's ``mask/NNNNNN.png``: 8-bit semantic class ids per
  pixel (:data:`SEMANTIC_CLASSES`).

Class ids are one fixed table, not numbered per house or per export, so they mean the same in every
house and every export; a new type is appended, never inserted. COCO category ids are the same
numbers (objects only: structure is in the semantic images alone).
"""
from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ravh_sim.dataset import layout
from ravh_sim.dataset.api import Dataset
from ravh_sim.errors import UserError
from ravh_sim.files import encode_png

STRUCTURE_CLASSES = ("floor", "ceiling", "walls", "door", "window")
OBJECT_CLASSES = (
    "Armchair", "Bathtub", "Bed", "Brush", "Burner", "Cabinet", "Chair", "Closet", "Counter", "Cup",
    "Decoration", "Desk", "Dishwasher", "Dresser", "Drying", "Keyboard", "KitchenFurniture", "Lamp",
    "Laptop", "Light", "Lighter", "Microwave", "Mirror", "Nightstand", "Oven", "Picture", "Pouf",
    "Refrigerator", "Shelf", "ShowerCabin", "Sink", "Sofa", "Standard", "Station", "Stool", "Table",
    "Toilet", "Toothbrush", "Towel", "Tv", "Washbasin", "WashingMachine",
)
DRESSING_CLASSES = (
    "Plate", "Bowl", "FruitBowl", "Vase", "Pan", "Kettle", "Bottle", "DishRack", "Book", "Box", "Plant",
    "Pillow", "Duvet", "Cushion", "Throw", "Rug", "Curtain", "Blind",
)
"""The types of dressing objects (:mod:`ravh_sim.world.dressing`) that the paper's list lacks; dressing
cups, towels and pictures are the paper's Cup, Towel and Picture."""
SEMANTIC_CLASSES: dict[str, int] = {name: i for i, name in enumerate(
    ("nothing", *STRUCTURE_CLASSES, *OBJECT_CLASSES, *DRESSING_CLASSES))}
"""Class name -> id in the semantic images: 0 nothing, 1-5 structure, 6-47 object types, 48-65 the
dressing's own types."""
OBJECT_KINDS = ("object", "dressing")
"""Instance kinds whose semantic class is their type (the COCO annotations: ``kind: object`` alone)."""
SEMANTIC_DIR = "semantic"
INSTANCES_JSON = "instances.json"


def class_of(instance: dict[str, Any]) -> str:
    """The semantic class of a footprint instance: its object (or dressing object's) type, or its
    structure kind."""
    return instance["type"] if instance["kind"] in OBJECT_KINDS else instance["kind"]


def class_lookup(ds: Dataset) -> np.ndarray:
    """uint8 table: instance id -> semantic class id (unknown ids: 0)."""
    table = np.zeros(max(ds.instances, default=0) + 1, np.uint8)
    for i, row in ds.instances.items():
        name = class_of(row)
        if name not in SEMANTIC_CLASSES:
            raise UserError(f"{ds.dir}: instance {i} has type {name!r}, which has no semantic class id")
        table[i] = SEMANTIC_CLASSES[name]
    return table


def semantic_image(ids: np.ndarray, table: np.ndarray) -> np.ndarray:
    """(H, W) uint8 semantic class ids of an instance image, through :func:`class_lookup`'s table."""
    return np.where(ids < len(table), table[np.minimum(ids, len(table) - 1)], 0).astype(np.uint8)


def datasets_under(root: Path) -> list[Path]:
    """``root`` itself when it is a dataset, else every dataset folder below it (sorted)."""
    if (root / layout.DATASET_JSON).is_file():
        return [root]
    found = sorted(p.parent for p in root.rglob(layout.DATASET_JSON))
    if not found:
        raise UserError(f"{root}: no ravh_sim dataset (no {layout.DATASET_JSON}) in it or below it")
    return found


def export_coco(root: Path, out: Path, min_pixels: int = 1) -> dict[str, int]:
    """Write OUT/instances.json and the semantic images of every dataset under ``root``; returns
    counts of images, annotations and datasets."""
    from pycocotools import mask as mask_utils
    images: list[dict[str, Any]] = []
    annotations: list[dict[str, Any]] = []
    folders = datasets_under(root)
    for folder in folders:
        ds = Dataset(folder)
        table = class_lookup(ds)
        for sample in ds:
            image_id = len(images) + 1
            ids = sample.instance
            height, width = ids.shape
            semantic = semantic_image(ids, table)
            target = folder / SEMANTIC_DIR / sample.files["mask"].name
            target.parent.mkdir(exist_ok=True)
            layout.atomic_write(target, encode_png(semantic))
            images.append({"id": image_id, "file_name": str(sample.files["rgb"].relative_to(root)),
                           "width": width, "height": height,
                           "semantic_file": str(target.relative_to(root)),
                           "instance_file": str(sample.files["mask"].relative_to(root)),
                           "house": int(ds.meta["house"]), "index": sample.index, "stamp": sample.stamp,
                           "room": sample.room, "pose": list(sample.pose)})
            for instance_id in _objects(ds, ids, min_pixels):
                row = ds.instances[instance_id]
                rle = mask_utils.encode(np.asfortranarray(ids == instance_id, dtype=np.uint8))
                annotations.append({
                    "id": len(annotations) + 1, "image_id": image_id,
                    "category_id": SEMANTIC_CLASSES[row["type"]],
                    "segmentation": {"size": rle["size"], "counts": rle["counts"].decode("ascii")},
                    "area": float(mask_utils.area(rle)), "bbox": [float(v) for v in mask_utils.toBbox(rle)],
                    "iscrowd": 0,
                    "attributes": {"room": row["room"], "room_type": row["room_type"], "object_id": row["name"],
                                   "instance_id": instance_id}})
    categories = [{"id": SEMANTIC_CLASSES[name], "name": name, "supercategory": "object"}
                  for name in OBJECT_CLASSES]
    document = {"info": {"description": "ravh_sim captures (Robot@VirtualHome)", "format": "COCO instances",
                         "semantic_classes": SEMANTIC_CLASSES, "image_root": str(root.resolve())},
                "licenses": [], "images": images, "annotations": annotations, "categories": categories}
    out.mkdir(parents=True, exist_ok=True)
    layout.atomic_write(out / INSTANCES_JSON, json.dumps(document).encode())
    return {"datasets": len(folders), "images": len(images), "annotations": len(annotations)}


def _objects(ds: Dataset, ids: np.ndarray, min_pixels: int) -> Iterator[int]:
    """The instance id of every object covering at least ``min_pixels`` of the image."""
    counts = np.bincount(ids.ravel())
    for i in np.flatnonzero(counts >= min_pixels):
        row = ds.instances.get(int(i))
        if row is not None and row["kind"] == "object":
            yield int(i)
