"""Whole raids: sim, behaviour and recorder as real processes, checked through the dataset they leave."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from rosgraph import ros_env

from ravh_sim.dataset.api import Dataset
from ravh_sim.dataset.raid import PRESETS, preset_settings, run_raid


@pytest.fixture
def raid_env(monkeypatch):
    for key, value in ros_env().items():
        monkeypatch.setenv(key, value)


def _consistent(out: Path) -> Dataset:
    ds = Dataset(out)
    rows = (out / "captures.jsonl").read_text().splitlines()
    for folder in ("rgb", "depth", "mask", "scan"):
        assert len(list((out / folder).iterdir())) == len(rows) == len(ds), folder
    return ds


def test_wanderer_raid_visits_every_room_of_house_20(tmp_path, raid_env):
    out = tmp_path / "raid1"
    summary = run_raid(20, 1, out, fast=True, quiet=True, timeout=400)
    assert summary["status"] == "done", (out / "logs" / "sim.log").read_text()[-2000:]
    ds = _consistent(out)
    assert set(summary["rooms_visited"]) == {"Bathroom_1", "Bedroom_1", "KitchenLivingRoom_1"}
    assert set(ds.rooms_visited()) == set(summary["rooms_visited"])
    log = [json.loads(line) for line in (out / "logs" / "behaviour_captures.jsonl").read_text().splitlines()]
    assert len(log) == len(ds)                               # the behaviour logged every capture
    sample = ds[len(ds) // 2]
    assert sample.rgb.shape == (480, 640, 3) and np.isfinite(sample.depth).any()
    assert json.loads((out / "dataset.json").read_text())["raid"]["preset"]["behaviour"] == "wanderer"


def test_grid_raid_turns_ten_captures_per_node(tmp_path, raid_env):
    out = tmp_path / "raid0"
    summary = run_raid(20, 0, out, fast=True, quiet=True, max_nodes=3, timeout=300)
    assert summary["status"] == "done" and summary["captures"] == 30
    ds = _consistent(out)
    poses = np.array([s.pose for s in ds])
    nodes = poses[::10, :2]
    for k in range(3):
        group = poses[10 * k:10 * (k + 1)]
        assert np.linalg.norm(group[:, :2] - group[0, :2], axis=1).max() < 0.1      # turning on the spot
        turns = np.sort((group[:, 2] - group[0, 2]) % (2 * math.pi))
        assert np.allclose(np.diff(turns), 2 * math.pi / 10, atol=math.radians(5))
    assert all(0.3 < d < 1.2 for d in np.linalg.norm(np.diff(nodes, axis=0), axis=1))  # lattice neighbours


def test_presets_follow_the_paper():
    assert [p.behaviour for p in PRESETS] == ["grid"] + ["wanderer"] * 4
    assert [p.sun for p in PRESETS] == ["day", "day", "day", "sunset", "night"]
    s = preset_settings(PRESETS[4], 7)
    assert s["lights"] == {"sun_angle": "night", "ceiling": "on", "lamps": "random"}
    assert s["paint"] == {"walls": "random", "floors": "random"} and s["models"] == {"all": "random"}
