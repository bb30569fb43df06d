"""The capture hand-over on the wire: what ``ravh/capture`` and ``ravh/capture_recorded`` carry.

The sim announces each requested capture with a :class:`CaptureEvent` (std_msgs/String JSON, also
the capture service's reply); recorders match the capture's messages by its stamp and confirm each
stored one with a :class:`CaptureRecorded`. Defined here once for the sim, the recorder and the
behaviours, and checked on the way in, so a malformed message is one clear error, not a KeyError
deep in a callback. Plain Python: clients can import it without the simulator.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

Pose = tuple[float, float, float]


class CaptureFormatError(ValueError):
    """A capture message that does not have the documented fields."""


def _object(text: str | bytes, what: str) -> dict[str, Any]:
    try:
        data = json.loads(text)
    except (ValueError, TypeError, RecursionError) as e:
        raise CaptureFormatError(f"{what}: not JSON: {e}") from None
    if not isinstance(data, dict):
        raise CaptureFormatError(f"{what}: expected a JSON object, got {type(data).__name__}")
    return data


def _number(data: dict[str, Any], key: str, what: str) -> float:
    value = data.get(key)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise CaptureFormatError(f"{what}: {key!r} must be a finite number, got {value!r}")
    return float(value)


def _pose(data: dict[str, Any], key: str, what: str) -> Pose:
    value = data.get(key)
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise CaptureFormatError(f"{what}: {key!r} must be [x, y, yaw], got {value!r}")
    x, y, yaw = (_number({key: v}, key, what) for v in value)
    return (x, y, yaw)


def _optional_text(data: dict[str, Any], key: str, what: str) -> str | None:
    value = data.get(key)
    if value is not None and not isinstance(value, str):
        raise CaptureFormatError(f"{what}: {key!r} must be a string or null, got {value!r}")
    return value


@dataclass(frozen=True)
class CaptureEvent:
    """One synchronised capture: every message of it carries ``stamp`` (sim seconds) in its header."""
    agent: str
    stamp: float
    pose: Pose                   # true pose in map (x, y, yaw)
    room: str | None             # the room the robot stood in (None: outside every room)
    odom: Pose                   # odometry's pose in odom
    reason: str | None = None    # why the behaviour asked for it (its own log only; not on the wire)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"agent": self.agent, "stamp": self.stamp, "pose": list(self.pose),
                               "room": self.room, "odom": list(self.odom)}
        if self.reason is not None:
            out["reason"] = self.reason
        return out

    def to_json(self) -> str:
        return json.dumps(self.to_dict())

    @classmethod
    def from_json(cls, text: str | bytes) -> CaptureEvent:
        what = "capture event"
        data = _object(text, what)
        agent = data.get("agent")
        if not isinstance(agent, str) or not agent:
            raise CaptureFormatError(f"{what}: 'agent' must be a non-empty string, got {agent!r}")
        return cls(agent, _number(data, "stamp", what), _pose(data, "pose", what),
                   _optional_text(data, "room", what), _pose(data, "odom", what),
                   _optional_text(data, "reason", what))


@dataclass(frozen=True)
class CaptureRecorded:
    """A recorder's confirmation that the capture at ``stamp`` is stored as dataset sample ``index``."""
    stamp: float
    index: int

    def to_json(self) -> str:
        return json.dumps({"stamp": self.stamp, "index": self.index})

    @classmethod
    def from_json(cls, text: str | bytes) -> CaptureRecorded:
        what = "capture confirmation"
        data = _object(text, what)
        index = data.get("index")
        if isinstance(index, bool) or not isinstance(index, int) or index < 0:
            raise CaptureFormatError(f"{what}: 'index' must be a non-negative integer, got {index!r}")
        return cls(_number(data, "stamp", what), index)
