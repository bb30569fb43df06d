"""Two agents in one sim node: each has its own namespaced topics, frames and commands."""
from __future__ import annotations

import math
import time

import pytest
from rosgraph import NodeProcess, spin_until, start_rclpy

rclpy = pytest.importorskip("rclpy")

from geometry_msgs.msg import PoseStamped, Twist  # noqa: E402
from sensor_msgs.msg import LaserScan  # noqa: E402

from ravh_msgs_py import names as n  # noqa: E402
from ravh_sim.nodes.common import SENSOR_QOS, STATE_QOS  # noqa: E402

CONFIG = """agents:
  - {name: robot, profile: giraff, start: station}
  - {name: robot2, profile: giraff, start: [-1.5, 1.5, 0.0]}
"""


def test_two_agents_have_their_own_topics_and_move_independently(tmp_path):
    cfg = tmp_path / "two.yaml"
    cfg.write_text(CONFIG)
    proc = NodeProcess("sim", "--house", "20", "--config", str(cfg), "--camera-rate", "0")
    start_rclpy()
    node = rclpy.create_node("two_agents_probe")
    got = {k: [] for k in ("scan1", "scan2", "pose1", "pose2")}
    node.create_subscription(LaserScan, n.SCAN, got["scan1"].append, SENSOR_QOS)
    node.create_subscription(LaserScan, f"robot2/{n.SCAN}", got["scan2"].append, SENSOR_QOS)
    node.create_subscription(PoseStamped, n.GROUND_TRUTH_POSE, got["pose1"].append, STATE_QOS)
    node.create_subscription(PoseStamped, f"robot2/{n.GROUND_TRUTH_POSE}", got["pose2"].append, STATE_QOS)
    cmd2 = node.create_publisher(Twist, f"robot2/{n.CMD_VEL}", 10)
    try:
        assert spin_until(node, lambda: all(got.values()), 90), proc.log()[-2000:]
        assert got["scan1"][-1].header.frame_id == n.LASER_FRAME
        assert got["scan2"][-1].header.frame_id == f"robot2/{n.LASER_FRAME}"
        p1 = got["pose1"][-1].pose.position
        p2 = got["pose2"][-1].pose.position
        assert (p2.x, p2.y) == pytest.approx((-1.5, 1.5), abs=0.15)
        turn = Twist()
        turn.angular.z = 0.4
        def turned() -> bool:
            q = got["pose2"][-1].pose.orientation
            return abs(2 * math.atan2(q.z, q.w)) > 0.3

        end = time.monotonic() + 60                    # however long 0.3 rad takes on a loaded machine
        while not turned() and time.monotonic() < end:
            cmd2.publish(turn)
            spin_until(node, lambda: False, 0.1)
        q2 = got["pose2"][-1].pose.orientation
        assert abs(2 * math.atan2(q2.z, q2.w)) > 0.3                      # robot2 turned
        q1, p1b = got["pose1"][-1].pose.orientation, got["pose1"][-1].pose.position
        assert math.dist((p1.x, p1.y), (p1b.x, p1b.y)) < 0.01             # robot did not move
        assert abs(2 * math.atan2(q1.z, q1.w) - math.pi / 2) < 0.05
    finally:
        node.destroy_node()
        assert proc.stop() == 0, proc.log()[-2000:]
