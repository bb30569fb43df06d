"""Reference mappers, run from a dataset's files: an oracle and a seeded degraded oracle.

Both detect from the stored instance masks and build the map with the same fusion as a user's
detector (:mod:`ravh_sim.eval.fusion`), so they exercise the whole pipeline:

* ``oracle``: every object instance covering at least :data:`~ravh_sim.dataset.api.MIN_PIXELS`
  pixels of a capture is a detection with its true type and exact mask. Its precision and recall
  check the fusion and the evaluation themselves (they should be near 1).
* ``degraded``: the oracle with a detector's typical errors, each drawn once per object from the
  seed (so an object is consistently missed or mislabelled, as a real detector tends to be):
  missed objects, label confusion (another type present in the house), merging of nearby objects
  of the same type into one detection (a box over several chairs), and noise on the final boxes'
  centres and sizes. :class:`Degradation` holds the rates; each can be set to 0 to see its effect.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ravh_sim.dataset.api import MIN_PIXELS, Dataset, Sample
from ravh_sim.errors import UserError
from ravh_sim.eval.fusion import Detection, build_map
from ravh_sim.eval.semantic_map import SemanticMap, float3

Detector = Callable[[Sample], list[Detection]]


@dataclass(frozen=True)
class Degradation:
    miss: float = 0.15              # share of objects never detected
    confuse: float = 0.10           # share of objects detected under another type
    merge_radius: float = 0.8       # m: same-type objects whose centres are this close merge
    center_sigma: float = 0.05      # m, Gaussian noise on each box centre (x, y, z)
    size_sigma: float = 0.10        # log-normal sigma on each box side


def visible_objects(dataset: Dataset, sample: Sample) -> list[int]:
    """Ids of the object instances covering at least MIN_PIXELS of ``sample``."""
    pixels = np.bincount(sample.instance.ravel())
    return [int(i) for i in np.flatnonzero(pixels >= MIN_PIXELS)
            if dataset.instances.get(int(i), {}).get("kind") == "object"]


def oracle_detector(dataset: Dataset) -> Detector:
    def detect(sample: Sample) -> list[Detection]:
        ids = sample.instance
        return [Detection(dataset.instances[i]["type"], ids == i) for i in visible_objects(dataset, sample)]
    return detect


def degraded_detector(dataset: Dataset, seed: int, errors: Degradation) -> Detector:
    """The oracle detector after the per-object misses, confusions and merges of ``errors``."""
    rng = np.random.default_rng([seed, 14])
    objects = sorted(i for i, r in dataset.instances.items() if r["kind"] == "object")
    types = sorted({dataset.instances[i]["type"] for i in objects})
    group = _merge_groups(dataset, objects, errors.merge_radius)
    label: dict[int, str | None] = {}
    for i in objects:                                   # one draw per object, in id order
        missed, confused, other = rng.random(), rng.random(), rng.integers(len(types))
        true = dataset.instances[i]["type"]
        wrong = [t for t in types if t != true]
        label[i] = (None if missed < errors.miss
                    else wrong[other % len(wrong)] if confused < errors.confuse and wrong else true)
    reported = {i: t for i, t in label.items() if t is not None}       # the label of each object not missed

    def detect(sample: Sample) -> list[Detection]:
        masks: dict[int, np.ndarray] = {}
        for i in visible_objects(dataset, sample):
            if group[i] in reported:
                hit = sample.instance == i
                masks[group[i]] = masks[group[i]] | hit if group[i] in masks else hit
        return [Detection(reported[g], mask) for g, mask in masks.items()]
    return detect


def _merge_groups(dataset: Dataset, objects: list[int], radius: float) -> dict[int, int]:
    """Object id -> the smallest id of its group: same-type objects chained within ``radius``."""
    group = {i: i for i in objects}

    def root(i: int) -> int:
        while group[i] != i:
            i = group[i]
        return i

    for a in objects:
        for b in objects:
            ra, rb = dataset.instances[a], dataset.instances[b]
            if a < b and ra["type"] == rb["type"] and math.dist(ra["position"], rb["position"]) <= radius:
                group[max(root(a), root(b))] = min(root(a), root(b))
    return {i: root(i) for i in objects}


def perturb(semantic_map: SemanticMap, seed: int, errors: Degradation) -> SemanticMap:
    """Noise on every box's centre and sides (seeded)."""
    rng = np.random.default_rng([seed, 15])
    boxes = []
    for b in semantic_map.boxes:
        shift = rng.normal(0.0, errors.center_sigma, 3)
        scale = np.exp(rng.normal(0.0, errors.size_sigma, 3))
        boxes.append(replace(b, center=float3(np.add(b.center, shift)), size=float3(np.multiply(b.size, scale))))
    return SemanticMap(semantic_map.house, boxes, semantic_map.detections)


MAPPERS = ("oracle", "degraded")


def run_mapper(dataset: Dataset, mapper: str, seed: int = 0, errors: Degradation | None = None) -> SemanticMap:
    """The semantic map of ``dataset`` by a reference mapper (one of :data:`MAPPERS`)."""
    if mapper == "oracle":
        return build_map(dataset, oracle_detector(dataset))
    if mapper == "degraded":
        errors = errors or Degradation()
        return perturb(build_map(dataset, degraded_detector(dataset, seed, errors)), seed, errors)
    raise UserError(f"unknown mapper {mapper!r}; valid: {', '.join(MAPPERS)}")
