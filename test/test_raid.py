"""Whole raids: sim, behaviour and recorder as real processes, checked through the dataset they leave."""
from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from rosgraph import NodeProcess, remove_orphan_shm, ros_env

from ravh_sim.dataset.api import Dataset
from ravh_sim.errors import UserError
from ravh_sim.nodes.common import SIM_LOST_S
from ravh_sim.raids.outcome import Outcome
from ravh_sim.raids.raid import PRESETS, _final_status, _rows, preset_settings, run_raid


@pytest.fixture
def raid_env(monkeypatch):
    for key, value in ros_env().items():
        monkeypatch.setenv(key, value)


def _log_tails(out: Path) -> str:
    return "\n".join(f"--- {log.name}\n{log.read_text()[-1500:]}" for log in sorted((out / "logs").glob("*.log")))


def _consistent(out: Path) -> Dataset:
    ds = Dataset(out)
    rows = (out / "captures.jsonl").read_text().splitlines()
    for folder in ("rgb", "depth", "mask", "scan"):
        assert len(list((out / folder).iterdir())) == len(rows) == len(ds), folder
    return ds


@pytest.mark.timeout(1800)
def test_wanderer_raid_visits_every_room_of_house_20(tmp_path, raid_env):
    out = tmp_path / "raid1"
    summary = run_raid(20, 1, out, fast=True, quiet=True)
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
    summary = run_raid(20, 0, out, fast=True, quiet=True, max_nodes=3)
    assert summary["status"] == "done" and summary["captures"] == 30
    ds = _consistent(out)
    poses = np.array([s.pose for s in ds])
    nodes = poses[::10, :2]
    for k in range(3):
        group = poses[10 * k:10 * (k + 1)]
        assert np.linalg.norm(group[:, :2] - group[0, :2], axis=1).max() < 0.1      # turning on the spot
        turns = np.sort((group[:, 2] - group[0, 2]) % (2 * math.pi))
        assert np.allclose(np.diff(turns), 2 * math.pi / 10, atol=math.radians(5))
    # lattice neighbours, distinct stops: the paper's node rule moves a point the robot cannot reach to the
    # nearest spot it can, so stops near walls lie closer than the 0.5 m lattice
    assert all(0.15 < d < 1.2 for d in np.linalg.norm(np.diff(nodes, axis=0), axis=1))


def test_presets_follow_the_paper():
    assert [p.behaviour for p in PRESETS] == ["grid"] + ["wanderer"] * 4
    assert [p.sun for p in PRESETS] == ["day", "day", "day", "sunset", "night"]
    s = preset_settings(PRESETS[4], 7)
    assert s["lights"] == {"sun_angle": "night", "ceiling": "on", "lamps": "random"}
    assert s["paint"] == {"walls": "random", "floors": "random"} and s["models"] == {"all": "random"}


# ------------------------------------------------------------------ nothing lost, nothing half-written

@pytest.fixture
def overload():
    """4 busy-loop processes: on a 2-core machine every raid process gets well under half a core."""
    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(4)]
    yield
    for proc in busy:
        proc.kill()
        proc.wait()


@pytest.mark.timeout(1800)
def test_no_capture_lost_under_cpu_overload(tmp_path, raid_env, overload):
    out = tmp_path / "raid0"
    summary = run_raid(20, 0, out, fast=True, quiet=True, max_nodes=2)
    assert summary["status"] == "done", _log_tails(out)
    assert summary["captures"] == summary["requested"] == 20
    assert len(_consistent(out)) == 20


def test_a_raid_folder_must_be_new(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(UserError, match="not empty"):
        run_raid(20, 1, tmp_path, quiet=True)
    assert [p.name for p in tmp_path.iterdir()] == ["notes.txt"]


def test_an_unwritable_raid_folder_is_one_line():
    with pytest.raises(UserError, match=r"^/proc/ravh_raid.*cannot write the raid"):
        run_raid(20, 1, Path("/proc/ravh_raid/out"), quiet=True)


class _Exited:
    def __init__(self, code: int) -> None:
        self.returncode = code


@pytest.mark.parametrize("status, requested, recorded, behaviour, recorder, expected", [
    ("done", 30, 30, 0, 0, "done"),
    ("done", 30, 27, 0, 0, "lost 3 of 30 captures (see logs/)"),
    ("stopped at 5 captures", 6, 5, 0, 0, "lost 1 of 6 captures (see logs/)"),
    ("done", 30, 30, 2, 0, "behaviour exited with 2 (see logs/behaviour.log)"),
    ("done", 30, 30, 0, 1, "recorder exited with 1 (see logs/recorder.log)"),
    ("interrupted (Ctrl-C)", 3, 3, 0, 0, "interrupted (Ctrl-C)"),
    ("interrupted (Ctrl-C)", 3, 2, 0, 0, "interrupted (Ctrl-C); lost 1 of 3 captures (see logs/)"),
])
def test_a_raid_is_done_only_when_nothing_was_lost(status, requested, recorded, behaviour, recorder, expected):
    assert _final_status(status, requested, recorded, _Exited(behaviour), _Exited(recorder)) == expected


def test_every_status_sentence_reads_back_as_its_outcome():
    details = {"captures": 5, "limit": "600 s", "name": "sim", "code": 2, "lost": 1, "requested": 3}
    for outcome in Outcome:
        assert Outcome.of(outcome.status(**details)) is outcome
    assert Outcome.of("interrupted (Ctrl-C); lost 1 of 3 captures (see logs/)") is Outcome.INTERRUPTED
    assert Outcome.of("timed out after 3600 sim s") is Outcome.TIMED_OUT                 # the direct engine's
    assert [o for o in Outcome if o.complete] == [Outcome.DONE, Outcome.STOPPED]
    with pytest.raises(ValueError, match="not a raid status"):
        Outcome.of("finished")


def test_behaviour_and_recorder_stop_when_the_sim_goes(tmp_path):
    sim = NodeProcess("sim", "--house", "20", "--camera-rate", "0", "--rtf", "0")
    recorder = NodeProcess("recorder", "--out", str(tmp_path / "ds"), "--no-bag")
    behaviour = NodeProcess("wanderer", "--wait-recorder", "--capture-period", "2.0")
    try:
        end = time.monotonic() + 180
        while "capture 1 " not in behaviour.log() and time.monotonic() < end and behaviour.alive():
            time.sleep(0.5)
        assert "capture 1 " in behaviour.log(), behaviour.log()[-2000:] + sim.log()[-2000:]
        assert sim.stop() == 0
        gone = time.monotonic()
        for proc in (behaviour, recorder):          # they notice after SIM_LOST_S without /clock; the bound
            while proc.alive() and time.monotonic() - gone < SIM_LOST_S + 120:   # only catches a hang
                time.sleep(0.2)
            assert not proc.alive(), proc.log()[-2000:]
    finally:
        for proc in (behaviour, recorder, sim):
            proc.stop()
    for proc in (behaviour, recorder):
        assert proc.proc.returncode != 0 and "lost the sim" in proc.log(), proc.log()[-2000:]
    assert (tmp_path / "ds" / "captures.jsonl").read_text().count("\n") >= 1


@pytest.mark.timeout(1800)
def test_same_seed_same_raid(tmp_path, raid_env):
    """Lockstep raids depend on sim time alone: same seed -> same stamps, poses and image bytes."""
    outs = [tmp_path / "first", tmp_path / "second"]
    for out in outs:
        summary = run_raid(20, 0, out, fast=True, quiet=True, max_nodes=2)
        assert summary["status"] == "done" and summary["captures"] == 20, _log_tails(out)
    first, second = (_consistent(out) for out in outs)
    rows = [[json.loads(line) for line in (out / "captures.jsonl").read_text().splitlines()] for out in outs]
    motion = [[(r["stamp"], r["pose"], r["odom"]) for r in run] for run in rows]
    assert motion[0] == motion[1]
    for a, b in zip(rows[0], rows[1]):
        for kind in ("rgb", "depth", "mask", "scan"):
            assert (outs[0] / a["files"][kind]).read_bytes() == (outs[1] / b["files"][kind]).read_bytes(), kind


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


def test_ctrl_c_ends_a_raid_with_its_summary(tmp_path):
    """Ctrl-C in a terminal reaches the raid and its processes (one process group), pressed again and again
    here until the raid exits: the raid still stops every process, prints its summary, writes raid.json, exits
    with its own status (not killed by a press landing while Python shuts down) and leaves a readable dataset."""
    out = tmp_path / "raid"
    raid = subprocess.Popen([sys.executable, "-m", "ravh_sim.cli", "raid", "--house", "20", "--raid", "1", "--fast",
                             "--out", str(out)], env=ros_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    try:
        end = time.monotonic() + 300
        while len(_rows(out / "captures.jsonl")) < 3 and raid.poll() is None and time.monotonic() < end:
            time.sleep(0.5)
        assert len(_rows(out / "captures.jsonl")) >= 3 and raid.poll() is None, _log_tails(out)
        end = time.monotonic() + 120
        while raid.poll() is None and time.monotonic() < end:   # later presses land while the raid winds
            os.killpg(raid.pid, signal.SIGINT)                  # down, writes its summary and exits
            time.sleep(0.05)
        stdout, stderr = raid.communicate(timeout=10)
    finally:
        if _group_alive(raid.pid):
            os.killpg(raid.pid, signal.SIGKILL)
    assert raid.returncode == 1, stderr[-3000:] + _log_tails(out)
    assert not _group_alive(raid.pid), "a raid process outlived the raid"
    printed = json.loads(stdout)
    saved = json.loads((out / "raid.json").read_text())
    assert printed == saved and saved["status"] == "interrupted (Ctrl-C)", (saved, _log_tails(out))
    assert "Traceback" not in stderr + _log_tails(out), stderr[-3000:] + _log_tails(out)
    # every capture the behaviour was answered for is stored; one answered while Ctrl-C stopped the
    # behaviour is stored too, though the behaviour, stopped, never logged its answer
    assert saved["captures"] == len(_consistent(out)) >= saved["requested"] >= 3


# Runs a command with writes past N bytes per file failing (EFBIG), as on a full disk; its children inherit it.
FILE_SIZE_LIMITED = ("import os, resource, sys\n"
                     "resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), resource.getrlimit("
                     "resource.RLIMIT_FSIZE)[1]))\n"
                     "os.execv(sys.executable, [sys.executable, *sys.argv[2:]])\n")


def test_a_full_disk_ends_a_raid_with_one_line_and_its_summary(tmp_path):
    """Images and the bag do not fit (200 kB per file), small files do: the recorder ends with one line,
    the raid says which process stopped, and nothing half-written or temporary is left in the dataset."""
    out = tmp_path / "raid"
    started = time.time()
    try:
        raid = subprocess.run([sys.executable, "-c", FILE_SIZE_LIMITED, "200000", "-m", "ravh_sim.cli", "raid",
                               "--house", "20", "--raid", "1", "--fast", "--out", str(out)],
                              env=ros_env(), capture_output=True, text=True, timeout=300)
    finally:
        # The limit holds for /dev/shm too: each process's Fast DDS segment stops at 1 byte and stays there
        # (Fast DDS falls back to UDP).
        remove_orphan_shm(started)
    assert raid.returncode == 1, raid.stderr[-3000:] + _log_tails(out)
    saved = json.loads((out / "raid.json").read_text())
    assert json.loads(raid.stdout) == saved
    assert saved["status"] == "the recorder stopped with exit status 2 (see logs/recorder.log)", _log_tails(out)
    log = (out / "logs" / "recorder.log").read_text()
    assert "Traceback" not in log and log.rstrip().splitlines()[-1] == "ravh: error: File too large", log[-3000:]
    dataset_files = [p for p in out.rglob("*") if p.is_file() and "logs" not in p.parts and "bag" not in p.parts]
    assert [p.name for p in dataset_files if p.name.startswith(".")] == []
    assert [p.name for p in dataset_files if p.stat().st_size == 0] in ([], ["captures.jsonl"])
    assert len(Dataset(out)) == saved["captures"]
