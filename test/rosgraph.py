"""Helpers for integration tests: run real nodes in subprocesses and watch them with rclpy.

Each test run uses the user's ROS_DOMAIN_ID when set, else one of its own (the report header says
which), and ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, so DDS traffic stays on this machine and parallel
runs do not see each other. Nodes are stopped with SIGINT (SIGKILL
leaves Fast DDS shared-memory files behind).
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from typing import Any

from conftest import ROOT, subprocess_env

from ravh_sim.nodes.common import ros_domain_id

DOMAIN_ID, DOMAIN_ID_SOURCE = ros_domain_id(10 + os.getpid())


def ros_env(**extra: str) -> dict[str, str]:
    return subprocess_env(ROS_DOMAIN_ID=DOMAIN_ID, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
                          PYTHONUNBUFFERED="1", **extra)


class NodeProcess:
    """A ravh node (``ravh NODE ARGS``) in a subprocess, its output kept in a log file."""

    def __init__(self, name: str, *args: str, log_dir: str = "/tmp") -> None:
        self.log_path = os.path.join(log_dir, f"ravh_{name}_{os.getpid()}_{time.monotonic_ns()}.log")
        self._log = open(self.log_path, "w")
        self.proc = subprocess.Popen([sys.executable, "-m", "ravh_sim.cli", name, *args], cwd=ROOT,
                                     env=ros_env(), stdout=self._log, stderr=subprocess.STDOUT)

    def __enter__(self) -> NodeProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def alive(self) -> bool:
        return self.proc.poll() is None

    def log(self) -> str:
        if not self._log.closed:
            self._log.flush()
        with open(self.log_path) as f:
            return f.read()

    def stop(self, timeout: float = 20.0) -> int:
        """SIGINT, wait; returns the exit code (SIGKILL only as a last resort, reported as -9). Safe to call
        again: a fixture's ``finally`` stops what a test may already have stopped."""
        if self.alive():
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._log.close()
        return self.proc.returncode


def read_line(stream: Any, timeout: float) -> str:
    """The next line a child writes to its pipe, or "" if none comes within ``timeout``: a bare
    readline() on a child that hangs would hang the test."""
    import select
    if select.select([stream], [], [], timeout)[0]:
        return stream.readline()
    return ""


def spin_until(node: Any, condition: Callable[[], bool], timeout: float) -> bool:
    import rclpy
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        rclpy.spin_once(node, timeout_sec=0.05)
    return condition()


def start_rclpy() -> None:
    """rclpy in the test process, on the test run's domain, with the nodes' DDS transport profile."""
    import rclpy

    from ravh_sim.nodes.common import use_large_message_transport
    os.environ.update(ROS_DOMAIN_ID=DOMAIN_ID, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    use_large_message_transport()
    if not rclpy.ok():
        rclpy.init()


def remove_orphan_shm(since: float) -> int:
    """Delete Fast DDS shared-memory files made after ``since`` (epoch s) whose owner is gone: what a
    SIGKILLed participant leaves behind. A participant holds its segment's lock (``_el``) open for its
    whole life, while its peers (this test process among them) map the segment to write into it; so a
    segment with a lock is owned while some process holds the lock open, whoever maps it. A file without a
    lock is held where a process maps or opens it; a mutex (``sem.*_mutex``) goes with its segment.
    Returns how many were removed."""
    import glob
    mapped: set[str] = set()
    opened: set[str] = set()
    for pid in glob.glob("/proc/[0-9]*"):
        try:
            with open(f"{pid}/maps") as f:
                mapped.update(line.split()[-1] for line in f if "/dev/shm/" in line)
            for fd in os.scandir(f"{pid}/fd"):
                opened.add(os.readlink(fd.path))
        except OSError:
            continue

    def owned(segment: str) -> bool:
        lock = segment + "_el"
        return lock in opened if os.path.exists(lock) else segment in mapped or segment in opened

    removed = 0
    for path in glob.glob("/dev/shm/*fastrtps_*"):
        name = os.path.basename(path)
        segment = "/dev/shm/" + name.removeprefix("sem.").removesuffix("_mutex").removesuffix("_el")
        try:
            if os.path.getmtime(path) >= since and not owned(segment):
                os.remove(path)
                removed += 1
        except OSError:
            continue
    return removed
