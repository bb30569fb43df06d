"""The sim node as users see it: a real process, checked over real topics and services with rclpy."""
from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest
import rclpy
from diagnostic_msgs.srv import AddDiagnostics
from geometry_msgs.msg import PoseStamped, TransformStamped, Twist
from nav_msgs.msg import OccupancyGrid, Odometry
from nav_msgs.srv import GetMap, GetPlan
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from rosgraph import NodeProcess, spin_until, start_rclpy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, LaserScan
from std_msgs.msg import String
from std_srvs.srv import Trigger

from ravh_msgs_py import names as n
from ravh_msgs_py.capture import CaptureEvent
from ravh_msgs_py.client import RavhClient
from ravh_sim.nav.grid import FREE
from ravh_sim.nodes import convert
from ravh_sim.nodes.common import LATCHED_QOS, SENSOR_QOS, STATE_QOS

HOUSE = "20"
# REP 2003: map clients subscribe reliable and transient-local
REP2003_MAP = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
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

    def change(self, request: str, patience: float = 60.0):
        """An appearance change, sent again while the sim answers busy (its share of time for
        appearance changes is spent: issue 24), as RavhClient does; the last reply."""
        give_up = time.monotonic() + patience
        while True:
            reply = self.call(AddDiagnostics, n.APPEARANCE_SERVICE, AddDiagnostics.Request(load_namespace=request))
            busy = not reply.success and json.loads(reply.message)["error"]["code"] == "busy"
            if not busy or time.monotonic() > give_up:
                return reply
            spin_until(self.node, lambda: False, 0.5)

    def close(self) -> None:
        self.node.destroy_node()


@pytest.fixture(scope="module")
def sim():
    # every frame, so image rates in sim time are the camera's on a loaded machine too (the default,
    # dropping frames to keep real time, is tested in test_streaming.py)
    with NodeProcess("sim", "--house", HOUSE, "--seed", "0", "--frame-policy", "wait") as proc:
        probe = Probe()
        try:
            ok = spin_until(probe.node, lambda: len(probe.got[n.COLOR_IMAGE]) >= 3 and probe.got[n.GROUND_TRUTH], 90)
            assert ok, f"sim did not publish images:\n{proc.log()[-3000:]}"
            yield proc, probe
        finally:
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
    """Messages per second of sim time, counted by the publisher's sequence numbers: a subscriber
    starved on a loaded machine may drop messages, but the numbers of those it gets still count them."""
    _, probe = sim
    seen: dict[str, list[tuple[float, int]]] = {t: [] for t in RATES}
    subs = [probe.node.create_subscription(
        TOPICS[t][0], t, lambda m, info, t=t: seen[t].append((stamp_s(m), info["publication_sequence_number"])),
        TOPICS[t][1]) for t in RATES]
    try:
        assert spin_until(probe.node, lambda: all(len(v) >= 2 and v[-1][0] - v[0][0] >= 2.0 for v in seen.values()),
                          120)
    finally:
        for sub in subs:
            probe.node.destroy_subscription(sub)
    for topic, rate in RATES.items():
        (t0, seq0), (t1, seq1) = seen[topic][0], seen[topic][-1]
        assert (seq1 - seq0) / (t1 - t0) == pytest.approx(rate, rel=0.1), topic


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
    reply = probe.change('{"sun_angle": "night", "lights": {"all": "off"}}')
    assert reply.success, reply.message
    night = brightness()
    assert night < day - 20
    bad = probe.call(AddDiagnostics, n.APPEARANCE_SERVICE,
                     AddDiagnostics.Request(load_namespace='{"doors": {"Door_99": "open"}}'))
    assert not bad.success and "Door_0" in json.loads(bad.message)["error"]["valid"]
    assert probe.change('{"sun_angle": "day"}').success


def gt_pose(probe) -> tuple[float, float, float]:
    return convert.pose_of(probe.got[n.GROUND_TRUTH_POSE][-1].pose)


def sim_time(probe) -> float:
    return stamp_s(probe.got[n.CLOCK][-1])


def subscribe(probe, kind, topic: str, qos) -> list:
    """Messages of ``topic``, once the subscription has matched the sim's publisher."""
    got: list = []
    sub = probe.node.create_subscription(kind, topic, got.append, qos)
    assert spin_until(probe.node, lambda: sub.get_publisher_count() >= 1, 30), topic
    return got


def still(probe, sim_seconds: float) -> tuple[float, float, float]:
    """Wait until sim time has run ``sim_seconds`` on; the ground-truth pose then."""
    until = sim_time(probe) + sim_seconds
    assert spin_until(probe.node, lambda: stamp_s(probe.got[n.GROUND_TRUTH_POSE][-1]) > until, 60)
    return gt_pose(probe)


def test_capture_service_publishes_now(sim):
    """The reply's stamp is a capture that went out: the event, an image, a depth image and a scan of it."""
    _, probe = sim
    events = subscribe(probe, String, n.CAPTURE_EVENT, QoSProfile(depth=10))
    reply = probe.call(Trigger, n.CAPTURE_SERVICE, Trigger.Request())
    event = CaptureEvent.from_json(reply.message)
    assert reply.success and event.room and event.agent == n.DEFAULT_AGENT and len(event.pose) == 3

    def published(topic: str) -> bool:
        return any(stamp_s(m) == pytest.approx(event.stamp, abs=1e-6) for m in probe.got[topic])
    assert spin_until(probe.node, lambda: any(CaptureEvent.from_json(m.data).stamp == event.stamp for m in events)
                      and all(published(t) for t in (n.COLOR_IMAGE, n.DEPTH_IMAGE, n.SCAN)), 30)


def test_bad_velocities_are_refused_with_a_warning(sim):
    """NaN, inf and 1e9 m/s are refused (logged) and do not move the robot."""
    proc, probe = sim
    before = still(probe, 1.0)                        # at rest: the command timeout stopped earlier turns
    for bad in (float("nan"), float("inf"), 1e9):
        t = Twist()
        t.linear.x = bad
        probe.cmd.publish(t)
    assert spin_until(probe.node, lambda: "rejected" in proc.log(), 30)
    after = still(probe, 1.0)
    assert proc.alive()
    assert all(math.isfinite(v) for v in after) and math.dist(before[:2], after[:2]) < 1e-3


def test_commands_stop_half_a_second_after_the_last_one(sim):
    """A robot whose cmd_vel stops is stopped CMD_TIMEOUT_S (0.5 s of sim time) later: it turns while
    commanded, then its heading holds still."""
    _, probe = sim
    start = still(probe, 0.2)
    turn = Twist()
    turn.angular.z = 0.5
    end = time.monotonic() + 60
    while abs(math.remainder(gt_pose(probe)[2] - start[2], 2 * math.pi)) < 0.2 and time.monotonic() < end:
        probe.cmd.publish(turn)
        spin_until(probe.node, lambda: False, 0.05)
    last_command = sim_time(probe)              # the sim got the last command at this sim time or later
    assert spin_until(probe.node, lambda: stamp_s(probe.got[n.GROUND_TRUTH_POSE][-1]) > last_command + 4.0, 120)

    def headings(t0: float, t1: float) -> list[float]:
        return [convert.pose_of(m.pose)[2] for m in probe.got[n.GROUND_TRUTH_POSE]
                if last_command + t0 <= stamp_s(m) <= last_command + t1]
    early, late = headings(0.05, 0.45), headings(2.0, 4.0)
    assert len(early) >= 5 and abs(math.remainder(early[-1] - early[0], 2 * math.pi)) > 0.05   # still turning
    assert len(late) >= 10 and max(late) - min(late) < 1e-3                                  # stopped


def test_map_is_republished_when_a_door_changes(sim):
    """Closing a door is an obstacle on the next /map: the map changes where the door is, and opening it
    again gives the first map back."""
    _, probe = sim
    maps = subscribe(probe, OccupancyGrid, n.MAP, REP2003_MAP)
    assert spin_until(probe.node, lambda: bool(maps), 10)
    door = json.loads(probe.call(AddDiagnostics, n.QUERY_SERVICE, AddDiagnostics.Request(
        load_namespace='{"query": "door", "id": "Door_0"}')).message)["result"]
    first = convert.grid_of(maps[-1])
    flip = "closed" if door["open"] else "open"
    for state, count in ((flip, 2), ("open" if flip == "closed" else "closed", 3)):
        reply = probe.change(json.dumps({"doors": {"Door_0": state}}))
        assert reply.success, reply.message
        assert spin_until(probe.node, lambda c=count: len(maps) >= c, 30), f"no /map after Door_0 {state}"
    changed, back = convert.grid_of(maps[1]), convert.grid_of(maps[2])
    differ = np.argwhere(changed.data != first.data)
    assert len(differ) > 0 and np.array_equal(back.data, first.data)
    x, y = door["position"][:2]
    assert min(math.dist((x, y), changed.center_of(r, c)) for r, c in differ) < door["width"]


def test_free_space_is_the_obstacle_map_shrunk_by_the_robot(sim):
    """/ravh/free_space (latched) is the GetFreeSpace map; every free cell of it is free on /map, it is
    smaller (inflated by the robot's radius), and the robot stands in it."""
    _, probe = sim
    free = subscribe(probe, OccupancyGrid, n.FREE_SPACE_MAP, REP2003_MAP)
    maps = subscribe(probe, OccupancyGrid, n.MAP, REP2003_MAP)
    assert spin_until(probe.node, lambda: bool(free) and bool(maps), 10)
    assert free[-1].header.frame_id == n.MAP_FRAME
    grid, obstacles = convert.grid_of(free[-1]), convert.grid_of(maps[-1])
    served = convert.grid_of(probe.call(GetMap, n.GET_FREE_SPACE_SERVICE, GetMap.Request()).map)
    assert np.array_equal(grid.data, served.data)
    assert grid.data.shape == obstacles.data.shape and grid.origin == pytest.approx(obstacles.origin)
    assert np.all(obstacles.data[grid.data == FREE] == FREE)
    assert 0.2 * (obstacles.data == FREE).sum() < (grid.data == FREE).sum() < 0.95 * (obstacles.data == FREE).sum()
    assert grid.is_free(*gt_pose(probe)[:2])


def test_reset_puts_the_robot_back_and_undoes_appearance(sim):
    """/ravh/reset: the robot is back at its start pose (the footprint's), a closed door is as the
    settings say again."""
    _, probe = sim
    footprint = json.loads(probe.got[n.GROUND_TRUTH][-1].data)
    start = footprint["settings"]["agents"][0]["pose"]
    initial_door = footprint["settings"]["doors"]["Door_1"]
    changed = "closed" if initial_door else "open"
    assert probe.change(json.dumps({"doors": {"Door_1": changed}})).success
    forward = Twist()
    forward.angular.z = 0.5
    end = time.monotonic() + 60
    while abs(math.remainder(gt_pose(probe)[2] - start[2], 2 * math.pi)) < 0.3 and time.monotonic() < end:
        probe.cmd.publish(forward)
        spin_until(probe.node, lambda: False, 0.05)
    assert abs(math.remainder(gt_pose(probe)[2] - start[2], 2 * math.pi)) >= 0.3    # away from the start
    assert probe.call(Trigger, n.RESET_SERVICE, Trigger.Request()).success
    x, y, yaw = still(probe, 0.2)
    assert math.dist((x, y), start[:2]) < 0.01 and abs(math.remainder(yaw - start[2], 2 * math.pi)) < 0.01
    door = json.loads(probe.call(AddDiagnostics, n.QUERY_SERVICE, AddDiagnostics.Request(
        load_namespace='{"query": "door", "id": "Door_1"}')).message)["result"]
    assert door["open"] == initial_door


def test_qos_offered_follows_rep_2003(sim):
    """What the sim offers, read from the graph and compared with REP 2003's values (not with the
    node's own constants): sensor data reliable and volatile (SystemDefaultsQoS), so both sensor-data
    (best-effort) and reliable subscribers match; maps and other latched data reliable and
    transient-local, so late joiners get them. A best-effort SensorDataQoS subscriber gets scans."""
    _, probe = sim
    expected = {**{t: ("RELIABLE", "VOLATILE") for t in (n.SCAN, n.COLOR_IMAGE, n.DEPTH_IMAGE, n.INSTANCE_IMAGE,
                                                      n.COLOR_INFO, n.ODOM)},
                **{t: ("RELIABLE", "TRANSIENT_LOCAL") for t in (n.MAP, n.FREE_SPACE_MAP, n.TF_STATIC,
                                                             n.GROUND_TRUTH)}}
    for topic, (reliability, durability) in expected.items():
        name = topic if topic.startswith("/") else "/" + topic
        offered = [i.qos_profile for i in probe.node.get_publishers_info_by_topic(name)]
        assert offered, topic
        assert {(q.reliability.name, q.durability.name) for q in offered} == {(reliability, durability)}, topic
    scans = subscribe(probe, LaserScan, n.SCAN, qos_profile_sensor_data)
    assert spin_until(probe.node, lambda: len(scans) >= 3, 30)


def test_oversized_requests_are_refused_and_not_kept(sim):
    """10 MB requests are refused by their length; the sim keeps no copy of them (eight more after the
    first two add less than two of them would: its allocator and renders move RSS by a few MB on their
    own), and what stays is bounded (DDS buffers, not requests)."""
    proc, probe = sim

    def rss_mb() -> float:
        with open(f"/proc/{proc.proc.pid}/status") as f:
            return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:")) / 1024

    big = "x" * 10_000_000
    before = rss_mb()
    replies, after_two = [], 0.0
    for k in range(10):
        service = n.QUERY_SERVICE if k % 2 == 0 else n.APPEARANCE_SERVICE
        replies.append(probe.call(AddDiagnostics, service, AddDiagnostics.Request(load_namespace=big), timeout=60))
        if k == 1:
            after_two = rss_mb()
    after_ten = rss_mb()
    assert all(not r.success and "over the limit" in r.message and len(r.message) < 1000 for r in replies)
    assert after_ten - after_two < 2 * len(big) / 1e6, (before, after_two, after_ten)
    assert after_ten - before < 40, (before, after_two, after_ten)
    assert proc.alive()


def test_get_plan_takes_start_and_goal_in_odom_or_an_agent_frame(sim):
    """Issue 24: a start stamped in odom or base_link was planned as if it were in map. (Last: its refusals
    are logged as warnings, which are throttled.)"""
    _, probe = sim
    probe.got[n.GROUND_TRUTH_POSE].clear()
    assert spin_until(probe.node, lambda: probe.got[n.GROUND_TRUTH_POSE], 10)
    truth = probe.got[n.GROUND_TRUTH_POSE][-1].pose.position

    grid = convert.grid_of(probe.call(GetMap, n.GET_FREE_SPACE_SERVICE, GetMap.Request()).map)
    free = grid.center_of(*np.argwhere(grid.data == FREE)[-1])

    def plan(start_frame: str, goal_frame: str = n.MAP_FRAME, goal=free, start=(0.0, 0.0)) -> list[tuple[float, float]]:
        req = GetPlan.Request()
        req.start.header.frame_id, req.goal.header.frame_id = start_frame, goal_frame
        req.start.pose.position.x, req.start.pose.position.y = start
        req.goal.pose.position.x, req.goal.pose.position.y = goal
        reply = probe.call(GetPlan, n.GET_PLAN_SERVICE, req).plan
        assert reply.header.frame_id == n.MAP_FRAME
        return [(p.pose.position.x, p.pose.position.y) for p in reply.poses]

    from_robot = plan(n.BASE_FRAME)                             # (0, 0) in base_link: where the robot is
    assert from_robot and math.dist(from_robot[0], (truth.x, truth.y)) < 0.1
    assert plan(n.LASER_FRAME)[0] == pytest.approx(from_robot[0], abs=1e-6)
    assert plan(n.MAP_FRAME)[:1] != from_robot[:1]              # (0, 0) in map is elsewhere (or no start)
    to_robot = plan(n.MAP_FRAME, n.BASE_FRAME, goal=(0.0, 0.0), start=free)
    assert math.dist(to_robot[-1], (truth.x, truth.y)) < 0.1
    assert plan("kitchen") == [] and plan(n.MAP_FRAME, "odom_combined") == []     # unknown: refused
