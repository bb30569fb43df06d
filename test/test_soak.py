"""Soak: a running sim keeps serving new subscribers and service clients through churn and CPU overload.

Issue 12 item 8: once, under heavy load, a sim stopped answering every new subscriber and client while
its loop kept running. This test reproduces the conditions, bounded in time (~40 s): busy-loop
processes overload the CPUs while hundreds of /clock subscriptions and service clients join and leave,
and whole participants join, leave and are SIGKILLed; afterwards fresh processes must still get /clock,
a service reply and the sim in the node list.
"""
from __future__ import annotations

import json
import subprocess
import sys
import time

import rclpy
from diagnostic_msgs.srv import AddDiagnostics
from rosgraph import NodeProcess, read_line, remove_orphan_shm, ros_env, spin_until, start_rclpy
from rosgraph_msgs.msg import Clock

from ravh_msgs_py import names as n
from ravh_sim.nodes.common import STATE_QOS

BURNERS = 3                    # busy-loop processes: with the sim and this test, ~3x the CPUs of a 2-core box
CHURN_S = 20.0                 # wall seconds of subscription and client churn (at least MIN_JOINS joins)
MIN_JOINS = 200
JOIN_TIMEOUT_S = 10.0          # a new subscriber must get /clock within this, even overloaded

# A fresh participant: first /clock, one query reply, the sim in the graph; prints what it got.
JOINER = """
import json, sys, time, rclpy
from rosgraph_msgs.msg import Clock
from diagnostic_msgs.srv import AddDiagnostics
rclpy.init()
node = rclpy.create_node("soak_joiner")
got = []
node.create_subscription(Clock, "/clock", got.append, 10)
end = time.monotonic() + 30
while not got and time.monotonic() < end:
    rclpy.spin_once(node, timeout_sec=0.05)
client = node.create_client(AddDiagnostics, "/ravh/query")
ok = client.wait_for_service(timeout_sec=30)
reply = None
if ok:
    future = client.call_async(AddDiagnostics.Request(load_namespace='{"query": "rooms"}'))
    rclpy.spin_until_future_complete(node, future, timeout_sec=30)
    reply = future.result().success if future.done() else None
end = time.monotonic() + 10               # the node list fills in as discovery data arrives
while "ravh_sim" not in node.get_node_names() and time.monotonic() < end:
    rclpy.spin_once(node, timeout_sec=0.05)
print(json.dumps({"clock": bool(got), "reply": reply, "graph": "ravh_sim" in node.get_node_names()}), flush=True)
if sys.argv[1] == "hold":
    time.sleep(120)                       # until the test SIGKILLs it
node.destroy_node()
rclpy.shutdown()
"""


def joiner(mode: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", JOINER, mode], env=ros_env(), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)


def fresh_participants_are_served(count: int) -> list[dict]:
    procs = [joiner("once") for _ in range(count)]
    results = []
    for p in procs:
        out, _ = p.communicate(timeout=90)
        results.append(json.loads(out.strip().splitlines()[-1]))
    return results


def test_sim_serves_newcomers_through_churn_and_overload():
    started = time.time()
    proc = NodeProcess("sim", "--house", "20", "--seed", "0", "--camera-rate", "2")
    burn = f"import time\nend = time.monotonic() + {CHURN_S + 60}\nwhile time.monotonic() < end: pass"
    burners = [subprocess.Popen([sys.executable, "-c", burn]) for _ in range(BURNERS)]
    start_rclpy()
    node = rclpy.create_node("soak_probe")
    killed: list[subprocess.Popen] = []
    try:
        first: list[Clock] = []
        sub = node.create_subscription(Clock, n.CLOCK, first.append, STATE_QOS)
        assert spin_until(node, lambda: bool(first), 90), proc.log()[-3000:]
        node.destroy_subscription(sub)

        killed = [joiner("hold") for _ in range(3)]              # participants that will die uncleanly
        joins, calls, waits = 0, 0, []
        end = time.monotonic() + CHURN_S
        while time.monotonic() < end or joins < MIN_JOINS:
            got: list[Clock] = []
            t0 = time.monotonic()
            sub = node.create_subscription(Clock, n.CLOCK, got.append, STATE_QOS)
            joined = spin_until(node, lambda: bool(got), JOIN_TIMEOUT_S)  # noqa: B023 (waited for here)
            assert joined, f"join {joins}: no /clock in {JOIN_TIMEOUT_S} s\n{proc.log()[-3000:]}"
            waits.append(time.monotonic() - t0)
            node.destroy_subscription(sub)
            joins += 1
            if joins % 10 == 0:
                client = node.create_client(AddDiagnostics, n.QUERY_SERVICE)
                assert client.wait_for_service(timeout_sec=JOIN_TIMEOUT_S), f"call {calls}: no service"
                future = client.call_async(AddDiagnostics.Request(load_namespace='{"query": "rooms"}'))
                rclpy.spin_until_future_complete(node, future, timeout_sec=JOIN_TIMEOUT_S)
                assert future.done() and future.result().success, f"call {calls}: no reply"
                node.destroy_client(client)
                calls += 1
        for p in killed:                                          # each subscribed and served, then SIGKILLed
            line = read_line(p.stdout, 90)
            p.kill()
            p.wait()
            assert line and json.loads(line) == {"clock": True, "reply": True, "graph": True}, \
                f"a held participant was not served: {line!r}"
        waits.sort()
        print(f"soak: {joins} joins, {calls} service clients; first /clock after median "
              f"{waits[len(waits) // 2] * 1000:.0f} ms, max {waits[-1] * 1000:.0f} ms")
        assert joins >= MIN_JOINS and calls >= MIN_JOINS // 10
        for result in fresh_participants_are_served(3):
            assert result == {"clock": True, "reply": True, "graph": True}, (result, proc.log()[-3000:])
    finally:
        for b in burners:
            b.kill()
            b.wait()
        for p in killed:
            p.kill()
            p.wait()
        node.destroy_node()
        code = proc.stop()
        remove_orphan_shm(started)
    assert code == 0, proc.log()[-3000:]
    assert proc.log().count("Traceback") == 0
