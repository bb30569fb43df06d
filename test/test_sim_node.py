"""The sim node as users see it: a real process, checked over real topics and services with rclpy."""
from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest
from rosgraph import NodeProcess, spin_until, start_rclpy

rclpy = pytest.importorskip("rclpy")

from diagnostic_msgs.srv import AddDiagnostics  # noqa: E402
from geometry_msgs.msg import PoseStamped, TransformStamped, Twist  # noqa: E402
from nav_msgs.msg import OccupancyGrid, Odometry  # noqa: E402
from nav_msgs.srv import GetMap, GetPlan  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, LaserScan  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from ravh_msgs_py import names as n  # noqa: E402
from ravh_msgs_py.capture import CaptureEvent  # noqa: E402
from ravh_msgs_py.client import RavhClient  # noqa: E402
from ravh_sim.nav.grid import FREE  # noqa: E402
from ravh_sim.nodes import convert  # noqa: E402
from ravh_sim.nodes.common import LATCHED_QOS, SENSOR_QOS, STATE_QOS  # noqa: E402

HOUSE = "20"
TOPICS = {   # topic: (type, qos, expected frame_id or None)
    n.CLOCK: (Clock, STATE_QOS, None),
    n.SCAN: (LaserScan, SENSOR_QOS, n.LASER_FRAME),
    n.COLOR_IMAGE: (Image, SENSOR_QOS, n.CAMERA_OPTICAL_FRAME),
    n.COLOR_INFO: (CameraInfo, SENSOR_QOS, n.CAMERA_OPTICAL_FRAME),
    n.COLOR_COMPRESSED: (CompressedImage, SENSOR_QOS, n.CAMERA_OPTICAL_FRAME),
    n.DEPTH_IMAGE: (Image, SENSOR_QOS, n.CAMERA_OPTICAL_FRAME),
    n.DEPTH_INFO: (CameraInfo, SENSOR_QOS, n.CAMERA_OPTICAL_FRAME),
    n.INSTANCE_IMAGE: (Image, SENSOR_QOS, n.CAMERA_OPTICAL_FRAME),
    n.ODOM: (Odometry, STATE_QOS, n.ODOM_FRAME),
    n.GROUND_TRUTH_POSE: (PoseStamped, STATE_QOS, n.MAP_FRAME),
    n.ODOM_TRANSFORM: (TransformStamped, STATE_QOS, n.ODOM_FRAME),
    n.MAP_TO_ODOM: (TransformStamped, STATE_QOS, n.MAP_FRAME),
    n.ROOM: (String, LATCHED_QOS, None),
    n.INSTANCE_LABELS: (String, LATCHED_QOS, None),
    n.GROUND_TRUTH: (String, LATCHED_QOS, None),
}
RATES = {n.CLOCK: 100.0, n.SCAN: 10.0, n.COLOR_IMAGE: 10.0, n.DEPTH_IMAGE: 10.0, n.ODOM: 50.0}


def stamp_s(msg) -> float:
    return convert.seconds(msg.clock if isinstance(msg, Clock) else msg.header.stamp)


class Probe:
    """A test node that records every message of :data:`TOPICS`."""

    def __init__(self) -> None:
        start_rclpy()
        self.node = rclpy.create_node(f"probe_{time.monotonic_ns()}")
        self.got: dict[str, list] = {t: [] for t in TOPICS}
        for topic, (kind, qos, _) in TOPICS.items():
            self.node.create_subscription(kind, topic, lambda m, t=topic: self.got[t].append(m), qos)
        self.cmd = self.node.create_publisher(Twist, n.CMD_VEL, 10)

    def spin(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            rclpy.spin_once(self.node, timeout_sec=0.02)

    def call(self, srv_type, name: str, request, timeout: float = 10.0):
        client = self.node.create_client(srv_type, name)
        assert client.wait_for_service(timeout_sec=timeout), name
        future = client.call_async(request)
        rclpy.spin_until_future_complete(self.node, future, timeout_sec=timeout)
        self.node.destroy_client(client)
        assert future.done(), f"{name}: no reply"
        return future.result()

    def close(self) -> None:
        self.node.destroy_node()


@pytest.fixture(scope="module")
def sim():
    # every frame, so image rates in sim time are the camera's on a loaded machine too (the default,
    # dropping frames to keep real time, is tested in test_streaming.py)
    proc = NodeProcess("sim", "--house", HOUSE, "--seed", "0", "--frame-policy", "wait")
    probe = Probe()
    ok = spin_until(probe.node, lambda: len(probe.got[n.COLOR_IMAGE]) >= 3 and probe.got[n.GROUND_TRUTH], 90)
    assert ok, f"sim did not publish images:\n{proc.log()[-3000:]}"
    yield proc, probe
    probe.close()
    code = proc.stop()
    assert code == 0, f"sim did not stop cleanly on SIGINT (exit {code}):\n{proc.log()[-3000:]}"
    assert "Traceback" not in proc.log()


def test_every_topic_has_its_type_and_frame(sim):
    _, probe = sim
    probe.spin(2.0)
    for topic, (_, _, frame) in TOPICS.items():
        msgs = probe.got[topic]
        assert msgs, f"nothing on {topic}"
        if frame is not None:
            assert msgs[-1].header.frame_id == frame, topic
    assert probe.got[n.ODOM][-1].child_frame_id == n.BASE_FRAME
    assert probe.got[n.ODOM_TRANSFORM][-1].child_frame_id == n.BASE_FRAME
    rgb, depth, inst = (probe.got[t][-1] for t in (n.COLOR_IMAGE, n.DEPTH_IMAGE, n.INSTANCE_IMAGE))
    assert (rgb.encoding, depth.encoding, inst.encoding) == ("rgb8", "32FC1", "16UC1")
    assert (rgb.width, rgb.height) == (640, 480) and depth.step == 640 * 4


def test_rates_in_sim_time(sim):
    _, probe = sim
    for topic in RATES:
        probe.got[topic].clear()
    assert spin_until(probe.node, lambda: all(len(probe.got[t]) >= 10 for t in RATES), 60)
    for topic, rate in RATES.items():
        stamps = [stamp_s(m) for m in probe.got[topic]]
        measured = (len(stamps) - 1) / (stamps[-1] - stamps[0])
        assert measured == pytest.approx(rate, rel=0.1), topic


def test_one_capture_shares_one_stamp(sim):
    _, probe = sim
    topics = (n.COLOR_IMAGE, n.DEPTH_IMAGE, n.INSTANCE_IMAGE, n.COLOR_INFO, n.DEPTH_INFO, n.COLOR_COMPRESSED)

    def common() -> set:
        return set.intersection(*({stamp_s(m) for m in probe.got[t]} for t in topics))
    assert spin_until(probe.node, lambda: len(common()) >= 3, 60)


def test_camera_info_follows_the_papers_formula(sim):
    _, probe = sim
    k = probe.got[n.COLOR_INFO][-1].k
    assert k[0] == pytest.approx(18.0 * 640 / 21.0) and k[4] == pytest.approx(18.0 * 480 / 15.2)
    assert (k[2], k[5]) == (320.0, 240.0)


def test_depth_is_metres_and_scan_follows_rep117(sim):
    _, probe = sim
    depth = convert.image_array(probe.got[n.DEPTH_IMAGE][-1])
    assert depth.shape == (480, 640)
    valid = depth[np.isfinite(depth)]
    assert valid.size > 0.5 * depth.size and 0.05 < valid.min() and valid.max() < 25
    scan = probe.got[n.SCAN][-1]
    assert len(scan.ranges) == round((scan.angle_max - scan.angle_min) / scan.angle_increment) + 1 == 360
    finite = [r for r in scan.ranges if math.isfinite(r)]
    assert finite and all(scan.range_min <= r <= scan.range_max for r in finite)


def test_clock_advances(sim):
    """Sim time moves forward and never back; how fast depends on the machine's load, so no rate."""
    _, probe = sim
    before = stamp_s(probe.got[n.CLOCK][-1])
    seen = len(probe.got[n.CLOCK])
    assert spin_until(probe.node, lambda: stamp_s(probe.got[n.CLOCK][-1]) > before + 0.5, 60)
    stamps = [stamp_s(m) for m in probe.got[n.CLOCK][seen - 1:]]
    assert all(b > a for a, b in zip(stamps, stamps[1:]))


def test_cmd_vel_moves_the_robot(sim):
    _, probe = sim
    gt0 = convert.pose_of(probe.got[n.GROUND_TRUTH_POSE][-1].pose)
    odom0, _, _ = convert.odometry_of(probe.got[n.ODOM][-1])
    scan0 = convert.scan_of(probe.got[n.SCAN][-1]).ranges
    turn = Twist()
    turn.angular.z = 0.4

    def turned(p0, p) -> float:
        return abs(math.remainder(p[2] - p0[2], 2 * math.pi))

    def gt():
        return convert.pose_of(probe.got[n.GROUND_TRUTH_POSE][-1].pose)

    end = time.monotonic() + 60                   # however long half a radian takes on this machine
    while turned(gt0, gt()) < 0.5 and time.monotonic() < end:
        probe.cmd.publish(turn)
        probe.spin(0.1)
    assert turned(gt0, gt()) >= 0.5
    assert turned(odom0, convert.odometry_of(probe.got[n.ODOM][-1])[0]) > 0.3      # odometry saw the turn
    scan1 = convert.scan_of(probe.got[n.SCAN][-1]).ranges
    both = np.isfinite(scan0) & np.isfinite(scan1)
    assert np.abs(scan1[both] - scan0[both]).max() > 0.1


def test_map_reaches_a_late_subscriber(sim):
    _, probe = sim
    got = []
    sub = probe.node.create_subscription(OccupancyGrid, n.MAP, got.append, LATCHED_QOS)
    assert spin_until(probe.node, lambda: bool(got), 10)
    probe.node.destroy_subscription(sub)
    grid = convert.grid_of(got[-1])
    assert got[-1].header.frame_id == n.MAP_FRAME and grid.data.size == got[-1].info.width * got[-1].info.height
    assert set(np.unique(grid.data)) == {-1, 0, 100}


def test_ground_truth_query_answers(sim):
    _, probe = sim
    reply = probe.call(AddDiagnostics, n.QUERY_SERVICE, AddDiagnostics.Request(load_namespace='{"query": "rooms"}'))
    assert reply.success and len(json.loads(reply.message)["result"]) == 3
    bad = probe.call(AddDiagnostics, n.QUERY_SERVICE, AddDiagnostics.Request(load_namespace="{nope"))
    assert not bad.success and json.loads(bad.message)["error"]["code"] == "bad_json"


def test_client_helper(sim):
    _, probe = sim
    client = RavhClient(probe.node)
    assert client.wait_for_services(10)
    assert {r["type"] for r in client.query("rooms")} == {"KitchenLivingRoom", "Bedroom", "Bathroom"}


def test_get_plan_stays_in_free_space(sim):
    _, probe = sim
    grid = convert.grid_of(probe.call(GetMap, n.GET_FREE_SPACE_SERVICE, GetMap.Request()).map)
    free = np.argwhere(grid.data == FREE)
    start, goal = grid.center_of(*free[0]), grid.center_of(*free[-1])
    req = GetPlan.Request()
    req.start.pose.position.x, req.start.pose.position.y = start
    req.goal.pose.position.x, req.goal.pose.position.y = goal
    plan = probe.call(GetPlan, n.GET_PLAN_SERVICE, req).plan
    pts = [(p.pose.position.x, p.pose.position.y) for p in plan.poses]
    assert len(pts) >= 2 and plan.header.frame_id == n.MAP_FRAME
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        for t in np.linspace(0, 1, 20):
            assert grid.is_free(x0 + t * (x1 - x0), y0 + t * (y1 - y0))


def test_appearance_change_alters_the_next_image(sim):
    _, probe = sim

    def brightness() -> float:
        probe.got[n.COLOR_IMAGE].clear()
        spin_until(probe.node, lambda: len(probe.got[n.COLOR_IMAGE]) >= 2, 10)
        return float(convert.image_array(probe.got[n.COLOR_IMAGE][-1]).mean())

    day = brightness()
    reply = probe.call(AddDiagnostics, n.APPEARANCE_SERVICE,
                       AddDiagnostics.Request(load_namespace='{"sun_angle": "night", "lights": {"all": "off"}}'))
    assert reply.success, reply.message
    night = brightness()
    assert night < day - 20
    bad = probe.call(AddDiagnostics, n.APPEARANCE_SERVICE,
                     AddDiagnostics.Request(load_namespace='{"doors": {"Door_99": "open"}}'))
    assert not bad.success and "Door_0" in json.loads(bad.message)["error"]["valid"]
    probe.call(AddDiagnostics, n.APPEARANCE_SERVICE, AddDiagnostics.Request(load_namespace='{"sun_angle": "day"}'))


def test_capture_service_publishes_now(sim):
    _, probe = sim
    reply = probe.call(Trigger, n.CAPTURE_SERVICE, Trigger.Request())
    event = CaptureEvent.from_json(reply.message)
    assert reply.success and event.room and event.agent == n.DEFAULT_AGENT and len(event.pose) == 3


def test_bad_velocities_are_refused_with_a_warning(sim):
    proc, probe = sim
    for bad in (float("nan"), float("inf"), 1e9):
        t = Twist()
        t.linear.x = bad
        probe.cmd.publish(t)
    probe.spin(1.0)
    assert proc.alive()
    assert "rejected" in proc.log()


def test_oversized_requests_are_refused_and_not_kept(sim):
    """10 MB requests are refused by their length; the sim keeps no copy of them (its memory after six
    is what it was after two), and what stays is bounded (DDS buffers, not requests)."""
    proc, probe = sim

    def rss_mb() -> float:
        with open(f"/proc/{proc.proc.pid}/status") as f:
            return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:")) / 1024

    big = "x" * 10_000_000
    before = rss_mb()
    replies, after_two = [], 0.0
    for k in range(6):
        service = n.QUERY_SERVICE if k % 2 == 0 else n.APPEARANCE_SERVICE
        replies.append(probe.call(AddDiagnostics, service, AddDiagnostics.Request(load_namespace=big), timeout=60))
        if k == 1:
            after_two = rss_mb()
    after_six = rss_mb()
    assert all(not r.success and "over the limit" in r.message and len(r.message) < 1000 for r in replies)
    assert after_six - after_two < 5, (before, after_two, after_six)
    assert after_six - before < 40, (before, after_two, after_six)
    assert proc.alive()
