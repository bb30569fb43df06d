"""``ravh dataset export --format coco``: pycocotools reads the export back, masks equal to ours."""
from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from evaldata import small_dataset

from ravh_sim.cli import main
from ravh_sim.dataset.api import Dataset
from ravh_sim.dataset.coco import OBJECT_CLASSES, SEMANTIC_CLASSES, class_of
from ravh_sim.files import read_png


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    root = tmp_path_factory.mktemp("coco") / "build"
    shutil.copytree(small_dataset(tmp_path_factory), root / "house20" / "raid9")   # a build root of one raid
    assert main(["dataset", "export", str(root), "--format", "coco"]) == 0
    return root, Dataset(root / "house20" / "raid9")


def test_pycocotools_reads_the_export_back_with_our_masks(exported):
    from pycocotools.coco import COCO
    root, ds = exported
    coco = COCO(str(root / "coco" / "instances.json"))
    assert len(coco.getImgIds()) == len(ds) == 12
    assert {c["name"] for c in coco.loadCats(coco.getCatIds())} == set(OBJECT_CLASSES)
    checked = 0
    for image in coco.loadImgs(coco.getImgIds()):
        sample = ds[image["index"]]
        assert image["file_name"] == "house20/raid9/rgb/%06d.png" % sample.index
        assert (root / image["file_name"]).is_file() and (image["height"], image["width"]) == sample.instance.shape
        anns = coco.loadAnns(coco.getAnnIds(imgIds=image["id"]))
        ids = sample.instance
        objects = {i for i in np.unique(ids) if ds.instances.get(int(i), {}).get("kind") == "object"}
        assert {a["attributes"]["instance_id"] for a in anns} == objects and objects
        for a in anns:
            row = ds.instances[a["attributes"]["instance_id"]]
            mask = coco.annToMask(a)
            assert np.array_equal(mask.astype(bool), ids == a["attributes"]["instance_id"])
            assert coco.loadCats(a["category_id"])[0]["name"] == row["type"]
            assert a["attributes"]["room"] == row["room"] and a["area"] == mask.sum()
            rows, cols = np.nonzero(mask)
            assert a["bbox"] == [cols.min(), rows.min(), cols.max() - cols.min() + 1, rows.max() - rows.min() + 1]
            checked += 1
    assert checked > 20


def test_pycocotools_evaluates_the_ground_truth_as_perfect_detections(exported):
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval
    root, _ = exported
    gt = COCO(str(root / "coco" / "instances.json"))
    results = [{"image_id": a["image_id"], "category_id": a["category_id"], "segmentation": a["segmentation"],
                "score": 1.0} for a in gt.dataset["annotations"]]
    for kind in ("segm", "bbox"):
        if kind == "bbox":
            results = [{**r, "bbox": a["bbox"]} for r, a in zip(results, gt.dataset["annotations"])]
            for r in results:
                del r["segmentation"]
        evaluator = COCOeval(gt, gt.loadRes(results), kind)
        evaluator.evaluate(), evaluator.accumulate()
        evaluator.summarize()
        assert evaluator.stats[1] == pytest.approx(1.0)          # AP at IoU 0.5
    half = results[::2]                                          # half the boxes: recall drops
    evaluator = COCOeval(gt, gt.loadRes(half), "bbox")
    evaluator.evaluate(), evaluator.accumulate(), evaluator.summarize()
    assert evaluator.stats[8] < 0.9                              # AR@100


def test_semantic_images_lie_beside_the_instance_images_with_stable_ids(exported):
    root, ds = exported
    info = json.loads((root / "coco" / "instances.json").read_text())["info"]
    assert info["semantic_classes"] == SEMANTIC_CLASSES
    # ids are fixed, not numbered per house: a few pinned here so a reordering fails
    assert (SEMANTIC_CLASSES["nothing"], SEMANTIC_CLASSES["floor"], SEMANTIC_CLASSES["window"]) == (0, 1, 5)
    assert (SEMANTIC_CLASSES["Armchair"], SEMANTIC_CLASSES["Bed"], SEMANTIC_CLASSES["WashingMachine"]) == (6, 8, 47)
    for sample in ds:
        semantic = read_png(root / "house20" / "raid9" / "semantic" / sample.files["mask"].name)
        assert semantic.dtype == np.uint8 and semantic.shape == sample.instance.shape
        for i in np.unique(sample.instance):
            expected = SEMANTIC_CLASSES[class_of(ds.instances[int(i)])] if i else 0
            assert np.all(semantic[sample.instance == i] == expected)


def test_every_type_of_every_house_has_a_class(houses):
    from ravh_sim.world.footprint import build_instances
    for house in houses.values():
        for inst in build_instances(house):
            name = inst.type if inst.kind == "object" else inst.kind
            assert name in SEMANTIC_CLASSES, (house.number, inst.name)
