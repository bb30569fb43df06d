"""What every node shares (ravh_sim.nodes.common): a stop signal ends a node cleanly whatever it is doing."""
from __future__ import annotations

import signal
import subprocess
import sys

import pytest
from conftest import ROOT
from rosgraph import read_line, ros_env

# A node that sends itself SIGINT at the worst instant: while rclpy converts a message it took (the
# message class's __init__ runs inside rclpy's C++ take_message). A KeyboardInterrupt raised there
# comes out of pybind11 as a RuntimeError, which is what a loaded machine made of Ctrl-C now and then.
NODE = """
import os, signal, sys
from rclpy.node import Node
from std_msgs.msg import _string
from std_msgs.msg import String
from ravh_sim.nodes.common import run_node

class SignalsWhileTaking(Node):
    def __init__(self):
        super().__init__("signals_while_taking")
        self.pub = self.create_publisher(String, "signals_while_taking", 10)
        self.create_subscription(String, "signals_while_taking", lambda m: None, 10)
        self.create_timer(0.05, lambda: self.pub.publish(String(data="x")))
        self.armed = True

node = None
original_init = _string.String.__init__

def init_then_signal(self, *args, **kwargs):
    original_init(self, *args, **kwargs)
    if not args and not kwargs and node is not None and node.armed:   # rclpy's conversion, not our publish
        node.armed = False
        print("signalled while taking", flush=True)
        os.kill(os.getpid(), signal.SIGINT)
        sum(range(1000))                  # Python runs the signal handler here, inside the conversion

_string.String.__init__ = init_then_signal

def make(_args):
    global node
    node = SignalsWhileTaking()
    return node

sys.exit(run_node(make, ["signals_while_taking"]))
"""


def test_sigint_while_a_message_is_taken_exits_cleanly():
    proc = subprocess.run([sys.executable, "-c", NODE], cwd=ROOT, env=ros_env(), capture_output=True, text=True,
                          timeout=120)
    output = proc.stdout + proc.stderr
    assert "signalled while taking" in output, output      # the signal did come at that instant
    assert proc.returncode == 0, output
    assert "Traceback" not in output, output


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_signal_while_spinning_closes_the_node(signum):
    node = ("import sys\nfrom rclpy.node import Node\nfrom ravh_sim.nodes.common import run_node\n"
            "class Busy(Node):\n"
            "    def __init__(self):\n"
            "        super().__init__('busy')\n"
            "        self.create_timer(0.001, lambda: print('spinning', flush=True) or sum(range(10000)))\n"
            "    def close(self):\n"
            "        print('closed', flush=True)\n"
            "sys.exit(run_node(lambda _args: Busy(), ['busy']))\n")
    proc = subprocess.Popen([sys.executable, "-c", node], cwd=ROOT, env=ros_env(), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    assert proc.stdout is not None
    try:
        first = read_line(proc.stdout, 120)
        proc.send_signal(signum)
        rest = proc.communicate(timeout=60)[0]
    finally:
        proc.kill()
        proc.wait()
    assert first == "spinning\n", first + rest
    assert proc.returncode == 0, rest
    assert "closed" in rest and "Traceback" not in rest, rest


def test_spinning_until_a_behaviour_ends_keeps_nothing_per_callback():
    """rclpy's spin_until_future_complete adds a done-callback to the future at every spin: a behaviour
    node waiting on its ``finished`` future grew ~30 KB per capture. Ours keeps nothing per callback."""
    import tracemalloc

    import rclpy
    from rclpy.task import Future
    from rosgraph import start_rclpy

    from ravh_sim.nodes.common import StopSignals, spin_until_stopped

    start_rclpy()
    node = rclpy.create_node("spin_memory")
    ticks = [0]
    goal = [0]

    def tick() -> None:
        ticks[0] += 1
        if ticks[0] >= goal[0] and not node.finished.done():
            node.finished.set_result(True)

    node.create_timer(0.0005, tick)
    stop = StopSignals()
    tracemalloc.start()
    try:
        sizes = []
        for more in (300, 3000):
            node.finished, goal[0] = Future(), ticks[0] + more
            spin_until_stopped(node, stop)
            sizes.append(tracemalloc.get_traced_memory()[0])
    finally:
        tracemalloc.stop()
        stop.restore()
        rclpy.get_global_executor().remove_node(node)
        node.destroy_node()
    assert sizes[1] - sizes[0] < 50_000, sizes          # with rclpy.spin_until_future_complete: +80 KB


def test_a_stopped_node_first_finishes_the_requests_it_took():
    """After a stop signal the node is still spun while its ``in_flight()`` says a request it took is
    unfinished (the sim's capture waiting for its frame), and no longer than that."""
    import rclpy
    from rosgraph import start_rclpy

    from ravh_sim.nodes.common import StopSignals, spin_until_stopped

    start_rclpy()
    node = rclpy.create_node("drain")
    ticks = [0]
    node.create_timer(0.001, lambda: ticks.__setitem__(0, ticks[0] + 1))
    node.in_flight = lambda: ticks[0] < 20          # the request ends on the 20th turn
    stop = StopSignals()
    stop.requested = True                           # the stop came before the first spin
    try:
        spin_until_stopped(node, stop)
    finally:
        stop.restore()
        rclpy.get_global_executor().remove_node(node)
        node.destroy_node()
    assert ticks[0] == 20
