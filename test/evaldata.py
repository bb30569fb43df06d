"""Small datasets for the evaluation tests, recorded once per test session with the direct engine."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

# House 20's kitchen-living room: two spots, six headings each (chairs, table, sofa, kitchen in view).
SPOTS = ((-4.3, -0.2), (-2.7, 0.7))
HEADINGS = 6

_recorded: dict[str, Path] = {}


def small_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 12-capture dataset of house 20 (day light), shared by every test that asks for it."""
    if "small" not in _recorded:
        from ravh_sim.raids.direct import PosesSpec, record
        poses = tuple((x, y, 2 * math.pi * k / HEADINGS) for x, y in SPOTS for k in range(HEADINGS))
        out = tmp_path_factory.mktemp("eval") / "h20_small"
        record(out, 20, PosesSpec(poses), seed=5)
        _recorded["small"] = out
    return _recorded["small"]
