"""``ravh probe``: delivered rate and latency of the sim's topics, measured from another process.

Like ``ros2 topic hz`` and ``ros2 topic delay`` for every ravh_sim topic at once (there is no ros2cli
in the PyPI wheels). Stamps are sim time; the probe maps them to wall time with the /clock messages of
the last second (the smallest wall - sim offset among them is the clock's own, nearly zero, transport
delay; a window, because the sim re-anchors sim time to wall time when it falls behind), so
latency = receipt wall time - the stamp's wall time. Prints one JSON object. ``--no-images``: the
images are left out (a subscriber makes the sim render them).
"""
from __future__ import annotations

import argparse
import json
import statistics
import time
from collections import deque

from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.task import Future
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, LaserScan

from ravh_msgs_py import names as n
from ravh_sim.nodes import convert
from ravh_sim.nodes.common import SENSOR_QOS, STATE_QOS, run_node

OFFSET_WINDOW_S = 1.0
CAMERA = {n.COLOR_IMAGE: Image, n.COLOR_COMPRESSED: CompressedImage, n.COLOR_INFO: CameraInfo,
          n.DEPTH_IMAGE: Image, n.DEPTH_INFO: CameraInfo, n.INSTANCE_IMAGE: Image}
MEASURED = {**CAMERA, n.SCAN: LaserScan, n.ODOM: Odometry}


class Probe(Node):
    def __init__(self, seconds: float, warmup: float, images: bool = True) -> None:
        super().__init__("ravh_probe")
        self.seconds, self.warmup = seconds, warmup
        self.clock_window: deque[tuple[float, float]] = deque()   # (wall, wall - sim) of recent /clock
        self.first_clock: tuple[float, float] | None = None
        self.last_clock: tuple[float, float] | None = None
        measured = {t: kind for t, kind in MEASURED.items() if images or t not in CAMERA}
        self.samples: dict[str, list[tuple[float, float]]] = {t: [] for t in measured}  # (receipt, stamp) wall
        self.clocks = 0                                              # /clock messages while measuring
        self.create_subscription(Clock, n.CLOCK, self._on_clock, STATE_QOS)
        for topic, kind in measured.items():
            self.create_subscription(kind, topic, lambda m, t=topic: self._on_msg(t, m), SENSOR_QOS
                                     if kind is not Odometry else STATE_QOS)
        self.finished = Future()
        self.start = time.monotonic()
        self.create_timer(0.2, self._check)

    def _measuring(self) -> bool:
        return time.monotonic() - self.start >= self.warmup

    def _on_clock(self, msg: Clock) -> None:
        wall, sim = time.time(), convert.seconds(msg.clock)
        self.clock_window.append((wall, wall - sim))
        while self.clock_window[0][0] < wall - OFFSET_WINDOW_S:
            self.clock_window.popleft()
        if self._measuring():
            self.clocks += 1
            self.first_clock = self.first_clock or (wall, sim)
            self.last_clock = (wall, sim)

    def _on_msg(self, topic: str, msg) -> None:
        if self._measuring() and self.clock_window:
            stamp = msg.header.stamp
            offset = min(o for _, o in self.clock_window)
            self.samples[topic].append((time.time(), convert.seconds(stamp) + offset))

    def _check(self) -> None:
        if time.monotonic() - self.start >= self.warmup + self.seconds and not self.finished.done():
            print(json.dumps(self.report()), flush=True)
            self.finished.set_result(True)

    def report(self) -> dict:
        out: dict = {"seconds": self.seconds}
        if self.first_clock and self.last_clock and self.last_clock[0] > self.first_clock[0]:
            out["real_time_factor"] = round((self.last_clock[1] - self.first_clock[1])
                                            / (self.last_clock[0] - self.first_clock[0]), 3)
            out[n.CLOCK] = {"count": self.clocks,
                            "rate_hz": round((self.clocks - 1) / (self.last_clock[0] - self.first_clock[0]), 2)}
        for topic, rows in self.samples.items():
            if len(rows) < 2:
                out[topic] = {"count": len(rows)}
                continue
            walls = [w for w, _ in rows]
            latencies = sorted((w - s) * 1000 for w, s in rows)
            out[topic] = {"count": len(rows), "rate_hz": round((len(rows) - 1) / (walls[-1] - walls[0]), 2),
                          "latency_ms_median": round(statistics.median(latencies), 2),
                          "latency_ms_p95": round(latencies[int(0.95 * (len(latencies) - 1))], 2)}
        return out


def main(argv: list[str] | None = None) -> int:
    def make(args: list[str]) -> Probe:
        p = argparse.ArgumentParser(prog="probe", description="Rate and latency of the sim's topics (JSON).")
        p.add_argument("--seconds", type=float, default=10.0)
        p.add_argument("--warmup", type=float, default=2.0)
        p.add_argument("--no-images", dest="images", action="store_false",
                       help="leave the images out (a subscriber makes the sim render them)")
        a = p.parse_args(args)
        return Probe(a.seconds, a.warmup, a.images)
    return run_node(make, argv)
