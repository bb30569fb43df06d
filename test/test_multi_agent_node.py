"""Agents in one sim node: each has its own namespaced topics, frames and commands; the first has the
plain names, whatever it is called."""
from __future__ import annotations

import math
import time

import pytest
import rclpy
from geometry_msgs.msg import PoseStamped, Twist
from rosgraph import NodeProcess, spin_until, start_rclpy
from sensor_msgs.msg import LaserScan

from ravh_msgs_py import names as n
from ravh_msgs_py.capture import CaptureEvent
from ravh_sim.nodes import convert
from ravh_sim.nodes.common import SENSOR_QOS, STATE_QOS

CONFIG = """agents:
  - {name: robot, profile: giraff, start: station}
  - {name: robot2, profile: giraff, start: [-1.5, 1.5, 0.0]}
"""


def test_two_agents_have_their_own_topics_and_move_independently(tmp_path):
    cfg = tmp_path / "two.yaml"
    cfg.write_text(CONFIG)
    with NodeProcess("sim", "--house", "20", "--config", str(cfg), "--camera-rate", "0") as proc:
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
            x1, y1, _ = convert.pose_of(got["pose1"][-1].pose)
            x2, y2, _ = convert.pose_of(got["pose2"][-1].pose)
            assert (x2, y2) == pytest.approx((-1.5, 1.5), abs=0.15)
            turn = Twist()
            turn.angular.z = 0.4
            def turned() -> bool:
                return abs(convert.pose_of(got["pose2"][-1].pose)[2]) > 0.3

            end = time.monotonic() + 60                    # however long 0.3 rad takes on a loaded machine
            while not turned() and time.monotonic() < end:
                cmd2.publish(turn)
                spin_until(node, lambda: False, 0.1)
            assert turned()                                                   # robot2 turned
            x1b, y1b, yaw1 = convert.pose_of(got["pose1"][-1].pose)
            assert math.dist((x1, y1), (x1b, y1b)) < 0.01                     # robot did not move
            assert abs(yaw1 - math.pi / 2) < 0.05
        finally:
            node.destroy_node()
        assert proc.stop() == 0, proc.log()[-2000:]


def test_a_renamed_first_agent_is_driven_on_the_plain_topics(tmp_path):
    """The first agent uses the plain names whatever it is called: a behaviour learns it from the
    footprint (no --agent), drives /cmd_vel and the robot moves; its capture events name it."""
    cfg = tmp_path / "alpha.yaml"
    cfg.write_text("agents:\n  - {name: alpha, profile: giraff, start: station}\n")
    log = tmp_path / "captures.jsonl"
    with NodeProcess("sim", "--house", "20", "--config", str(cfg), "--camera-rate", "0") as sim, \
            NodeProcess("wanderer", "--capture-period", "1.0", "--log", str(log)) as behaviour:
        start_rclpy()
        node = rclpy.create_node("alpha_probe")
        poses: list[PoseStamped] = []
        node.create_subscription(PoseStamped, n.GROUND_TRUTH_POSE, poses.append, STATE_QOS)
        try:
            assert spin_until(node, lambda: bool(poses), 90), sim.log()[-2000:]
            start = poses[-1].pose.position

            def moved() -> float:
                p = poses[-1].pose.position
                return math.dist((start.x, start.y), (p.x, p.y))

            assert spin_until(node, lambda: moved() > 0.3, 180), behaviour.log()[-2000:]
            assert spin_until(node, lambda: log.exists() and log.read_text().count("\n") >= 1, 120), \
                behaviour.log()[-2000:]
            event = CaptureEvent.from_json(log.read_text().splitlines()[0])
            assert event.agent == "alpha" and event.reason
            assert behaviour.alive() and "Traceback" not in behaviour.log()
        finally:
            node.destroy_node()
        assert behaviour.stop() == 0, behaviour.log()[-2000:]
        assert sim.stop() == 0, sim.log()[-2000:]
