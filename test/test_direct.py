"""The direct engine: one process, deterministic, the dataset format the reader expects."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from ravh_sim.dataset.api import Dataset
from ravh_sim.errors import UserError
from ravh_sim.raids.direct import GridSpec, PosesSpec, WandererSpec, record

SMALL_GRID = GridSpec(max_nodes=1, captures_per_node=4)


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_same_seed_gives_a_byte_identical_dataset(tmp_path):
    settings = {"lights": {"sun_angle": "sunset", "lamps": "random"}, "paint": {"walls": "random"}}
    a = record(tmp_path / "a", 20, SMALL_GRID, settings=settings, seed=11)
    b = record(tmp_path / "b", 20, SMALL_GRID, settings=settings, seed=11)
    assert a["status"] == b["status"] == "done" and a["captures"] == 4
    files_a, files_b = _files(tmp_path / "a"), _files(tmp_path / "b")
    assert files_a.keys() == files_b.keys()
    timing = {"dataset.json", "raid.json"}                  # when it ran and how long it took
    assert len(files_a) > 4 * 4 + len(timing)
    for name in files_a.keys() - timing:
        assert files_a[name] == files_b[name], name
    meta_a, meta_b = (json.loads(files[n]) for files in (files_a, files_b) for n in ["dataset.json"])
    meta_a.pop("created"), meta_b.pop("created")
    assert meta_a == meta_b
    other = record(tmp_path / "c", 20, SMALL_GRID, settings=settings, seed=12)
    assert _files(tmp_path / "c")["rgb/000000.png"] != files_a["rgb/000000.png"]   # the seed matters
    assert other["captures"] == 4


def test_grid_raid_reads_back_through_the_dataset_api(tmp_path):
    summary = record(tmp_path / "g", 20, SMALL_GRID, raid={"purpose": "test"})
    ds = Dataset(tmp_path / "g")
    assert len(ds) == summary["captures"] == 4
    assert ds.meta["raid"]["engine"] == "direct" and ds.meta["raid"]["purpose"] == "test"
    poses = np.array([s.pose for s in ds])
    assert np.linalg.norm(poses[:, :2] - poses[0, :2], axis=1).max() < 0.1          # one node, turning
    turns = np.sort((poses[:, 2] - poses[0, 2]) % (2 * math.pi))
    assert np.allclose(np.diff(turns), math.pi / 2, atol=math.radians(5))
    sample = ds[0]
    assert sample.rgb.shape == (480, 640, 3) and np.isfinite(sample.depth).any()
    assert sample.room == "KitchenLivingRoom_1" and sample.room_type is not None
    assert len(sample.scan.ranges) == 360 and ds.map is not None
    assert ds.camera["robot"]["width"] == 640 and ds.settings.seed == summary["seed"]


def test_scripted_poses_are_captured_where_asked(tmp_path):
    poses = ((-3.0, 1.6, 0.0), (-2.6, 1.2, -math.pi / 2))
    ds_dir = tmp_path / "p"
    summary = record(ds_dir, 20, PosesSpec(poses))
    ds = Dataset(ds_dir)
    assert summary["captures"] == 2
    for sample, pose in zip(ds, poses):
        assert np.allclose(sample.pose, pose, atol=1e-3)
    assert ds[1].stamp > ds[0].stamp                          # sim time advances between poses
    assert not np.array_equal(ds[0].rgb, ds[1].rgb)


def test_max_captures_stops_a_wanderer_early(tmp_path):
    summary = record(tmp_path / "w", 20, WandererSpec(capture_period=0.25), max_captures=3)
    assert summary["status"] == "stopped at 3 captures" and len(Dataset(tmp_path / "w")) == 3


def test_bad_requests_are_clear_errors(tmp_path):
    with pytest.raises(UserError, match="unknown behaviour"):
        record(tmp_path / "x", 20, "dance")
    with pytest.raises(UserError, match="order"):
        record(tmp_path / "y", 20, WandererSpec(order="sideways"))
    record(tmp_path / "z", 20, PosesSpec(((-3.0, 1.6, 0.0),)), settings={"seed": 4})
    kept = {name: (tmp_path / "z" / name).read_bytes() for name in ("raid_settings.yaml", "captures.jsonl")}
    with pytest.raises(UserError, match="already holds"):
        record(tmp_path / "z", 20, PosesSpec(((-3.0, 1.6, 0.0),)), settings={"seed": 5})
    assert kept == {name: (tmp_path / "z" / name).read_bytes() for name in kept}      # nothing lost


# ---------------------------------------------------------------------------- against the ROS engine

@pytest.fixture(scope="module")
def ros_grid_raid(tmp_path_factory):
    """One small grid raid (one node, ten captures) through the ROS engine's three processes."""
    from rosgraph import ros_env

    from ravh_sim.raids.raid import run_raid
    out = tmp_path_factory.mktemp("ros") / "raid0"
    with pytest.MonkeyPatch.context() as mp:
        for key, value in ros_env().items():
            mp.setenv(key, value)
        summary = run_raid(20, 0, out, fast=True, quiet=True, max_nodes=1, timeout=300)
    assert summary["status"] == "done", (out / "logs" / "sim.log").read_text()[-2000:]
    return summary, out


def test_both_engines_write_datasets_the_api_reads_the_same_way(tmp_path, ros_grid_raid):
    from ravh_sim.raids.raid import PRESETS, preset_settings
    ros_summary, ros_dir = ros_grid_raid
    seed = ros_summary["seed"]
    direct = record(tmp_path / "direct", 20, GridSpec(max_nodes=1), settings=preset_settings(PRESETS[0], seed),
                    seed=seed)
    ros, ours = Dataset(ros_dir), Dataset(tmp_path / "direct")
    assert len(ours) == direct["captures"] == 10
    assert 0 < len(ros) == ros_summary["captures"] <= 10      # on a loaded machine the recorder may drop one
    assert ours.footprint == ros.footprint and ours.settings == ros.settings
    assert ours.camera == ros.camera
    assert np.array_equal(ours.map.data, ros.map.data) and ours.map.origin == pytest.approx(ros.map.origin)
    assert ours.map.resolution == pytest.approx(ros.map.resolution)
    assert ours.meta.keys() == ros.meta.keys() and ours.meta["house"] == ros.meta["house"] == 20
    assert ours.rooms_visited() == ros.rooms_visited()
    for a, b in zip(ours, ros):
        assert (a.index, a.agent, a.room, a.room_type) == (b.index, b.agent, b.room, b.room_type)
        assert np.allclose(a.pose[:2], b.pose[:2], atol=0.1)               # the same node, turning
        assert a.files.keys() == b.files.keys()
        assert a.rgb.shape == b.rgb.shape and a.depth.dtype == b.depth.dtype and a.instance.dtype == b.instance.dtype
        assert (a.scan.range_min, a.scan.range_max) == (b.scan.range_min, b.scan.range_max)
        assert np.allclose(a.scan.angles, b.scan.angles)
    assert ours.objects_in(ours[0]).keys() <= {r["type"] for r in ours.instances.values()}


def test_the_same_poses_give_the_same_images_in_both_engines(tmp_path, ros_grid_raid):
    """Replay the ROS raid's recorded poses with the direct engine: every image is identical
    (colour, depth and instances; the camera sees only the pose and the world's settings)."""
    from ravh_sim.raids.raid import PRESETS, preset_settings
    ros_summary, ros_dir = ros_grid_raid
    ros = Dataset(ros_dir)
    poses = tuple(s.pose for s in ros)
    record(tmp_path / "replay", 20, PosesSpec(poses), settings=preset_settings(PRESETS[0], ros_summary["seed"]),
           seed=ros_summary["seed"])
    replay = Dataset(tmp_path / "replay")
    assert len(replay) == len(ros) > 0
    for a, b in zip(replay, ros):
        assert a.pose == b.pose
        assert np.array_equal(a.rgb, b.rgb) and np.array_equal(a.instance, b.instance)
        assert np.array_equal(a.depth, b.depth, equal_nan=True)
