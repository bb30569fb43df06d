"""The paper's own figures (``config/paper/*.tsv``, transcribed from its tables), read for the
side-by-side reports: Table 2 beside ``ravh dataset build``, Table 3 beside ``ravh eval semantic-map``."""
from __future__ import annotations

import csv
from pathlib import Path

from ravh_sim.paths import PAPER_DIR

TABLE2 = PAPER_DIR / "table2_captures.tsv"
TABLE3 = PAPER_DIR / "table3_semantic_maps.tsv"
RAID_COLUMNS = ("grid", "w1", "w2", "w3", "w4")      # Table 2's column of each raid preset 0-4


def read_tsv(path: str | Path) -> list[dict[str, str]]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f, delimiter="\t"))


def table2(path: str | Path = TABLE2) -> dict[int, dict[int, int]]:
    """Captures per house and raid preset (0: grid, 1-4: wanderer W1-W4)."""
    return {int(row["house"]): {raid: int(row[column]) for raid, column in enumerate(RAID_COLUMNS)}
            for row in read_tsv(path)}
