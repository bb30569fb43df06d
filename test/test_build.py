"""``ravh dataset build``: many raids, resumable, on a process pool or a real two-node Ray cluster."""
from __future__ import annotations

import json
import os
import secrets
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml
from conftest import ROOT, subprocess_env

import ravh_sim
from ravh_sim.dataset.api import Dataset
from ravh_sim.errors import UserError
from ravh_sim.raids.build import build, parse_numbers, raid_seed, summary_table

SMALL = ("--max-nodes", "1", "--max-captures", "12")        # grid: one node; wanderer: 12 captures


def _ravh(*args: str, **popen) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "ravh_sim.cli", *args], cwd=ROOT, env=subprocess_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen)


def _complete(folder: Path) -> Dataset:
    """The raid's dataset, checked to hold exactly the files its captures.jsonl names."""
    ds = Dataset(folder)
    for kind in ("rgb", "depth", "mask", "scan"):
        assert len(list((folder / kind).iterdir())) == len(ds) > 0, (folder, kind)
    return ds


def test_house_and_raid_lists():
    assert parse_numbers("1-3,7", range(1, 31), "houses") == [1, 2, 3, 7]
    assert parse_numbers("20,29", range(1, 31), "houses") == [20, 29]
    for bad in ("0-2", "31", "a-b", ""):
        with pytest.raises(UserError, match="--houses"):
            parse_numbers(bad, range(1, 31), "houses")
    assert raid_seed(20, 1, None) == 201 and raid_seed(20, 1, 3) != raid_seed(20, 1, 4)


@pytest.mark.timeout(1200)
def test_build_is_interrupted_and_resumed_without_redoing_finished_raids(tmp_path):
    out = tmp_path / "ds"
    args = ("dataset", "build", "--houses", "20,29", "--raids", "0,1", "--workers", "2", "--out", str(out), *SMALL)
    first = _ravh(*args, start_new_session=True)
    deadline = time.monotonic() + 300
    while not list(out.glob("house*/raid*/raid.json")) and first.poll() is None and time.monotonic() < deadline:
        time.sleep(0.2)
    os.killpg(first.pid, signal.SIGINT)                    # Ctrl-C: the build and its workers
    _, stderr = first.communicate(timeout=120)
    assert first.returncode == 130, stderr[-3000:]         # stopped by the interrupt, not finished
    finished = {p.parent: (p.stat().st_mtime_ns, (p.parent / "captures.jsonl").stat().st_mtime_ns)
                for p in out.glob("house*/raid*/raid.json")}
    assert 0 < len(finished) < 4

    second = _ravh(*args)
    stdout, stderr = second.communicate(timeout=600)
    assert second.returncode == 0, stderr[-3000:]
    assert f"({len(finished)} already there)" in stdout
    for folder, stamps in finished.items():                # skipped, not redone
        assert (folder / "raid.json").stat().st_mtime_ns == stamps[0]
        assert (folder / "captures.jsonl").stat().st_mtime_ns == stamps[1]
    for house in (20, 29):
        for raid in (0, 1):
            ds = _complete(out / f"house{house}" / f"raid{raid}")
            assert len(ds) in (10, 12) and ds.meta["raid"]["raid"] == raid
    assert "paper: Table 2" in stdout and "grid, sun day" in stdout
    assert "10/640 0.02" in stdout                         # house 20's grid raid beside the paper's 640


def test_the_summary_sets_each_house_and_raid_beside_the_paper():
    raids = [{"house": 15, "raid": 0, "captures": 1870}, {"house": 20, "raid": 0, "captures": 320},
             {"house": 20, "raid": 1, "captures": 326}, {"house": 29, "raid": 0, "captures": 480}]
    text = summary_table({"raids": raids})
    rows = {line.split()[0]: line for line in text.splitlines() if line.strip()}
    assert rows["15"].split()[1:] == ["1870/1870", "1.00", "-"]
    assert rows["20"].split()[1:] == ["320/640", "0.50", "326/163", "2.00"]
    assert "1.00 (0.50-1.50)" in rows["0"] and "2670" in rows["0"] and "2830" in rows["0"]   # 1870+640+320
    assert "2.00 (2.00-2.00)" in rows["1"]


def test_a_half_written_raid_is_redone_from_an_empty_folder(tmp_path):
    stale = tmp_path / "house20" / "raid1"
    (stale / "rgb").mkdir(parents=True)
    (stale / "rgb" / "000099.png").write_bytes(b"left by a killed run")
    (stale / "captures.jsonl").write_text('{"index": 99, "torn')
    result = build(tmp_path, [20], [1], max_captures=5, show_progress=False)
    assert not result["failed"] and result["raids"][0]["captures"] == 5
    ds = _complete(stale)
    assert len(ds) == 5 and not (stale / "rgb" / "000099.png").exists()


def test_a_resume_redoes_a_raid_recorded_with_other_parameters(tmp_path):
    """Issue 24: a build with --max-captures 5, then without it, printed '1 already there' and kept 5
    captures; another --seed kept the old seed's raid. Resume compares what the raid was built with."""
    folder = tmp_path / "house20" / "raid1"
    redone: list[tuple[str, str]] = []

    def again(**kwargs) -> dict:
        redone.clear()
        return build(tmp_path, [20], [1], show_progress=False, on_redo=lambda *a: redone.append(a), **kwargs)

    first = again(max_captures=5)
    recorded = json.loads((folder / "raid.json").read_text())["build"]
    assert recorded == {"seed": 201, "preset": recorded["preset"], "max_captures": 5, "max_nodes": 0,
                        "engine": "direct", "quality": "realistic", "version": ravh_sim.__version__}
    assert recorded["preset"]["behaviour"] == "wanderer" and first["raids"][0]["captures"] == 5
    stamp = (folder / "raid.json").stat().st_mtime_ns

    same = again(max_captures=5)                                 # the same request: kept as it is
    assert same["skipped"] == 1 and not same["redone"] and not redone
    assert (folder / "raid.json").stat().st_mtime_ns == stamp

    more = again(max_captures=8)                                 # another limit: redone, and said why
    assert more["skipped"] == 0 and more["raids"][0]["captures"] == 8 and len(_complete(folder)) == 8
    assert redone == [("house20/raid1", "max captures 5, asked for 8")] == list(more["redone"].items())

    other_seed = again(max_captures=8, seed=3)
    assert redone == [("house20/raid1", f"seed 201, asked for {raid_seed(20, 1, 3)}")]
    assert Dataset(folder).meta["raid"]["build"]["seed"] == raid_seed(20, 1, 3) == other_seed["raids"][0]["seed"]

    live = {kind: [cv2.imread(str(p), cv2.IMREAD_UNCHANGED) for p in sorted((folder / kind).iterdir())]
            for kind in ("rgb", "mask")}
    finer = again(max_captures=8, seed=3, quality="dataset")     # the dataset camera: its own profile
    assert redone == [("house20/raid1", "quality realistic, asked for dataset")]
    assert yaml.safe_load((folder / "raid_settings.yaml").read_text())["agents"][0]["profile"] == "giraff_dataset"
    assert finer["raids"][0]["captures"] == 8 and len(_complete(folder)) == 8
    sharper = {kind: [cv2.imread(str(p), cv2.IMREAD_UNCHANGED) for p in sorted((folder / kind).iterdir())]
               for kind in ("rgb", "mask")}
    assert any(not np.array_equal(a, b) for a, b in zip(live["rgb"], sharper["rgb"]))   # other models drawn
    for a, b in zip(live["mask"], sharper["mask"]):           # the same instances in the same pixels
        assert np.mean(a != b) < 0.02

    summary = json.loads((folder / "raid.json").read_text())   # a raid of an older ravh_sim: no parameters
    del summary["build"]
    (folder / "raid.json").write_text(json.dumps(summary))
    old = again(max_captures=8, seed=3)
    assert redone == [("house20/raid1", "recorded without its build parameters (an older ravh_sim)")]
    assert old["raids"][0]["build"]["max_captures"] == 8


def test_the_build_command_names_the_parameter_that_differs(tmp_path):
    args = ("dataset", "build", "--houses", "20", "--raids", "1", "--out", str(tmp_path), "--no-progress")
    first = _ravh(*args, "--max-captures", "3")
    stdout, stderr = first.communicate(timeout=300)
    assert first.returncode == 0, stderr[-3000:]
    second = _ravh(*args, "--max-captures", "4", "--engine", "direct")
    stdout, stderr = second.communicate(timeout=300)
    assert second.returncode == 0, stderr[-3000:]
    assert "raid house20/raid1 was recorded with other parameters, redoing it: max captures 3, asked for 4" \
        in stderr
    assert "(0 already there, 1 redone with other parameters)" in stdout
    assert len(_complete(tmp_path / "house20" / "raid1")) == 4


def test_a_failed_raid_is_named_and_the_exit_status_is_not_zero(tmp_path):
    (tmp_path / "house29").write_text("a file where the raid folders should go")
    run = _ravh("dataset", "build", "--houses", "20,29", "--raids", "1", "--out", str(tmp_path),
                "--max-captures", "3", "--no-progress")
    stdout, stderr = run.communicate(timeout=300)
    assert run.returncode == 1
    assert "raid house29/raid1 failed" in stderr
    assert len(_complete(tmp_path / "house20" / "raid1")) == 3              # the others still ran


def test_a_full_disk_names_the_file_and_the_progress_bar_shows_the_failed_raid(tmp_path):
    """Issue 24: a full disk said 'OSError: [Errno 28] No space left on device' without the file, and the
    bar showed the failed raid as 1/1 100 %. Writes past a file-size limit fail as on a full disk."""
    import resource

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (150_000, resource.getrlimit(resource.RLIMIT_FSIZE)[1]))

    run = _ravh("dataset", "build", "--houses", "20", "--raids", "1", "--out", str(tmp_path), "--max-captures", "3",
                preexec_fn=small_files)
    _, stderr = run.communicate(timeout=300)
    assert run.returncode == 1
    folder = tmp_path / "house20" / "raid1"
    failure = next(line for line in stderr.splitlines() if "failed:" in line)
    assert f"ravh: raid house20/raid1 failed: {folder}/" in failure and ": File too large" in failure
    bars = [line for line in stderr.replace("\r", "\n").splitlines() if "raid/s" in line]
    assert "1 raid FAILED" in bars[-1] and "0/1" in bars[-1] and "1/1" not in stderr and "100%" not in stderr


class RayCluster:
    """A head and one worker node started with ``ray start --block`` on this machine, each in its own
    process group so that stopping them touches nothing else."""

    def __init__(self, tmp: Path) -> None:
        self.temp = Path(tempfile.mkdtemp(prefix="ravh_ray_"))      # short: Ray's socket paths
        self.port = 20000 + os.getpid() % 20000
        self.address = f"127.0.0.1:{self.port}"
        # a token of its own: the ports are open only to this test's processes (and ~/.ray is not read)
        self.env = subprocess_env(RAY_USAGE_STATS_ENABLED="0", RAY_GRACEFUL_SHUTDOWN_DRAIN_TIMEOUT_S="0",
                                  RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=secrets.token_hex(32))
        self.logs = tmp
        self.procs: list[subprocess.Popen] = []

    def start(self) -> None:
        ray = str(Path(sys.executable).with_name("ray"))
        common = ["--block", "--num-cpus", "1", "--disable-usage-stats"]
        self._spawn("head", [ray, "start", "--head", "--port", str(self.port), "--include-dashboard=false",
                             f"--temp-dir={self.temp}", *common])
        self._wait_for_nodes(1)
        self._spawn("worker", [ray, "start", "--address", self.address, *common])
        self._wait_for_nodes(2)

    def _spawn(self, name: str, cmd: list[str]) -> None:
        log = open(self.logs / f"ray_{name}.log", "w")
        self.procs.append(subprocess.Popen(cmd, env=self.env, stdout=log, stderr=subprocess.STDOUT,
                                           start_new_session=True))

    def _wait_for_nodes(self, count: int, timeout: float = 120.0) -> None:
        ray = str(Path(sys.executable).with_name("ray"))
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            status = subprocess.run([ray, "status", "--address", self.address], env=self.env,
                                    capture_output=True, text=True, timeout=60)
            if status.returncode == 0 and status.stdout.count(" node_") >= count:
                return
            assert all(p.poll() is None for p in self.procs), (self.logs / "ray_head.log").read_text()[-2000:]
            time.sleep(1.0)
        raise AssertionError(f"the Ray cluster did not reach {count} nodes in {timeout:.0f} s")

    def stop(self) -> None:
        for proc in reversed(self.procs):                  # worker first, then the head
            try:
                os.killpg(proc.pid, signal.SIGTERM)
                proc.wait(40)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
            except ProcessLookupError:
                pass
        shutil.rmtree(self.temp, ignore_errors=True)


@pytest.mark.timeout(1200)
def test_ray_cluster_of_two_nodes_builds_two_raids(tmp_path):
    """The build as Ray tasks on a head and a worker node (the driver in its own process, as the CLI
    runs it): one raid per node, and the same files as a build on the local pool."""
    cluster = RayCluster(tmp_path)
    out = tmp_path / "shared"
    driver = ("import json, sys; from pathlib import Path; from ravh_sim.raids.build import build; "
              "print(json.dumps(build(Path(sys.argv[1]), [20], [0, 1], ray_address=sys.argv[2], max_nodes=1, "
              "max_captures=12, show_progress=False)))")
    try:
        cluster.start()
        run = subprocess.run([sys.executable, "-c", driver, str(out), cluster.address], cwd=ROOT,
                             env=cluster.env, capture_output=True, text=True, timeout=600)
    finally:
        cluster.stop()
    assert run.returncode == 0, run.stderr[-3000:]
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert not result["failed"], result["failed"]
    assert [(r["house"], r["raid"]) for r in result["raids"]] == [(20, 0), (20, 1)]
    assert len({r["ray_node"] for r in result["raids"]}) == 2           # one raid on each node
    local = tmp_path / "local"
    build(local, [20], [0], max_nodes=1, max_captures=12, show_progress=False)
    for raid in (0, 1):
        ds = _complete(out / "house20" / f"raid{raid}")
        assert len(ds) == json.loads((out / "house20" / f"raid{raid}" / "raid.json").read_text())["captures"]
    for path in (local / "house20" / "raid0").rglob("*.png"):
        assert path.read_bytes() == (out / path.relative_to(local)).read_bytes(), path
