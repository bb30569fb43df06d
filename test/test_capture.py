"""The capture hand-over messages: the wire format the sim, recorders and behaviours share."""
from __future__ import annotations

import json

import pytest

from ravh_msgs_py.capture import CaptureEvent, CaptureFormatError, CaptureRecorded

WIRE = '{"agent": "robot", "stamp": 353.6, "pose": [1.0, -2.5, 0.3], "room": "Bedroom_1", "odom": [1.1, -2.4, 0.29]}'


def test_the_event_keeps_the_wire_format():
    event = CaptureEvent.from_json(WIRE)
    assert event == CaptureEvent("robot", 353.6, (1.0, -2.5, 0.3), "Bedroom_1", (1.1, -2.4, 0.29))
    assert event.to_json() == WIRE                              # the same keys, in the same order
    outside = CaptureEvent("robot2", 1.0, (0.0, 0.0, 0.0), None, (0.0, 0.0, 0.0))
    assert CaptureEvent.from_json(outside.to_json()) == outside and json.loads(outside.to_json())["room"] is None


def test_a_reason_is_kept_only_when_set():
    event = CaptureEvent.from_json(WIRE)
    assert "reason" not in json.loads(event.to_json())
    logged = CaptureEvent("robot", 2.0, (0.0, 0.0, 0.0), None, (0.0, 0.0, 0.0), reason="waypoint")
    assert json.loads(logged.to_json())["reason"] == "waypoint" and CaptureEvent.from_json(logged.to_json()) == logged


@pytest.mark.parametrize("text, problem", [
    ("{nope", "not JSON"),
    ("[1, 2]", "JSON object"),
    ('{"stamp": 1.0, "pose": [0, 0, 0], "room": null, "odom": [0, 0, 0]}', "'agent'"),
    ('{"agent": "a", "stamp": "soon", "pose": [0, 0, 0], "room": null, "odom": [0, 0, 0]}', "'stamp'"),
    ('{"agent": "a", "stamp": NaN, "pose": [0, 0, 0], "room": null, "odom": [0, 0, 0]}', "'stamp'"),
    ('{"agent": "a", "stamp": 1.0, "pose": [0, 0], "room": null, "odom": [0, 0, 0]}', "'pose'"),
    ('{"agent": "a", "stamp": 1.0, "pose": [0, 0, true], "room": null, "odom": [0, 0, 0]}', "'pose'"),
    ('{"agent": "a", "stamp": 1.0, "pose": [0, 0, 0], "room": 7, "odom": [0, 0, 0]}', "'room'"),
    ('{"agent": "a", "stamp": 1.0, "pose": [0, 0, 0], "room": null}', "'odom'"),
])
def test_bad_events_are_one_clear_error(text, problem):
    with pytest.raises(CaptureFormatError, match=problem):
        CaptureEvent.from_json(text)


def test_the_confirmation_round_trips_and_is_checked():
    done = CaptureRecorded(353.6, 4)
    assert done.to_json() == '{"stamp": 353.6, "index": 4}'
    assert CaptureRecorded.from_json(done.to_json()) == done
    for bad in ('{"stamp": 1.0}', '{"stamp": 1.0, "index": -1}', '{"stamp": 1.0, "index": 1.5}', '{"index": 1}'):
        with pytest.raises(CaptureFormatError):
            CaptureRecorded.from_json(bad)
