"""The sim's start-up modes, each in its own sim: map_tf on and off, stamped velocity commands; and
``ravh probe`` against a running sim."""
from __future__ import annotations

import json
import math
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager

from conftest import ROOT
from geometry_msgs.msg import TransformStamped, TwistStamped
from rclpy.qos import QoSProfile
from rosgraph import NodeProcess, ros_env, spin_until
from test_sim_tf import SLAM_X, Watcher, stamp_ns

from ravh_msgs_py import names as n
from ravh_sim.nodes import convert


@contextmanager
def sim_with(*args: str) -> Iterator[tuple[NodeProcess, Watcher]]:
    """A one-agent sim started with ``args``, watched; stopped (and checked) on the way out."""
    with NodeProcess("sim", "--house", "20", "--seed", "0", "--camera-rate", "0", *args) as proc:
        watcher = Watcher()
        try:
            assert spin_until(watcher.node, lambda: watcher.clock_ns > 0 and len(watcher.poses) >= 2, 90), \
                proc.log()[-3000:]
            yield proc, watcher
        finally:
            watcher.node.destroy_node()
        assert proc.stop() == 0, proc.log()[-3000:]
    assert "Traceback" not in proc.log()


def test_map_tf_off_publishes_no_map_edge_and_stamped_commands_drive():
    """--map-tf off: odom -> base_link on /tf, the ground truth on map_to_odom, never map -> odom on /tf.
    --cmd-vel-stamped: cmd_vel takes TwistStamped, and the robot turns on it."""
    with sim_with("--map-tf", "off", "--cmd-vel-stamped") as (proc, watcher):
        truth: list[TransformStamped] = []
        watcher.node.create_subscription(TransformStamped, n.MAP_TO_ODOM, truth.append, QoSProfile(depth=10))

        def odom_edges() -> int:
            return sum(t.child_frame_id == n.BASE_FRAME for t in watcher.tf)
        assert spin_until(watcher.node, lambda: odom_edges() >= 100 and len(truth) >= 10, 60)
        assert watcher.map_odom() == []

        cmd = watcher.node.create_publisher(TwistStamped, n.CMD_VEL, 10)
        start = convert.pose_of(watcher.poses[max(watcher.poses)].pose)

        def turned() -> float:
            yaw = convert.pose_of(watcher.poses[max(watcher.poses)].pose)[2]
            return abs(math.remainder(yaw - start[2], 2 * math.pi))
        turn = TwistStamped()
        turn.header.frame_id, turn.twist.angular.z = n.BASE_FRAME, 0.5
        end = time.monotonic() + 60
        while turned() < 0.3 and time.monotonic() < end:
            cmd.publish(turn)
            watcher.spin(0.05)
        assert turned() >= 0.3, proc.log()[-3000:]


def test_map_tf_on_keeps_publishing_while_slam_does():
    """--map-tf on: the sim's ground truth stays on /tf even while another node publishes map -> odom
    (auto would hand over within a second of sim time)."""
    with sim_with("--map-tf", "on") as (proc, watcher):
        watcher.slam_on = True
        end = time.monotonic() + 30
        while not any(t.transform.translation.x == SLAM_X for t in watcher.map_odom()) and time.monotonic() < end:
            watcher.spin(0.1)                       # our SLAM's edges come back to us: they are on /tf
        slam_from = watcher.clock_ns
        end = time.monotonic() + 120
        while watcher.clock_ns < slam_from + 4_000_000_000 and time.monotonic() < end:
            watcher.spin(0.1)                       # 4 s of sim time with SLAM publishing
        ours = [t for t in watcher.map_odom() if t.transform.translation.x != SLAM_X
                and stamp_ns(t.header.stamp) > slam_from + 2_000_000_000]
        assert len(ours) >= 10, proc.log()[-3000:]
        assert "another node publishes" not in proc.log()


def test_probe_reports_what_the_sim_publishes():
    """``ravh probe`` on a sim with its camera off: scans and odometry with rates and latencies, no images."""
    with sim_with("--scan-rate", "10") as (_, watcher):
        probe = subprocess.Popen([sys.executable, "-m", "ravh_sim.cli", "probe", "--seconds", "3", "--warmup", "1"],
                                 cwd=ROOT, env=ros_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            while probe.poll() is None:
                watcher.spin(0.1)                     # the sim goes on meanwhile; the probe ends by itself
            out, err = probe.communicate(timeout=60)
        finally:
            probe.kill()
            probe.wait()
    assert probe.returncode == 0, err[-2000:]
    report = json.loads(out.strip().splitlines()[-1])
    for topic in (n.SCAN, n.ODOM):
        assert report[topic]["count"] >= 2 and report[topic]["rate_hz"] > 0, report
        assert report[topic]["latency_ms_median"] <= report[topic]["latency_ms_p95"], report
    assert report[n.COLOR_IMAGE] == {"count": 0} and report["real_time_factor"] > 0
