"""Every topic the sim node publishes, made once, and the stamp they all carry.

All names come from ``ravh_msgs_py.names`` (an agent after the first gets its name as a prefix). Sensor
topics come from the sensor suite (ravh_sim.sensors.suite): each port's topics. A stamp is the sim time,
announced on /clock first if it is not yet: a stamp ahead of the clock subscribers have cannot be
transformed on arrival (tf2 would extrapolate).
"""
from __future__ import annotations

import math
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped, TransformStamped
from nav_msgs.msg import OccupancyGrid, Odometry
from rclpy.node import Node
from rclpy.qos import qos_profile_system_default
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_sim.nodes import convert
from ravh_sim.nodes.common import LATCHED_QOS, SENSOR_QOS, STATE_QOS
from ravh_sim.runtime import Agent, SimRuntime
from ravh_sim.sensors.ports import SensorPort, Topic
from ravh_sim.sensors.suite import SENSORS


class SimTopics:
    """The node's publishers: the shared ones as attributes, each agent's in :attr:`agents` by key."""

    def __init__(self, node: Node, runtime: SimRuntime) -> None:
        pub = node.create_publisher
        self.runtime = runtime
        self.clock = pub(Clock, n.CLOCK, STATE_QOS)
        self.map = pub(OccupancyGrid, n.MAP, LATCHED_QOS)
        self.free_space = pub(OccupancyGrid, n.FREE_SPACE_MAP, LATCHED_QOS)
        self.footprint = pub(String, n.GROUND_TRUTH, LATCHED_QOS)
        self.labels = pub(String, n.INSTANCE_LABELS, LATCHED_QOS)
        self.tf = pub(TFMessage, n.TF, STATE_QOS)
        self.tf_static = pub(TFMessage, n.TF_STATIC, LATCHED_QOS)
        self.diagnostics = pub(DiagnosticArray, n.DIAGNOSTICS, qos_profile_system_default)
        self.agents: dict[str, dict[str, Any]] = {}
        for agent in runtime.agents:
            def name(base: str, a: Agent = agent) -> str:
                return n.agent_name(base, a.name, a.first)
            self.agents[agent.name] = {
                **{topic.key: pub(convert.KINDS[topic.kind].msg_type, name(topic.base), SENSOR_QOS)
                   for port in SENSORS for topic in port.topics},
                "odom": pub(Odometry, name(n.ODOM), STATE_QOS),
                "gt_pose": pub(PoseStamped, name(n.GROUND_TRUTH_POSE), STATE_QOS),
                "odom_tf": pub(TransformStamped, name(n.ODOM_TRANSFORM), STATE_QOS),
                "map_odom": pub(TransformStamped, name(n.MAP_TO_ODOM), STATE_QOS),
                "room": pub(String, name(n.ROOM), LATCHED_QOS),
                "capture": pub(String, name(n.CAPTURE_EVENT), STATE_QOS),
                "static": {child: pub(TransformStamped, name(n.TF_STATIC_TOPIC.format(child=child)), LATCHED_QOS)
                           for _, child, _, _ in runtime.static_transforms(agent)},
                "last_room": None,
            }
        self._clock_sent = -math.inf

    def now(self) -> float:
        """The sim time to stamp with, announced on /clock first if it is not yet."""
        t = self.runtime.time
        if t > self._clock_sent:
            self.clock.publish(convert.clock(t))
            self._clock_sent = t
        return t

    @staticmethod
    def frame(agent: Agent, frame: str) -> str:
        """``agent``'s name of ``frame``."""
        return n.agent_name(frame, agent.name, agent.first)

    def subscribed(self, agent: Agent, port: SensorPort) -> tuple[Topic, ...]:
        """The topics of ``agent``'s ``port`` that somebody subscribes to."""
        pubs = self.agents[agent.name]
        return tuple(t for t in port.topics if pubs[t.key].get_subscription_count() > 0)

    def publish_sensor(self, agent: Agent, port: SensorPort, data: Any, stamp: float,
                       topics: tuple[Topic, ...]) -> None:
        """One reading ``data`` of ``agent``'s sensor of ``port`` on ``topics``, all with one stamp."""
        pubs, frame = self.agents[agent.name], self.frame(agent, port.frame)
        hdr = convert.header(stamp, frame)
        for topic in topics:
            value = port.value(topic.key, data, agent.sensors[port.name], frame)
            pubs[topic.key].publish(convert.KINDS[topic.kind].to_message(value, hdr))
