"""The sim as standard ROS tools see it (issue 12): TF tree, map -> odom ownership, stamps, /map, parameters.

One sim with two agents, checked over real topics and services with rclpy, as slam_toolbox, AMCL,
Nav2 and rviz would use them.
"""
from __future__ import annotations

import math
import time
from collections import deque

import cv2
import numpy as np
import pytest
import rclpy
from geometry_msgs.msg import PoseStamped, TransformStamped
from nav_msgs.msg import OccupancyGrid
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph import NodeProcess, spin_until, start_rclpy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Image, LaserScan
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_sim.nav.grid import FREE, OCCUPIED
from ravh_sim.nodes import convert
from ravh_sim.nodes.common import LATCHED_QOS, SENSOR_QOS, STATE_QOS

CONFIG = """agents:
  - {name: robot, profile: giraff, start: station}
  - {name: robot2, profile: giraff, start: [-1.5, 1.5, 0.0]}
"""
SLAM_X = 100.0                 # the stand-in SLAM's map -> odom: far from anything the sim would publish
SENSORS = {n.SCAN: LaserScan, f"robot2/{n.SCAN}": LaserScan, n.DEPTH_IMAGE: Image,
           f"robot2/{n.DEPTH_IMAGE}": Image}


def stamp_ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


class Watcher:
    """Records /clock (subscribed first, so a clock and a sensor message ready together are taken in
    that order), /tf and sensor messages with the newest clock received when each arrived."""

    def __init__(self) -> None:
        start_rclpy()
        self.node = rclpy.create_node(f"tf_watcher_{time.monotonic_ns()}")
        self.clock_ns = -1
        self.clocks: set[int] = set()                      # every /clock value received (none dropped)
        self.node.create_subscription(Clock, n.CLOCK, self._on_clock,
                                      QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE))
        self.tf: deque[TransformStamped] = deque(maxlen=5000)
        self.node.create_subscription(TFMessage, n.TF, lambda m: self.tf.extend(m.transforms),
                                      QoSProfile(depth=100))
        self.arrivals: list[tuple[int, int]] = []         # (stamp, clock at arrival)
        self.sensors: dict[str, list] = {t: [] for t in SENSORS}
        for topic, kind in SENSORS.items():
            self.node.create_subscription(kind, topic, lambda m, t=topic: self._on_sensor(t, m), SENSOR_QOS)
        self.poses: dict[int, PoseStamped] = {}
        self.node.create_subscription(PoseStamped, n.GROUND_TRUTH_POSE,
                                      lambda m: self.poses.__setitem__(stamp_ns(m.header.stamp), m), STATE_QOS)
        self.slam = self.node.create_publisher(TFMessage, n.TF, QoSProfile(depth=100))
        self.slam_on = False

    def _on_clock(self, msg: Clock) -> None:
        self.clock_ns = max(self.clock_ns, stamp_ns(msg.clock))
        self.clocks.add(stamp_ns(msg.clock))

    def _on_sensor(self, topic: str, msg) -> None:
        self.sensors[topic].append(msg)
        self.arrivals.append((stamp_ns(msg.header.stamp), self.clock_ns))

    def spin(self, seconds: float) -> None:
        """Spin; while ``slam_on``, publish the stand-in SLAM's map -> odom at 20 Hz (as slam_toolbox does)."""
        end, next_slam = time.monotonic() + seconds, 0.0
        while time.monotonic() < end:
            if self.slam_on and time.monotonic() >= next_slam and self.clock_ns > 0:
                t = TransformStamped()
                t.header.stamp.sec, t.header.stamp.nanosec = divmod(self.clock_ns, 1_000_000_000)
                t.header.frame_id, t.child_frame_id = n.MAP_FRAME, n.ODOM_FRAME
                t.transform.translation.x, t.transform.rotation.w = SLAM_X, 1.0
                self.slam.publish(TFMessage(transforms=[t]))
                next_slam = time.monotonic() + 0.05
            rclpy.spin_once(self.node, timeout_sec=0.01)

    def map_odom(self) -> list[TransformStamped]:
        return [t for t in self.tf if t.header.frame_id == n.MAP_FRAME and t.child_frame_id == n.ODOM_FRAME]


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    cfg = tmp_path_factory.mktemp("tf") / "two.yaml"
    cfg.write_text(CONFIG)
    with NodeProcess("sim", "--house", "20", "--seed", "0", "--config", str(cfg), "--camera-rate", "3",
                     "--scan-rate", "7") as proc:          # rates whose periods fall between /clock ticks
        watcher = Watcher()
        try:
            ok = spin_until(watcher.node, lambda: all(watcher.sensors.values()) and watcher.map_odom(), 90)
            assert ok, f"sim did not start:\n{proc.log()[-3000:]}"
            yield proc, watcher
        finally:
            watcher.node.destroy_node()
        assert proc.stop() == 0, proc.log()[-3000:]
    assert "Traceback" not in proc.log()


def test_late_joiner_reaches_every_sensor_frame_of_both_agents_from_map(sim):
    _, watcher = sim
    assert spin_until(watcher.node, lambda: {t.child_frame_id for t in watcher.tf}
                      >= {n.BASE_FRAME, f"robot2/{n.BASE_FRAME}", n.ODOM_FRAME}, 30)
    late = rclpy.create_node(f"late_joiner_{time.monotonic_ns()}")
    statics: list[TFMessage] = []
    late.create_subscription(TFMessage, n.TF_STATIC, statics.append, LATCHED_QOS)
    try:
        assert spin_until(late, lambda: bool(statics), 10)
    finally:
        late.destroy_node()
    children = {t.child_frame_id for t in statics[-1].transforms}
    assert {f"robot2/{n.LASER_FRAME}", n.LASER_FRAME, f"robot2/{n.CAMERA_OPTICAL_FRAME}"} <= children
    edges = {(t.header.frame_id, t.child_frame_id) for t in [*statics[-1].transforms, *watcher.tf]}
    reached, frontier = {n.MAP_FRAME}, [n.MAP_FRAME]
    while frontier:
        parent = frontier.pop()
        for a, b in edges:
            if a == parent and b not in reached:
                reached.add(b)
                frontier.append(b)
    sensor_frames = {msgs[-1].header.frame_id for msgs in watcher.sensors.values()}
    assert len(sensor_frames) == 4 and sensor_frames <= reached


def test_tf_tree_matches_ground_truth(sim):
    """map -> odom -> base_link, composed, is the ground-truth pose of the same stamp."""
    _, watcher = sim

    def by_stamp() -> dict[int, dict[str, TransformStamped]]:
        edges: dict[int, dict[str, TransformStamped]] = {}
        for t in list(watcher.tf):
            edges.setdefault(stamp_ns(t.header.stamp), {})[t.child_frame_id] = t
        return edges

    def complete() -> list[tuple[int, dict[str, TransformStamped]]]:
        tf = by_stamp()
        return [(stamp, tf[stamp]) for stamp in list(watcher.poses)
                if {n.ODOM_FRAME, n.BASE_FRAME} <= set(tf.get(stamp, {}))]
    assert spin_until(watcher.node, lambda: len(complete()) >= 10, 60)
    checked = 0
    for stamp, edges in complete():
        pose = watcher.poses[stamp]
        (mx, my, myaw), (ox, oy, oyaw) = (_pose2d(edges[f].transform) for f in (n.ODOM_FRAME, n.BASE_FRAME))
        x = mx + ox * math.cos(myaw) - oy * math.sin(myaw)
        y = my + ox * math.sin(myaw) + oy * math.cos(myaw)
        p = pose.pose.position
        assert math.dist((x, y), (p.x, p.y)) < 1e-3
        checked += 1
    assert checked >= 10


def _pose2d(tf) -> tuple[float, float, float]:
    return tf.translation.x, tf.translation.y, 2 * math.atan2(tf.rotation.z, tf.rotation.w)


def test_no_stamp_is_ahead_of_the_clock(sim):
    """The sim never stamps later than the /clock it has published: since a /clock never runs ahead
    of sim time, every stamp must be a /clock value itself (one published for it when the 100 Hz ticks
    missed it). Checked by value, not by arrival order: DDS does not order delivery across topics,
    and on a loaded machine a /clock sent before an image can arrive after it."""
    _, watcher = sim
    watcher.arrivals.clear()
    assert spin_until(watcher.node, lambda: len(watcher.arrivals) >= 20, 60)
    late_clocks = [stamp for stamp, clock in watcher.arrivals if stamp > clock]
    spin_until(watcher.node, lambda: all(s in watcher.clocks for s in late_clocks), 5)
    ahead = [s for s, _ in watcher.arrivals if s not in watcher.clocks]
    assert not ahead, f"{len(ahead)} of {len(watcher.arrivals)} sensor messages stamped ahead of /clock"


def test_map_tf_auto_yields_to_a_slam_node_and_takes_over_again(sim):
    proc, watcher = sim
    watcher.slam_on = True
    end = time.monotonic() + 60
    while "another node publishes map -> odom" not in proc.log() and time.monotonic() < end:
        watcher.spin(0.1)                            # SLAM's edges go out while the sim notices them
    assert "another node publishes map -> odom" in proc.log(), proc.log()[-3000:]
    watcher.tf.clear()
    end = time.monotonic() + 60
    while len(watcher.map_odom()) < 30 and time.monotonic() < end:
        watcher.spin(0.1)
    edges = watcher.map_odom()
    assert len(edges) >= 30
    flips = sum(1 for a, b in zip(edges, edges[1:]) if (a.transform.translation.x == SLAM_X)
                != (b.transform.translation.x == SLAM_X))
    assert flips == 0 and edges[-1].transform.translation.x == SLAM_X
    assert proc.log().count("another node publishes map -> odom") == 1
    watcher.slam_on = False
    watcher.tf.clear()
    assert spin_until(watcher.node, lambda: any(t.transform.translation.x != SLAM_X for t in watcher.map_odom()), 6)
    assert "publishes its ground truth on /tf again" in proc.log()


def test_map_is_an_obstacle_map_where_the_laser_ends(sim):
    _, watcher = sim
    grids: list[OccupancyGrid] = []
    sub = watcher.node.create_subscription(OccupancyGrid, n.MAP, grids.append, LATCHED_QOS)
    assert spin_until(watcher.node, lambda: bool(grids), 10)
    watcher.node.destroy_subscription(sub)
    grid = convert.grid_of(grids[-1])
    data, origin, res = grid.data, grid.origin, grid.resolution
    assert set(np.unique(data)) == {-1, 0, 100}
    near = cv2.dilate((data == OCCUPIED).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    scan = watcher.sensors[n.SCAN][-1]
    pose = watcher.poses.get(stamp_ns(scan.header.stamp)) or max(watcher.poses.items())[1]
    x, y, yaw = convert.pose_of(pose.pose)
    hits = []
    for i, d in enumerate(scan.ranges):
        if math.isfinite(d):
            a = yaw + scan.angle_min + i * scan.angle_increment
            col = int(math.floor((x + d * math.cos(a) - origin[0]) / res))
            row = int(math.floor((y + d * math.sin(a) - origin[1]) / res))
            hits.append(near[row, col])
    assert len(hits) > 300 and np.mean(hits) >= 0.9
    assert (data == FREE).sum() * res * res > 15.0        # house 20: 33 m² of floor, furniture on ~1/3


def test_parameters_are_read_only(sim):
    _, watcher = sim
    client = watcher.node.create_client(SetParameters, "/ravh_sim/set_parameters")
    assert client.wait_for_service(timeout_sec=10)
    value = ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=1.0)
    future = client.call_async(SetParameters.Request(parameters=[Parameter(name="camera_rate", value=value)]))
    rclpy.spin_until_future_complete(watcher.node, future, timeout_sec=10)
    watcher.node.destroy_client(client)
    result = future.result().results[0]
    assert not result.successful and "read-only" in result.reason


def test_a_bad_map_tf_is_a_one_line_error():
    import subprocess
    import sys

    from rosgraph import ros_env
    out = subprocess.run([sys.executable, "-m", "ravh_sim.cli", "sim", "--house", "20", "--ros-args", "-p",
                          "map_tf:=bogus"], capture_output=True, text=True, env=ros_env(), timeout=120)
    assert out.returncode == 2 and "map_tf must be one of auto, on, off, got 'bogus'" in out.stderr
    assert "Traceback" not in out.stderr


def test_a_negative_rate_is_a_one_line_error():
    import subprocess
    import sys

    from rosgraph import ros_env
    out = subprocess.run([sys.executable, "-m", "ravh_sim.cli", "sim", "--house", "20", "--scan-rate", "-5"],
                         capture_output=True, text=True, env=ros_env(), timeout=120)
    assert out.returncode == 2 and "scan_rate must be >= 0 Hz (0 = never), got -5.0" in out.stderr
    assert "Traceback" not in out.stderr
