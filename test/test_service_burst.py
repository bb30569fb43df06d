"""The sim node under a burst of JSON requests (issue 24: at 50 appearance toggles a second, 684 of 1,001
requests got no reply and /clock fell from 99 to 30 Hz): every request is answered, made or refused as
"busy", and /clock keeps its rate."""
from __future__ import annotations

import json
import time

import pytest
import rclpy
from diagnostic_msgs.srv import AddDiagnostics
from rclpy.qos import QoSProfile
from rosgraph import NodeProcess, spin_until, start_rclpy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Image

from ravh_msgs_py import names as n
from ravh_msgs_py.client import RavhClient
from ravh_msgs_py.query import BUSY
from ravh_sim.nodes.appearance_budget import WorkBudget
from ravh_sim.nodes.common import SENSOR_QOS, STATE_QOS

BURST_HZ = 50.0
BURST_S = 8.0
KEEPS_RATE = 0.65       # /clock during the burst, of its rate around it (before the fix: 0.3-0.45; 2 loaded
                        # cores run the sim, its renderer's threads and this burst at once)


@pytest.fixture(scope="module")
def sim():
    proc = NodeProcess("sim", "--house", "20", "--seed", "0")
    start_rclpy()
    node = rclpy.create_node(f"burst_{time.monotonic_ns()}")
    clocks: list[float] = []
    node.create_subscription(Clock, n.CLOCK, lambda _m: clocks.append(time.monotonic()), STATE_QOS)
    # a camera subscriber: the sim renders frames (and redoes light maps after a change) only for one
    node.create_subscription(Image, n.COLOR_IMAGE, lambda _m: None, SENSOR_QOS)
    assert spin_until(node, lambda: len(clocks) > 50, 90), proc.log()[-3000:]
    yield proc, node, clocks
    node.destroy_node()
    assert proc.stop() == 0, proc.log()[-3000:]
    assert "Traceback" not in proc.log()


def _rate(clocks: list[float], start: float, end: float) -> float:
    return sum(start <= t <= end for t in clocks) / (end - start)


def _burst(node, service: str, bodies) -> tuple[list, float, float]:
    """Send ``bodies`` at BURST_HZ without waiting for replies; returns the futures and the burst's span."""
    client = node.create_client(AddDiagnostics, service, qos_profile=QoSProfile(depth=1000))
    assert client.wait_for_service(timeout_sec=30)
    futures, start = [], time.monotonic()
    for i, body in enumerate(bodies):
        while time.monotonic() < start + i / BURST_HZ:
            rclpy.spin_once(node, timeout_sec=0.002)
        futures.append(client.call_async(AddDiagnostics.Request(load_namespace=json.dumps(body))))
    end = time.monotonic()
    spin_until(node, lambda: all(f.done() for f in futures), 30)
    return futures, start, end


def test_a_burst_of_appearance_changes_is_answered_in_full_and_clock_keeps_its_rate(sim):
    proc, node, clocks = sim
    before = time.monotonic()
    spin_until(node, lambda: False, 4.0)
    toggles = [{"lights": {"ceiling": "on" if i % 2 else "off"}} for i in range(int(BURST_HZ * BURST_S))]
    futures, start, end = _burst(node, n.APPEARANCE_SERVICE, toggles)
    after = time.monotonic()
    spin_until(node, lambda: False, 4.0)
    baseline = (_rate(clocks, before, start) + _rate(clocks, after, time.monotonic())) / 2
    during = _rate(clocks, start, end)
    replies = [json.loads(f.result().message) for f in futures if f.done()]
    codes = [r["error"]["code"] if not r["ok"] else "ok" for r in replies]
    print(f"{len(futures)} requests: {codes.count('ok')} made, {codes.count(BUSY)} busy, "
          f"{len(futures) - len(replies)} unanswered; /clock {baseline:.0f} Hz around, {during:.0f} Hz during")
    assert len(replies) == len(futures)                       # every request answered
    assert set(codes) <= {"ok", BUSY} and codes.count("ok") >= 1 and codes.count(BUSY) > 0
    busy = next(r for r in replies if not r["ok"])["error"]["message"]
    assert "busy" in busy and "again" in busy
    assert during >= KEEPS_RATE * baseline
    client = RavhClient(node, timeout=30)                    # the client helper sends a busy change again
    assert client.appearance(lights={"ceiling": "on"})["settings"]["lights"]
    assert proc.alive()


def test_a_burst_of_queries_is_answered_in_full(sim):
    _, node, _ = sim
    futures, _, _ = _burst(node, n.QUERY_SERVICE, [{"query": "rooms"}] * 200)
    replies = [json.loads(f.result().message) for f in futures if f.done()]
    assert len(replies) == len(futures) and all(r["ok"] for r in replies)


def test_the_work_budget_refills_at_its_share():
    budget = WorkBudget(burst=0.5, share=0.1)
    assert budget.wait_s() == 0.0
    budget.spend(0.7)                                         # 0.2 s over: 2 s at 10 % to pay back
    assert budget.wait_s() == pytest.approx(2.0, abs=0.05)
    budget._at -= 3.0                                         # three seconds later
    assert budget.wait_s() == 0.0 and budget.level == pytest.approx(0.1, abs=0.01)
    budget._at -= 100.0
    assert budget.wait_s() == 0.0 and budget.level == 0.5      # never more than the burst
