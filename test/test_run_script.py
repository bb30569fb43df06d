"""tools/run.sh: arguments checked before anything starts; one process ending stops them all."""
from __future__ import annotations

import os
import signal
import subprocess
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
    import rclpy
    from rosgraph import spin_until, start_rclpy

    from ravh_msgs_py import names as n
    run = subprocess.Popen(["bash", RUN, "--house", "20", "--rtf", "0"], env=ros_env(), cwd=tmp_path,
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
    start_rclpy()
    node = rclpy.create_node("run_script_probe")
    try:
        # both up and running: the sim serves /clock, the wanderer drives cmd_vel
        up = spin_until(node, lambda: node.count_publishers("/" + n.CMD_VEL) >= 1
                        and node.count_publishers(n.CLOCK) >= 1 and len(_children(run.pid)) >= 2, 300)
        assert up, "run.sh did not start the sim and the wanderer"
        children = _children(run.pid)
        behaviour = next(pid for pid, cmd in children.items() if "wanderer" in cmd)
        subprocess.run(["kill", "-INT", str(behaviour)], check=True, timeout=30)
        run.wait(timeout=60)
        assert not any(Path(f"/proc/{pid}").exists() for pid in children)
    finally:
        node.destroy_node()
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGINT)                 # the script and everything it started
            try:
                run.wait(timeout=60)
            except subprocess.TimeoutExpired:
                os.killpg(run.pid, signal.SIGKILL)
                run.wait()
