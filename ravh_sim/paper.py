"""The paper's own figures (``config/paper/*.tsv``, transcribed from its tables), read for the
side-by-side reports: Table 2 beside ``ravh dataset build``, Table 3 beside ``ravh eval semantic-map``,
Table 4 beside ``ravh eval localization``. These files are the one copy of the paper's numbers: code
reads them, it never repeats them."""
from __future__ import annotations

import csv
from pathlib import Path

from ravh_sim.paths import PAPER_DIR

TABLE2 = PAPER_DIR / "table2_captures.tsv"
TABLE3 = PAPER_DIR / "table3_semantic_maps.tsv"
TABLE4 = PAPER_DIR / "table4_localization.tsv"
TABLE4_METHOD = "PSAC over NetVLAD"                 # what produced Table 4's cells (config/paper/README.md)
RAID_COLUMNS = ("grid", "w1", "w2", "w3", "w4")      # Table 2's column of each raid preset 0-4


def read_tsv(path: str | Path) -> list[dict[str, str]]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f, delimiter="\t"))


def table2(path: str | Path = TABLE2) -> dict[int, dict[int, int]]:
    """Captures per house and raid preset (0: grid, 1-4: wanderer W1-W4)."""
    return {int(row["house"]): {raid: int(row[column]) for raid, column in enumerate(RAID_COLUMNS)}
            for row in read_tsv(path)}


def table4(path: str | Path = TABLE4) -> dict[tuple[str, str], tuple[float, float]]:
    """Median position (m) and rotation (deg) error per (route, map), each named as ravh_sim's
    lightings are: the lighting and its sun angle l_a, e.g. ("night 195", "day 170")."""
    return {(f"{row['route']} {float(row['route_sun_deg']):g}", f"{row['map']} {float(row['map_sun_deg']):g}"):
            (float(row["median_position_m"]), float(row["median_rotation_deg"])) for row in read_tsv(path)}
