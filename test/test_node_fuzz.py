"""Property-based fuzzing of a running sim node: thousands of random requests, the node never dies.

Random JSON (well-formed and not, extremes included: +-1e308, NaN, inf, 5e-324, 10 MB strings) goes to
the query and appearance services, random points to GetPlan and random floats to cmd_vel; every reply
must be a well-formed envelope that never says ``internal``, and afterwards every service still answers.
"""
from __future__ import annotations

import json
import math

import pytest
import rclpy
from diagnostic_msgs.srv import AddDiagnostics
from geometry_msgs.msg import PoseStamped, Twist
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from nav_msgs.srv import GetMap, GetPlan
from rclpy.qos import QoSProfile
from rosgraph import NodeProcess, spin_until, start_rclpy
from std_srvs.srv import Trigger

from ravh_msgs_py import names as n
from ravh_msgs_py.query import QUERIES

WORDS = ["Door_0", "Door_1", "Bed_0", "Chair_0", "Light_0", "Bedroom_1", "Bathroom_1", "all", "ceiling",
         "lamps", "random", "on", "off", "open", "closed", "walls", "floor", "brick", "#ff0000", "night"]
KEYS = ["query", "id", "room", "tag", "type", "x", "y", "open_only", "sun_angle", "lights", "doors",
        "paint", "models", "seed", "randomise", *QUERIES]
EXTREMES = [1e308, -1e308, float("nan"), float("inf"), -float("inf"), 5e-324, -5e-324, 10**400, -(2**64)]
HUGE = "x" * 10_000_000
floats = st.floats(allow_nan=True, allow_infinity=True) | st.sampled_from(EXTREMES[:7])
scalars = (st.none() | st.booleans() | st.integers(-10**12, 10**12) | st.floats(allow_nan=True)
           | st.sampled_from(WORDS) | st.text(max_size=12) | st.sampled_from(EXTREMES))
values = st.recursive(scalars, lambda kids: st.lists(kids, max_size=3)
                      | st.dictionaries(st.sampled_from(KEYS + WORDS), kids, max_size=3), max_leaves=8)
requests = st.dictionaries(st.sampled_from(KEYS), values, max_size=4)
texts = requests.map(lambda d: json.dumps(d, allow_nan=True)) | st.text(max_size=40)
# appearance changes that rebuild every object are slow; keep the fuzz to cheap ones plus a few models
cheap_appearance = st.fixed_dictionaries({}, optional={
    "sun_angle": st.floats(-100, 500) | st.sampled_from(["day", "night", "noon", "random"]),
    "lights": st.dictionaries(st.sampled_from(["all", "ceiling", "Light_0", "Lamp_9"]),
                              st.sampled_from(["on", "off", "random", "dim", 3]), max_size=2),
    "doors": st.dictionaries(st.sampled_from(["Door_0", "Door_1", "Door_8", "all"]),
                             st.sampled_from(["open", "closed", "random", None]), max_size=2),
    "paint": st.dictionaries(st.sampled_from(["Bedroom_1", "Attic_1"]),
                             st.dictionaries(st.sampled_from(["walls", "floor", "roof"]),
                                             st.sampled_from(["brick", "plaid", "#00ff00", "random", 7])),
                             max_size=1),
    "models": st.dictionaries(st.sampled_from(["Bed_0", "Chair_0", "Ghost_1"]),
                              st.integers(-2, 9) | st.sampled_from(["random", "default", "x"]), max_size=1),
    "seed": st.integers(-5, 10**6) | st.text(max_size=3),
})


@pytest.fixture(scope="module")
def node():
    with NodeProcess("sim", "--house", "20", "--camera-rate", "0") as proc:
        start_rclpy()
        probe = rclpy.create_node("fuzzer")
        try:
            clients = {name: probe.create_client(AddDiagnostics, name)
                       for name in (n.QUERY_SERVICE, n.APPEARANCE_SERVICE)}
            clients.update({n.GET_PLAN_SERVICE: probe.create_client(GetPlan, n.GET_PLAN_SERVICE),
                            n.GET_MAP_SERVICE: probe.create_client(GetMap, n.GET_MAP_SERVICE),
                            n.RESET_SERVICE: probe.create_client(Trigger, n.RESET_SERVICE),
                            n.CAPTURE_SERVICE: probe.create_client(Trigger, n.CAPTURE_SERVICE)})
            assert all(c.wait_for_service(timeout_sec=90) for c in clients.values()), proc.log()[-2000:]
            yield proc, probe, clients, probe.create_publisher(Twist, n.CMD_VEL, 10)
        finally:
            probe.destroy_node()
        assert proc.stop() == 0, proc.log()[-3000:]
    assert "Traceback" not in proc.log()


def answer(probe, client, request):
    future = client.call_async(request)
    assert spin_until(probe, future.done, 60), "no reply"
    return future.result()


def call(probe, client, text: str) -> dict:
    result = answer(probe, client, AddDiagnostics.Request(load_namespace=text))
    reply = json.loads(result.message)
    assert set(reply) == ({"ok", "result"} if reply["ok"] else {"ok", "error"})
    assert result.success == reply["ok"]
    if not reply["ok"]:
        assert reply["error"]["code"] and reply["error"]["message"]
        assert reply["error"]["code"] != "internal", reply
        assert len(result.message) < 20_000          # a huge request is never echoed back
    return reply


FUZZ = settings(max_examples=1500, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)


@FUZZ
@given(text=texts)
def test_random_queries_get_envelopes(node, text):
    _, probe, clients, _ = node
    call(probe, clients[n.QUERY_SERVICE], text)


@settings(max_examples=400, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
@given(req=cheap_appearance | texts)
def test_random_appearance_changes_get_envelopes(node, req):
    _, probe, clients, _ = node
    call(probe, clients[n.APPEARANCE_SERVICE], req if isinstance(req, str) else json.dumps(req, allow_nan=True))


@FUZZ
@given(v=st.floats(allow_nan=True, allow_infinity=True), w=st.floats(allow_nan=True, allow_infinity=True))
def test_random_velocities_never_hurt(node, v, w):
    proc, probe, _, cmd = node
    msg = Twist()
    msg.linear.x, msg.angular.z = v, w
    cmd.publish(msg)
    rclpy.spin_once(probe, timeout_sec=0)
    assert proc.alive(), proc.log()[-3000:]


def test_after_random_velocities_the_robot_is_whole_and_inside_the_house(node):
    """What the velocities above did: the robot's true pose is finite and inside a room of house 20."""
    _, probe, clients, cmd = node
    cmd.publish(Twist())
    poses: list[PoseStamped] = []
    sub = probe.create_subscription(PoseStamped, n.GROUND_TRUTH_POSE, poses.append, QoSProfile(depth=10))
    try:
        assert spin_until(probe, lambda: len(poses) >= 3, 60)
    finally:
        probe.destroy_subscription(sub)
    p, q = poses[-1].pose.position, poses[-1].pose.orientation
    assert all(math.isfinite(v) for v in (p.x, p.y, p.z, q.z, q.w))
    room = call(probe, clients[n.QUERY_SERVICE], json.dumps({"query": "room_at", "x": p.x, "y": p.y}))
    assert room["ok"] and room["result"] is not None, (p.x, p.y)


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
@given(points=st.lists(floats, min_size=4, max_size=4))
def test_random_plans_never_hurt(node, points):
    _, probe, clients, _ = node
    request = GetPlan.Request()
    p = request.start.pose.position, request.goal.pose.position
    p[0].x, p[0].y, p[1].x, p[1].y = points
    answer(probe, clients[n.GET_PLAN_SERVICE], request)


@pytest.mark.parametrize("service", [n.QUERY_SERVICE, n.APPEARANCE_SERVICE])
@pytest.mark.parametrize("text", [HUGE, json.dumps({"query": HUGE}), json.dumps({"query": "room", "id": HUGE}),
                                  json.dumps({"sun_angle": 1e308, "seed": 10**400}), "[" * 100_000])
def test_huge_and_deep_requests_get_short_errors(node, service, text):
    _, probe, clients, _ = node
    assert call(probe, clients[service], text)["ok"] is False


def test_node_survives_and_still_answers(node):
    proc, probe, clients, _ = node
    assert proc.alive()
    reply = call(probe, clients[n.QUERY_SERVICE], '{"query": "counts"}')
    assert reply["ok"] and reply["result"]["rooms"] == 3
    assert call(probe, clients[n.QUERY_SERVICE], '{"query": "room_at", "x": 0, "y": 0}')["ok"] is True
    assert answer(probe, clients[n.RESET_SERVICE], Trigger.Request()).success      # undo the fuzzed appearance
    request = GetPlan.Request()
    request.start.pose.position.x, request.start.pose.position.y = -3.0, 1.2
    request.goal.pose.position.x, request.goal.pose.position.y = -5.0, 0.0
    assert len(answer(probe, clients[n.GET_PLAN_SERVICE], request).plan.poses) > 2
    assert answer(probe, clients[n.GET_MAP_SERVICE], GetMap.Request()).map.info.width > 0
    assert answer(probe, clients[n.CAPTURE_SERVICE], Trigger.Request()).success
