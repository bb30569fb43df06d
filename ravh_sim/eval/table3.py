"""Table 3 in the paper's protocol: one wanderer raid with a random appearance per house, mapped by our
reference mappers and set beside the paper's row (``ravh eval semantic-map --paper-protocol``).

The paper fused Detectron2 detections with ViMantic during one wanderer raid per house, with random
appearance. Here each house is recorded once with the direct engine (a wanderer round through every
room; sun, ceiling lights, lamps, paint and object models all drawn from the seed) into
``OUT/houseNN`` (reused when a finished recording is there), and each mapper's map is built from it and
evaluated like any other (:mod:`ravh_sim.eval.semantic_eval`).
"""
from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ravh_sim.eval.semantic_eval import DEFAULT_THRESHOLD, evaluate_datasets, format_beside_paper, format_table
from ravh_sim.eval.semantic_map import write_map
from ravh_sim.paper import TABLE3, read_tsv
from ravh_sim.raids.build import clear_unfinished, finished

RANDOM_APPEARANCE = {"lights": {"sun_angle": "random", "ceiling": "random", "lamps": "random"},
                     "paint": {"walls": "random", "floors": "random"}, "models": {"all": "random"}}


def record_house(house: int, out: Path, seed: int) -> Path:
    """The protocol's raid of ``house`` under ``out`` (recorded unless a finished one is there)."""
    from ravh_sim.raids.direct import WandererSpec, record
    folder = out / f"house{house:02d}"
    if finished(folder) is None:
        clear_unfinished(folder)
        record(folder, house, WandererSpec(order="once", seed=seed), settings=RANDOM_APPEARANCE,
               seed=house * 10 + seed * 1000, raid={"protocol": "table3", "appearance": "random"})
    return folder


def run_protocol(houses: list[int], out: Path, mappers: list[str], seed: int = 0,
                 threshold: float = DEFAULT_THRESHOLD, paper_path: Path = TABLE3,
                 progress: Callable[[str], None] = lambda text: None) -> dict[str, Any]:
    """Record, map and evaluate every house; writes OUT/table3_<mapper>.json and .txt (per house and type:
    boxes, correct, detectable, found, ...) and OUT/table3_paper.txt (beside the paper) and returns
    {mapper: Table 3 document}."""
    from ravh_sim.dataset.api import Dataset
    from ravh_sim.eval.mappers import run_mapper
    out.mkdir(parents=True, exist_ok=True)
    folders = {}
    for house in houses:
        progress(f"house {house}: recording a wanderer raid with a random appearance")
        folders[house] = record_house(house, out, seed)
    docs: dict[str, Any] = {}
    paper = {int(row["house"]): row for row in read_tsv(paper_path)}
    text = []
    for mapper in mappers:
        pairs = []
        for house, folder in folders.items():
            progress(f"house {house}: {mapper} map")
            map_path = out / "maps" / f"{mapper}_house{house:02d}.json"
            write_map(run_mapper(Dataset(folder), mapper, seed), map_path)
            pairs.append((folder, map_path))
        doc = evaluate_datasets(pairs, threshold, out / "maps")
        doc["protocol"] = {"raid": "one wanderer round", "appearance": RANDOM_APPEARANCE, "seed": seed}
        (out / f"table3_{mapper}.json").write_text(json.dumps(doc, indent=1) + "\n")
        (out / f"table3_{mapper}.txt").write_text(format_table(doc) + "\n")
        docs[mapper] = doc
        text.append(format_beside_paper(doc, paper, mapper))
    (out / "table3_paper.txt").write_text("\n\n".join(text) + "\n")
    return docs
