"""The behaviour node's hand-over with the recorder (--wait-recorder), without a running ROS graph."""
from __future__ import annotations

import json
from types import SimpleNamespace

import pytest
from rclpy.task import Future
from std_msgs.msg import String

from ravh_sim.nodes.behaviour_node import BehaviourNode


def waiting_node() -> BehaviourNode:
    """A BehaviourNode's hand-over state only (no sim to wait for): --wait-recorder, behaviour running."""
    node = object.__new__(BehaviourNode)
    logged: list[str] = []
    node.__dict__.update(wait_recorder=True, lockstep=False, capture_count=0, finished=Future(), _pending=set(),
                         _unrecorded={}, _recorded_early=set(), _rooms_seen=set(), _log_file=None, _reached=None,
                         behaviour=SimpleNamespace(done=False), logged=logged,
                         get_logger=lambda: SimpleNamespace(info=logged.append, warning=logged.append))
    return node


def reply(stamp: float) -> Future:
    future = Future()
    event = {"agent": "robot", "stamp": stamp, "pose": [0.0, 0.0, 0.0], "room": "Bedroom_1", "odom": [0, 0, 0]}
    future.set_result(SimpleNamespace(success=True, message=json.dumps(event)))
    return future


def recorded(stamp: float) -> String:
    return String(data=json.dumps({"stamp": stamp, "index": 0}))


@pytest.mark.parametrize("confirmation_first", [False, True])
def test_a_capture_counts_once_recorded_whichever_message_comes_first(confirmation_first):
    """The recorder can store a capture and confirm it before the behaviour handles the capture's reply
    (both wait in the same spin); that confirmation used to be dropped and the robot held for ever."""
    node = waiting_node()
    future = reply(1.5)
    node._pending.add(future)
    if confirmation_first:
        node._on_recorded(recorded(1.5))
        node._on_capture(future, "moving")
    else:
        node._on_capture(future, "moving")
        assert node._holding() and node.capture_count == 0          # held until the recorder confirms
        node._on_recorded(recorded(1.5))
    assert node.capture_count == 1 and not node._holding()
    assert node._unrecorded == {} and node._recorded_early == set()
