"""The recorder node: requested captures into a dataset folder, and the raid into a rosbag2 (MCAP).

``ros2 run ravh_sim recorder --out DIR [--no-bag] [--agent NAME] [--raid JSON]`` (or ``ravh recorder
...``). Every topic is subscribed raw (serialized CDR): the bag stores the bytes exactly as received,
and only the messages that end up in the dataset are deserialized, in a worker thread that encodes
and writes the files while the executor keeps receiving.

A capture is the set of messages that share the stamp of a ``ravh/capture`` event: every sensor port's
topics (ravh_sim.sensors.suite: RGB, depth, instances, camera_infos, the scan), decoded with
ravh_sim.nodes.convert and stored by the ports through the DatasetWriter. Events and images arrive on
different topics in any order, so parts wait by stamp in :class:`StampMatcher` until the set is
complete; periodic camera frames never get an event and are dropped unrecorded. The bag keeps the
continuous streams (scan, odom, ground-truth pose, capture events, /tf) whole, the latched ones (/map,
/tf_static, /ravh/ground_truth, instance labels) with transient-local QoS so ``ros2 bag play``
re-latches them, and of the camera only the captures (JPEG colour, depth, instances, camera_infos), so
bag and dataset describe the same frames. Bag times are sim receive times (``use_sim_time``); messages
that arrive before the first /clock are written at the first clock time. SIGINT closes the bag
(metadata.yaml written); a SIGKILLed recorder leaves a dataset that reads back complete up to its last
capture, and an MCAP without its summary (``mcap recover`` rebuilds it).

Nothing is lost silently: each stored capture is confirmed on ``ravh/capture_recorded`` (reliable,
keep-all), which a behaviour run with ``--wait-recorder`` waits for before it moves on; a capture that
cannot be completed or written, or a sim that goes away (no /clock), ends the recorder with an error
and a non-zero exit status after it has closed what it has.
"""
from __future__ import annotations

import argparse
import json
import struct
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import rclpy.clock
import rclpy.logging
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import OccupancyGrid, Odometry
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.publisher import Publisher
from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message
from rclpy.subscription import Subscription
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_msgs_py.capture import CaptureEvent, CaptureFormatError, CaptureRecorded
from ravh_sim.dataset import layout
from ravh_sim.dataset.writer import DatasetWriter
from ravh_sim.errors import UserError
from ravh_sim.nodes import convert
from ravh_sim.nodes.common import LATCHED_QOS, RECORDED_QOS, SENSOR_QOS, STATE_QOS, SimWatchdog, run_node
from ravh_sim.sensors.suite import SENSORS

NS = 1_000_000_000
PENDING_TIMEOUT_S = 30.0      # wall seconds a stamp's parts wait for the rest of their capture
MATCHED_LOG = "every capture topic matched the sim's publishers"
MAX_PENDING = 32              # stamps buffered at most (periodic frames without an event go first)

class Part(NamedTuple):
    """A per-agent topic the recorder subscribes to."""
    base: str                 # name in ravh_msgs_py.names (prefixed for agents after the first)
    msg_type: type
    qos: QoSProfile
    dataset: bool             # needed for the dataset (part of a capture's set)
    bag: bool                 # recorded in the bag
    per_capture: bool         # camera: waits by stamp, bagged only for captures (else streamed)
    kind: str | None = None   # a sensor topic's message kind (convert.KINDS), to decode it for the dataset


# Every sensor port's topics (ravh_sim.sensors.suite), then the agent's state and its capture events.
PARTS: dict[str, Part] = {
    **{topic.key: Part(topic.base, convert.KINDS[topic.kind].msg_type, SENSOR_QOS, topic.dataset, topic.bag,
                       port.captured, topic.kind) for port in SENSORS for topic in port.topics},
    "odom": Part(n.ODOM, Odometry, STATE_QOS, False, True, False),
    "gt_pose": Part(n.GROUND_TRUTH_POSE, PoseStamped, STATE_QOS, False, True, False),
    "event": Part(n.CAPTURE_EVENT, String, STATE_QOS, True, True, False),
}
# Latched, not per agent: name -> (message type, in the dataset).
LATCHED: dict[str, tuple[type, bool]] = {
    n.GROUND_TRUTH: (String, True),
    n.MAP: (OccupancyGrid, True),
    n.INSTANCE_LABELS: (String, False),
    n.TF_STATIC: (TFMessage, False),
}
# Continuous, not per agent: name -> message type, for the bag only.
STREAMS: dict[str, type] = {n.TF: TFMessage}


def type_name(msg_type: type) -> str:
    """'sensor_msgs/msg/Image' for sensor_msgs.msg.Image."""
    return f"{msg_type.__module__.split('.')[0]}/msg/{msg_type.__name__}"


def header_stamp_ns(cdr: bytes) -> int:
    """The header stamp of a serialized stamped message, read without deserializing it.

    CDR: 4 bytes of encapsulation (byte 1: 0 big-, 1 little-endian), then the first field, the
    std_msgs/Header, whose stamp is int32 sec, uint32 nanosec.
    """
    sec, nanosec = struct.unpack_from("<iI" if cdr[1] & 1 else ">iI", cdr, 4)
    return sec * NS + nanosec


def event_stamp_ns(seconds: float) -> int:
    """The header stamp the sim gave the messages of a capture whose event says ``seconds``."""
    t = convert.stamp(seconds)
    return t.sec * NS + t.nanosec


# ---------------------------------------------------------------------------- matching

@dataclass
class _Pending:
    created: float                                    # wall time of the first part
    parts: dict[str, Any] = field(default_factory=dict)


class StampMatcher:
    """Gathers a capture's parts by stamp; hands the set over once every required part is in.

    The sim gives every capture of an agent a stamp of its own (ravh_sim.nodes.sim_node), so a stamp
    names one capture. A second event at a stamp that already has one (pending or stored) would merge
    two captures: it is refused and reported in :attr:`duplicates`, never matched."""

    def __init__(self, required: set[str], max_pending: int = MAX_PENDING,
                 timeout_s: float = PENDING_TIMEOUT_S) -> None:
        self.required = frozenset(required)
        self.max_pending, self.timeout_s = max_pending, timeout_s
        self.pending: dict[int, _Pending] = {}
        self.lost: list[int] = []                     # stamps of captures (with an event) given up on
        self.duplicates: list[int] = []               # stamps of events refused: a capture had that stamp
        self._matched: deque[int] = deque(maxlen=4 * max_pending)     # stamps of recent complete sets

    def add(self, stamp_ns: int, part: str, value: Any, now: float) -> dict[str, Any] | None:
        """Add one part (the first of a stamp wins); returns the complete set, else None."""
        taken = stamp_ns in self._matched or (stamp_ns in self.pending and "event" in self.pending[stamp_ns].parts)
        if part == "event" and taken:
            self.duplicates.append(stamp_ns)
            return None
        entry = self.pending.setdefault(stamp_ns, _Pending(now))
        entry.parts.setdefault(part, value)
        if self.required <= entry.parts.keys():
            del self.pending[stamp_ns]
            self._matched.append(stamp_ns)
            return entry.parts
        self._prune(now)
        return None

    def _prune(self, now: float) -> None:
        for stamp, entry in list(self.pending.items()):
            if now - entry.created > self.timeout_s:
                self._drop(stamp)
        idle = sorted(s for s, e in self.pending.items() if "event" not in e.parts)
        for stamp in idle[:max(0, len(self.pending) - self.max_pending)]:
            self._drop(stamp)

    def _drop(self, stamp: int) -> None:
        if "event" in self.pending.pop(stamp).parts:
            self.lost.append(stamp)

    def waiting(self) -> int:
        """Announced captures (their event is in) still waiting for parts."""
        return sum("event" in e.parts for e in self.pending.values())


# ---------------------------------------------------------------------------- the bag

class BagWriter:
    """A rosbag2 folder with MCAP storage, written from serialized messages with ``rosbags``."""

    def __init__(self, path: Path) -> None:
        self._typestore = get_typestore(Stores.ROS2_JAZZY)
        self._writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
        self._writer.open()
        self._connections: dict[str, Any] = {}
        self._early: list[tuple[str, bytes]] = []     # before the first /clock

    def add_topic(self, topic: str, msg_type: type, latched: bool) -> None:
        zero = QosTime(0, 0)
        qos = Qos(QosHistory.KEEP_LAST, 1 if latched else 10, QosReliability.RELIABLE,
                  QosDurability.TRANSIENT_LOCAL if latched else QosDurability.VOLATILE, zero, zero,
                  QosLiveliness.AUTOMATIC, zero, False)
        self._connections[topic] = self._writer.add_connection(
            topic, type_name(msg_type), typestore=self._typestore, offered_qos_profiles=[qos])

    def write(self, topic: str, t_ns: int, data: bytes) -> None:
        if t_ns <= 0:
            self._early.append((topic, data))
            return
        self._flush_early(t_ns)
        self._writer.write(self._connections[topic], t_ns, data)

    def close(self) -> None:
        self._flush_early(1)                          # never saw a clock: keep them anyway
        self._writer.close()

    def _flush_early(self, t_ns: int) -> None:
        for topic, data in self._early:
            self._writer.write(self._connections[topic], t_ns, data)
        self._early.clear()


# ---------------------------------------------------------------------------- the node

class RecorderNode(Node):
    def __init__(self, out: Path, bag: bool, agent: str | None, raid: dict[str, Any]) -> None:
        super().__init__("ravh_recorder", parameter_overrides=[Parameter("use_sim_time", value=True)])
        self.out, self.raid, self.wanted_agent = out, raid, agent
        if bag and (out / layout.BAG_DIR).exists():
            raise UserError(f"{out / layout.BAG_DIR} exists; record into a new folder")
        self.writer = DatasetWriter(out)
        self.bag = BagWriter(out / layout.BAG_DIR) if bag else None
        self.worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ravh_recorder_write")
        self.parts = {k: p for k, p in PARTS.items() if p.dataset or (bag and p.bag)}
        self.matcher = StampMatcher({k for k, p in self.parts.items() if p.per_capture or p.dataset})
        self.agent: str | None = None
        self.captures = 0
        self.lost = 0                                 # captures announced but never stored
        self.failure: str | None = None               # the first write error (the worker thread's)
        self.exit_code = 0
        self.recorded_pub: Publisher | None = None        # made once the agent is known
        self.part_subs: list[Subscription] = []           # the capture topics, once the agent is known
        self.matched = False                              # every one of them matched a publisher
        self.log = self.get_logger()
        self.topics: dict[str, str] = {}              # part -> resolved topic name
        for topic, (msg_type, in_dataset) in LATCHED.items():
            if in_dataset or bag:
                sub = self.create_subscription(msg_type, topic, lambda d, t=topic: self._on_latched(t, d),
                                               LATCHED_QOS, raw=True)
                if self.bag:
                    self.bag.add_topic(sub.topic_name, msg_type, latched=True)
                self.topics[topic] = sub.topic_name
        if self.bag is not None:
            for topic, msg_type in STREAMS.items():
                sub = self.create_subscription(msg_type, topic, lambda d, t=topic: self._on_stream(t, d), STATE_QOS,
                                               raw=True)
                self.bag.add_topic(sub.topic_name, msg_type, latched=False)
                self.topics[topic] = sub.topic_name
        SimWatchdog(self)
        self.create_timer(0.5, self._check_writes,
                          clock=rclpy.clock.Clock(clock_type=rclpy.clock.ClockType.STEADY_TIME))
        self.log.info(f"waiting for {n.GROUND_TRUTH} to learn the house and its agents")

    # ------------------------------------------------------------------ set-up once the world is known
    def _start(self, footprint: dict[str, Any]) -> None:
        agents = n.footprint_agents(footprint)
        if not agents:
            raise UserError("the footprint names no agents; nothing to record")
        agent = self.wanted_agent or agents[0]
        if agent not in agents:
            raise UserError(f"unknown agent {agent!r}; the sim has {', '.join(agents)}")
        self.agent = agent
        self.recorded_pub = self.create_publisher(String, n.agent_name(n.CAPTURE_RECORDED, agent, agent == agents[0]),
                                                  RECORDED_QOS)
        self._submit(self.writer.write_meta, footprint["house"], [agent], self.raid, self.bag is not None)
        for key, part in self.parts.items():
            name = n.agent_name(part.base, agent, agent == agents[0])
            sub = self.create_subscription(part.msg_type, name, lambda d, k=key: self._on_part(k, d), part.qos,
                                           raw=True)
            self.topics[key] = sub.topic_name
            self.part_subs.append(sub)
            if self.bag and part.bag:
                self.bag.add_topic(sub.topic_name, part.msg_type, latched=False)
        self.log.info(f"recording agent {agent} of house {footprint['house']} into {self.out}"
                      f" ({'with' if self.bag else 'no'} bag)")

    # ------------------------------------------------------------------ callbacks
    def _now_ns(self) -> int:
        return self.get_clock().now().nanoseconds

    def _on_latched(self, topic: str, data: bytes) -> None:
        if self.bag:
            self.bag.write(self.topics[topic], self._now_ns(), data)
        if topic == n.GROUND_TRUTH:
            footprint = json.loads(deserialize_message(data, String).data)
            self._submit(self.writer.write_footprint, footprint)
            if self.agent is None:
                self._start(footprint)
        elif topic == n.MAP:
            self._submit(self.writer.write_map, convert.grid_of(deserialize_message(data, OccupancyGrid)))

    def _on_stream(self, topic: str, data: bytes) -> None:
        assert self.bag is not None, "streams are subscribed for the bag only"
        self.bag.write(self.topics[topic], self._now_ns(), data)

    def _on_part(self, key: str, data: bytes) -> None:
        now_ns, part = self._now_ns(), self.parts[key]
        value: CaptureEvent | tuple[int, bytes]
        if self.bag and part.bag and not part.per_capture:
            self.bag.write(self.topics[key], now_ns, data)
        if key == "event":
            try:
                event = CaptureEvent.from_json(deserialize_message(data, String).data)
            except CaptureFormatError as e:
                self.log.error(f"ignored a message on {self.topics[key]}: {e}")
                return
            if event.agent != self.agent:
                return
            stamp, value = event_stamp_ns(event.stamp), event
        elif key in self.matcher.required:
            stamp, value = header_stamp_ns(data), (now_ns, data)
        else:
            return
        parts = self.matcher.add(stamp, key, value, time.monotonic())
        while self.matcher.lost:
            self.lost += 1
            self.log.error(f"capture at t={self.matcher.lost.pop(0) / NS:.3f} s incomplete: lost")
        while self.matcher.duplicates:
            self.lost += 1
            self.log.error(f"a second capture at t={self.matcher.duplicates.pop(0) / NS:.3f} s: two captures "
                           "cannot share a stamp; the later one is lost")
        if parts is not None:
            self._complete(parts)

    def _complete(self, parts: dict[str, Any]) -> None:
        if self.bag:
            for key, value in parts.items():
                if self.parts[key].bag and self.parts[key].per_capture:
                    self.bag.write(self.topics[key], *value)
        self._submit(self._write_capture, parts)

    def _write_capture(self, parts: dict[str, Any]) -> None:
        """Worker thread: decode what the dataset keeps (every sensor's dataset topics) and write it."""
        values = {key: convert.KINDS[part.kind].from_message(deserialize_message(parts[key][1], part.msg_type))
                  for key, part in self.parts.items() if part.dataset and part.kind is not None}
        event: CaptureEvent = parts["event"]
        index = self.writer.write_capture(event, values)
        self.captures = index + 1
        self._confirm(event.stamp, index)
        self.log.info(f"capture {index} at t={event.stamp:.2f} s in {event.room}")

    def _confirm(self, stamp: float, index: int) -> None:
        """Tell the behaviour its capture is stored (close() runs before ROS shuts down, so this always can)."""
        assert self.recorded_pub is not None, "captures are matched only once the agent is known"
        self.recorded_pub.publish(String(data=CaptureRecorded(stamp, index).to_json()))

    def _submit(self, fn: Callable[..., object], *args: Any) -> None:
        self.worker.submit(fn, *args).add_done_callback(self._report)

    def _report(self, future: Future) -> None:
        error = future.exception()
        if error is not None and self.failure is None:
            self.failure = f"{error.strerror}: {error.filename}" if isinstance(error, OSError) else repr(error)

    def _check_writes(self) -> None:
        """A failed write ends the recording loudly (the worker thread cannot raise into the executor);
        says once when every capture topic has matched the sim's publisher (what a raid waits for)."""
        if self.part_subs and not self.matched and all(s.get_publisher_count() > 0 for s in self.part_subs):
            self.matched = True
            self.log.info(MATCHED_LOG)
        if self.failure is not None:
            raise UserError(f"dataset write failed ({self.failure}); stopped with {self.captures} captures "
                            f"in {self.out}")

    def in_flight(self) -> bool:
        """Whether an announced capture still waits for parts: a stopping recorder spins on until it is
        complete (spin_until_stopped, bounded), so Ctrl-C loses none it was told of."""
        return self.matcher.waiting() > 0

    def close(self) -> None:
        """Finish queued writes, then close the dataset and the bag (SIGINT lands here)."""
        waiting = self.matcher.waiting()
        self.worker.shutdown(wait=True)
        self.writer.close()
        if self.bag:
            self.bag.close()
        self.lost += waiting
        if self.lost or self.failure:
            self.exit_code = 1
            self.log.error(f"stopped: {self.captures} captures in {self.out}; {self.lost} announced captures "
                           f"lost" + (f"; a write failed: {self.failure}" if self.failure else ""))
        else:
            self.log.info(f"stopped: {self.captures} captures in {self.out}")


def parse_args(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="recorder", description="ravh_sim: record requested captures into a "
                                "dataset folder (see ravh_sim/dataset/README.md) and a rosbag2")
    p.add_argument("--out", type=Path, required=True, help="dataset folder (new, or empty)")
    p.add_argument("--bag", action=argparse.BooleanOptionalAction, default=True,
                   help="also record a rosbag2 (MCAP) in OUT/bag (default: yes)")
    p.add_argument("--agent", default=None, help="agent to record (default: the first)")
    p.add_argument("--raid", default="{}", help="JSON object stored as dataset.json's 'raid' (who, why, how)")
    return p.parse_args(argv)


def make_node(argv: list[str]) -> RecorderNode:
    args = parse_args(argv)
    try:
        raid = json.loads(args.raid)
    except ValueError as e:
        raise UserError(f"--raid: not JSON: {e}") from None
    if not isinstance(raid, dict):
        raise UserError("--raid: expected a JSON object")
    return RecorderNode(args.out, args.bag, args.agent, raid)


def main(argv: list[str] | None = None) -> int:
    return run_node(make_node, argv)


if __name__ == "__main__":
    raise SystemExit(main())
