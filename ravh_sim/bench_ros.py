"""Benchmarks of the ROS layer: the sim node as a subscriber in another process sees it.

``ravh bench node --json`` runs the main job, the sim node (house 15, default rates, real-time factor
1) with the wanderer driving the robot room to room (``--order cyclic``, seed 0: the same route every
run), with ``ravh probe`` measuring from a third process, in three set-ups, each beside a baseline
run in the same call:

- ``main_job``: nobody subscribes to the camera (the probe takes /clock, scans and odometry); baseline
  the camera off (``--camera-rate 0``): what lazy sensors should come close to.
- ``all_camera_topics``: the probe subscribes to every camera topic too; baseline ``--frame-policy
  wait`` (every frame kept by slowing the sim, as the node did when it rendered in its control loop).
- ``fast_quality``: the same with the fast camera (robot profile giraff_fast); the same baseline.

Each reports the real-time factor (from /clock), the delivered rate of every topic, the image latency,
and the sim node's CPU (cores) and peak RSS (from /proc). The wanderer asks for a capture every 0.5 s
of its own (captures always render), in every set-up.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from typing import Any

from ravh_msgs_py import names as n
from ravh_sim.nodes.common import ros_domain_id

CLK_TCK = os.sysconf("SC_CLK_TCK")
TARGET = {"main_job_real_time_factor": 0.95, "all_camera_topics_real_time_factor": 0.9, "scan_hz": 10.0,
          "clock_hz": 100.0, "rss_mb": 600.0}       # rss_mb: the sim node's peak


def _cli(*args: str, env: dict[str, str], **popen: Any) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "ravh_sim.cli", *args], env=env, **popen)


def _cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def _peak_rss_mb(pid: int) -> float:
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return float("nan")


WARMUP_S = 15.0                         # world build, EGL start, the wanderer's first plan
TOPICS = {"clock": n.CLOCK, "scan": n.SCAN, "odom": n.ODOM, "rgb": n.COLOR_IMAGE, "compressed": n.COLOR_COMPRESSED,
          "rgb_info": n.COLOR_INFO, "depth": n.DEPTH_IMAGE, "depth_info": n.DEPTH_INFO, "instance": n.INSTANCE_IMAGE}
FAST_CONFIG = "agents:\n  - {name: robot, profile: giraff_fast, start: station}\n"   # the fast camera


def _setups(fast_config: str) -> dict[str, tuple[list[str], bool, str, list[str]]]:
    """set-up -> (sim flags, whether the probe takes the images, baseline name, the baseline's sim flags)."""
    fast = ["--config", fast_config]
    return {"main_job": ([], False, "camera_off", ["--camera-rate", "0"]),
            "all_camera_topics": ([], True, "frame_policy_wait", ["--frame-policy", "wait"]),
            "fast_quality": (fast, True, "frame_policy_wait", [*fast, "--frame-policy", "wait"])}


def _session(house: int, seconds: float, flags: list[str], images: bool) -> dict[str, Any]:
    """One sim + wanderer + probe run; the probe's rates and latencies, the sim's CPU and memory."""
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
               ROS_DOMAIN_ID=ros_domain_id(100 + os.getpid())[0])
    sim = _cli("sim", "--house", str(house), "--seed", "0", *flags, env=env,
               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wanderer = _cli("wanderer", "--order", "cyclic", "--seed", "0", env=env,
                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        probe = _cli("probe", "--seconds", str(seconds), "--warmup", str(WARMUP_S),
                     *([] if images else ["--no-images"]), env=env, stdout=subprocess.PIPE,
                     stderr=subprocess.DEVNULL, text=True)
        time.sleep(WARMUP_S)
        cpu0, t0 = _cpu_seconds(sim.pid), time.monotonic()
        out, _ = probe.communicate(timeout=seconds + WARMUP_S + 60)
        cpu = (_cpu_seconds(sim.pid) - cpu0) / (time.monotonic() - t0)
        report = json.loads(out.strip().splitlines()[-1])
        return {"real_time_factor": report.get("real_time_factor"),
                **{f"{key}_hz": report[topic].get("rate_hz", 0.0) for key, topic in TOPICS.items() if topic in report},
                "rgb_latency_ms": report.get(n.COLOR_IMAGE, {}).get("latency_ms_median"),
                "scan_latency_ms": report.get(n.SCAN, {}).get("latency_ms_median"),
                "sim_cpu_cores": round(cpu, 2), "sim_peak_rss_mb": round(_peak_rss_mb(sim.pid), 1)}
    finally:
        for proc in (wanderer, sim):
            proc.send_signal(signal.SIGINT)
            proc.wait(30)


def bench_node(houses: list[int] | None = None, seconds: float = 20.0) -> dict[str, Any]:
    house = (houses or [15])[0]
    result: dict[str, Any] = {"house": house, "seconds": seconds, "route": "wanderer --order cyclic --seed 0",
                              "targets": TARGET}
    with tempfile.TemporaryDirectory() as tmp:
        fast_config = os.path.join(tmp, "fast.yaml")
        with open(fast_config, "w") as f:
            f.write(FAST_CONFIG)
        for name, (flags, images, baseline, baseline_flags) in _setups(fast_config).items():
            result[name] = {"ours": _session(house, seconds, flags, images),
                            baseline: _session(house, seconds, baseline_flags, images)}
    return result
