"""tools/run.sh: arguments checked before anything starts; one process ending stops them all."""
from __future__ import annotations

import signal
import subprocess
import time
from pathlib import Path

import pytest
from conftest import ROOT
from rosgraph import ros_env

RUN = str(ROOT / "tools" / "run.sh")


@pytest.mark.parametrize("args, message", [
    (["--behaviour", "wandrer"], "unknown behaviour 'wandrer'"),
    (["--house", "31"], "unknown house 31"),
    (["--seed", "-5"], "seed: expected an integer"),
    (["--rtf", "fast"], "--rtf must be a number"),
])
def test_bad_arguments_stop_before_anything_runs(args, message):
    done = subprocess.run(["bash", RUN, *args], capture_output=True, text=True, env=ros_env(), timeout=300)
    assert done.returncode == 2 and message in done.stderr, done.stderr
    assert "running" not in done.stderr                      # no sim was started


def _children(pid: int) -> dict[int, str]:
    """Child pid -> command line, from /proc."""
    out = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out[int(entry.name)] = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except (OSError, ValueError, IndexError):
            continue
    return out


def test_when_the_behaviour_ends_the_sim_is_stopped_too(tmp_path):
    run = subprocess.Popen(["bash", RUN, "--house", "20", "--rtf", "0"], env=ros_env(), cwd=tmp_path,
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        end = time.monotonic() + 300
        while len(_children(run.pid)) < 2 and time.monotonic() < end:
            time.sleep(0.5)
        children = _children(run.pid)
        behaviour = next(pid for pid, cmd in children.items() if "wanderer" in cmd)
        time.sleep(5)                                          # both up and running
        subprocess.run(["kill", "-INT", str(behaviour)], check=True)
        run.wait(timeout=60)
        assert not any(Path(f"/proc/{pid}").exists() for pid in children)
    finally:
        if run.poll() is None:
            run.send_signal(signal.SIGINT)
            run.wait(timeout=60)
