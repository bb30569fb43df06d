"""Benchmarks of the ROS layer: the sim node as a subscriber in another process sees it.

``ravh bench node --json`` runs the sim node (house 15, default rates, real-time factor 1) and
``ravh probe`` in separate processes, twice: with ravh_sim's Fast DDS profile (16 MiB shared-memory
segments, the default for our nodes) and with Fast DDS's defaults, the baseline. It reports delivered
rates, stamp-to-receipt latency, the real-time factor, and the sim node's CPU and peak RSS (from /proc).
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from typing import Any

from ravh_msgs_py import names as n
from ravh_sim.paths import FASTDDS_PROFILE

CLK_TCK = os.sysconf("SC_CLK_TCK")
TARGET = {"image_hz": 10.0, "scan_hz": 10.0, "real_time_factor": 1.0, "rss_mb": 500.0}


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


def _session(house: int, seconds: float, profile: bool) -> dict[str, Any]:
    """One sim + probe run; returns the probe's report plus the sim's CPU and memory."""
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
               ROS_DOMAIN_ID=str(100 + os.getpid() % 100))
    if profile:
        env["FASTRTPS_DEFAULT_PROFILES_FILE"] = str(FASTDDS_PROFILE)
    else:
        env["FASTRTPS_DEFAULT_PROFILES_FILE"] = os.devnull      # an empty profile: Fast DDS defaults
    sim = _cli("sim", "--house", str(house), env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        warmup = 8.0                                           # world build + EGL start
        probe = _cli("probe", "--seconds", str(seconds), "--warmup", str(warmup), env=env,
                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        time.sleep(warmup)
        cpu0, t0 = _cpu_seconds(sim.pid), time.monotonic()
        out, _ = probe.communicate(timeout=seconds + warmup + 60)
        cpu = (_cpu_seconds(sim.pid) - cpu0) / (time.monotonic() - t0)
        report = json.loads(out.strip().splitlines()[-1])
        report["sim_cpu_cores"] = round(cpu, 2)
        report["sim_peak_rss_mb"] = round(_peak_rss_mb(sim.pid), 1)
        return report
    finally:
        sim.send_signal(signal.SIGINT)
        sim.wait(30)


def bench_node(houses: list[int] | None = None, seconds: float = 10.0) -> dict[str, Any]:
    house = (houses or [15])[0]
    ours = _session(house, seconds, profile=True)
    default = _session(house, seconds, profile=False)

    def get(report: dict, topic: str, key: str) -> float:
        return report.get(topic, {}).get(key, float("nan"))

    rgb_ours, rgb_default = get(ours, n.COLOR_IMAGE, "latency_ms_median"), get(default, n.COLOR_IMAGE,
                                                                                 "latency_ms_median")
    return {
        "house": house, "seconds": seconds,
        "rgb_hz": get(ours, n.COLOR_IMAGE, "rate_hz"), "depth_hz": get(ours, n.DEPTH_IMAGE, "rate_hz"),
        "instance_hz": get(ours, n.INSTANCE_IMAGE, "rate_hz"), "scan_hz": get(ours, n.SCAN, "rate_hz"),
        "odom_hz": get(ours, n.ODOM, "rate_hz"),
        "rgb_latency_ms": rgb_ours, "depth_latency_ms": get(ours, n.DEPTH_IMAGE, "latency_ms_median"),
        "scan_latency_ms": get(ours, n.SCAN, "latency_ms_median"),
        "real_time_factor": ours.get("real_time_factor"),
        "sim_cpu_cores": ours["sim_cpu_cores"], "sim_peak_rss_mb": ours["sim_peak_rss_mb"],
        "baseline_default_dds": {"rgb_hz": get(default, n.COLOR_IMAGE, "rate_hz"),
                                 "rgb_latency_ms": rgb_default,
                                 "real_time_factor": default.get("real_time_factor")},
        "rgb_latency_default_over_ours": round(rgb_default / rgb_ours, 2) if rgb_ours else None,
        "targets": TARGET,
        "detail": {"ours": ours, "default_dds": default},
    }
