"""Property-based fuzzing of a running sim node: thousands of random requests, the node never dies.

Random JSON (well-formed and not) goes to the query and appearance services and random floats to
cmd_vel; every reply must be a well-formed envelope, and afterwards the node still runs and answers.
"""
from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rosgraph import NodeProcess, spin_until, start_rclpy

rclpy = pytest.importorskip("rclpy")

from diagnostic_msgs.srv import AddDiagnostics  # noqa: E402
from geometry_msgs.msg import Twist  # noqa: E402

from ravh_msgs_py import names as n  # noqa: E402
from ravh_msgs_py.query import QUERIES  # noqa: E402

WORDS = ["Door_0", "Door_1", "Bed_0", "Chair_0", "Light_0", "Bedroom_1", "Bathroom_1", "all", "ceiling",
         "lamps", "random", "on", "off", "open", "closed", "walls", "floor", "brick", "#ff0000", "night"]
KEYS = ["query", "id", "room", "tag", "type", "x", "y", "open_only", "sun_angle", "lights", "doors",
        "paint", "models", "seed", "randomise", *QUERIES]
scalars = (st.none() | st.booleans() | st.integers(-10**12, 10**12) | st.floats(allow_nan=True)
           | st.sampled_from(WORDS) | st.text(max_size=12))
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
    proc = NodeProcess("sim", "--house", "20", "--camera-rate", "0")
    start_rclpy()
    probe = rclpy.create_node("fuzzer")
    clients = {name: probe.create_client(AddDiagnostics, name) for name in (n.QUERY_SERVICE, n.APPEARANCE_SERVICE)}
    assert all(c.wait_for_service(timeout_sec=90) for c in clients.values()), proc.log()[-2000:]
    yield proc, probe, clients, probe.create_publisher(Twist, n.CMD_VEL, 10)
    probe.destroy_node()
    assert proc.stop() == 0, proc.log()[-3000:]
    assert "Traceback" not in proc.log()


def call(probe, client, text: str) -> dict:
    future = client.call_async(AddDiagnostics.Request(load_namespace=text))
    assert spin_until(probe, future.done, 20), "no reply"
    reply = json.loads(future.result().message)
    assert set(reply) == ({"ok", "result"} if reply["ok"] else {"ok", "error"})
    assert future.result().success == reply["ok"]
    if not reply["ok"]:
        assert reply["error"]["code"] and reply["error"]["message"]
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
    _, probe, _, cmd = node
    msg = Twist()
    msg.linear.x, msg.angular.z = v, w
    cmd.publish(msg)
    rclpy.spin_once(probe, timeout_sec=0)


def test_node_survives_and_still_answers(node):
    proc, probe, clients, _ = node
    assert proc.alive()
    reply = call(probe, clients[n.QUERY_SERVICE], '{"query": "counts"}')
    assert reply["ok"] and reply["result"]["rooms"] == 3
    assert call(probe, clients[n.QUERY_SERVICE], '{"query": "room_at", "x": 0, "y": 0}')["ok"] is True
