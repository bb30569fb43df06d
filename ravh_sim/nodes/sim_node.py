"""The sim node: a :class:`~ravh_sim.runtime.SimRuntime` on ROS 2 topics and services.

``ros2 run ravh_sim sim --house 15`` (or ``ravh sim --house 15``). The node is the clock: it advances
physics so that sim time follows wall time times the real-time factor (0 = as fast as possible;
``--lockstep``: as far as a behaviour grants, ravh_sim.nodes.pacing), publishes /clock, and stamps
everything with sim time, never ahead of the /clock it has published. All names come from
``ravh_msgs_py.names``. Parameters are read-only (they shape the world at start-up; ravh_sim.nodes.sim_params).

The node wires parts with one job each: the topics and their stamp (sim_topics), sensor readings streamed
to subscribers and camera frames on the render thread (frame_stream, render_thread), captures with a stamp
of their own (captures), the latched facts (latched_topics), each robot's state and who owns map -> odom
on /tf (robot_state, map_odom), the budget of appearance changes under a burst (appearance_budget), the
stop of a robot whose commands stop (command_watchdog), JSON services that answer every request waiting
(json_service) and its health on /diagnostics (health).
Requests never take it down: bad commands are refused with a throttled warning, bad service requests get
an error reply, and a frame that fails is one dropped frame; a capture whose frame fails replies
``success: false`` with the reason.
"""
from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from functools import partial
from typing import Any

from diagnostic_msgs.srv import AddDiagnostics
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.srv import GetMap, GetPlan
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_srvs.srv import Trigger
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_sim.errors import UserError
from ravh_sim.nav.grid import Grid
from ravh_sim.nodes import convert
from ravh_sim.nodes.appearance_budget import AppearanceBudget
from ravh_sim.nodes.captures import Captures
from ravh_sim.nodes.command_watchdog import CommandWatchdog
from ravh_sim.nodes.common import COMMAND_QOS, HANDOVER_QOS, run_node
from ravh_sim.nodes.frame_stream import FramePolicy, FrameStream
from ravh_sim.nodes.health import SimHealth
from ravh_sim.nodes.json_service import json_service
from ravh_sim.nodes.latched_topics import LatchedTopics
from ravh_sim.nodes.map_odom import MapOdomOwnership
from ravh_sim.nodes.pacing import MAX_STEP_S, Pacing
from ravh_sim.nodes.render_thread import RenderThread
from ravh_sim.nodes.robot_state import RobotState
from ravh_sim.nodes.sim_params import SimParams, parse_args
from ravh_sim.nodes.sim_topics import SimTopics
from ravh_sim.runtime import ODOM, Agent, Schedule, SimRuntime
from ravh_sim.sensors.suite import SENSORS

TICK_S = 0.005                          # wall period of the stepping timer
WARN_THROTTLE_S = 2.0
DIAGNOSTICS_PERIOD_S = 1.0              # wall seconds between /diagnostics messages (the ROS habit: 1 Hz)
# Listening for other map -> odom publishers: best effort matches reliable and best-effort publishers.
TF_LISTEN_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT)


class SimNode(Node):
    """Builds the runtime and the parts around it, steps physics on a timer and answers the services."""

    def __init__(self, overrides: dict[str, Any] | None = None) -> None:
        params = [Parameter(k, value=v) for k, v in (overrides or {}).items()]
        super().__init__("ravh_sim", parameter_overrides=params)
        p = self.params = SimParams.declare(self)
        self.render_thread = RenderThread()
        rt = self.runtime = self.render_thread.call(SimRuntime, p.house, p.config, p.seed, renderer=p.renderer,
                                                    rates=p.rates, footprint=p.footprint)
        self.get_logger().info(
            f"house {rt.house.number}: {len(rt.house.rooms)} rooms, {len(rt.house.objects)} objects, "
            f"renderer {rt.backend}, seed {rt.world.state.seed}, real-time factor {p.rtf:g}")
        self.topics = SimTopics(self, rt)
        self.health = SimHealth(p.rtf, self.get_logger().warning)
        self.budget = AppearanceBudget()
        self.frames = FrameStream(self.topics, self.render_thread, FramePolicy(p.frame_policy), self.health,
                                  self.budget, p.rtf, self.get_logger().warning)
        self.pacing = Pacing(p.rtf, p.lockstep, rt.world.physics_hz, rt.steps, rt.time)
        self.captures = Captures(self.topics, self.frames, self.pacing.grant)
        self.map_odom = MapOdomOwnership(p.map_tf, rt.agents, self.get_logger().info)
        self.robot_state = RobotState(self.topics, self.map_odom)
        self.latched = LatchedTopics(self.topics)
        self.watchdog = CommandWatchdog()
        self._last_warn = 0.0
        self._clock_due = Schedule.every(p.clock_rate, rt.world.physics_hz)
        self._make_subscriptions()
        self._make_services()
        self.latched.publish_all()
        self.create_timer(TICK_S, self._tick)
        self.create_timer(DIAGNOSTICS_PERIOD_S, lambda: self.topics.diagnostics.publish(
            self.health.array(self.runtime.time, self.captures.in_flight)))

    def _make_subscriptions(self) -> None:
        for agent in self.runtime.agents:
            topic = n.agent_name(n.CMD_VEL, agent.name, agent.first)
            if self.params.cmd_vel_stamped:
                self.create_subscription(TwistStamped, topic,
                                         lambda m, a=agent: self._on_cmd(a, m.twist), COMMAND_QOS)
            else:
                self.create_subscription(Twist, topic, lambda m, a=agent: self._on_cmd(a, m), COMMAND_QOS)
            if self.params.lockstep:
                self.create_subscription(TwistStamped, n.agent_name(n.STEP, agent.name, agent.first),
                                         lambda m, a=agent: self._on_step(a, m), HANDOVER_QOS)
        if self.map_odom.listens:
            self.create_subscription(TFMessage, n.TF, self.map_odom.heard, TF_LISTEN_QOS)

    def _make_services(self) -> None:
        srv = self.create_service
        json_service(self, n.QUERY_SERVICE, self._on_query, self.budget.new_batch)
        json_service(self, n.APPEARANCE_SERVICE, self._on_appearance, self.budget.new_batch)
        srv(GetMap, n.GET_MAP_SERVICE, lambda req, res: self._on_get_map(res, self.runtime.navigation.obstacle_map))
        srv(GetMap, n.GET_FREE_SPACE_SERVICE, lambda req, res: self._on_get_map(res, self.runtime.navigation.map))
        srv(GetPlan, n.GET_PLAN_SERVICE, self._on_get_plan)
        srv(Trigger, n.RESET_SERVICE, self._on_reset)
        # Captures in a group of their own: the executor runs the tick while a capture waits for its frame.
        captures = MutuallyExclusiveCallbackGroup()
        for agent in self.runtime.agents:
            srv(Trigger, n.agent_name(n.CAPTURE_SERVICE, agent.name, agent.first),
                partial(self._on_capture, agent), callback_group=captures)

    # ------------------------------------------------------------------ stepping
    def _tick(self) -> None:
        """Advance sim time towards wall time x RTF, publishing whatever falls due on the way."""
        rt = self.runtime
        if self.params.rtf == 0 and self.captures.rendering:
            return           # as fast as possible, yet not past a capture: readers would miss its parts
        last = self.pacing.last_step(rt.steps, rt.step_at)
        deadline, first = time.monotonic() + MAX_STEP_S, rt.steps
        while rt.steps < last and time.monotonic() < deadline:
            self.watchdog.check(rt.agents, rt.time)
            rt.step()
            self._publish_due()
        self.health.sim_time(rt.time)
        if rt.steps > first:
            self.captures.stepped()
        if self.pacing.beat_due(rt.steps):
            self.robot_state.arrived()
        self.pacing.settle(rt.time)

    def _publish_due(self) -> None:
        rt = self.runtime
        if self._clock_due.due(rt.steps):
            self.topics.now()
        if self.latched.map_stale:
            start = time.monotonic()
            self.latched.publish_map()           # a door or a model changed: the change's cost
            self.budget.spend(time.monotonic() - start)
        for agent in rt.agents:
            if rt.due(agent, ODOM):
                self.robot_state.publish(agent)
            for port in SENSORS:
                if rt.due(agent, port.name):
                    self.frames.stream(agent, port)

    # ------------------------------------------------------------------ callbacks
    def _warn(self, text: str) -> None:
        now = time.monotonic()
        if now - self._last_warn >= WARN_THROTTLE_S:
            self._last_warn = now
            self.get_logger().warning(text)

    def _on_cmd(self, agent: Agent, twist: Twist) -> None:
        try:
            self.runtime.command(agent, twist.linear.x, twist.angular.z)
            self.watchdog.commanded(agent, self.runtime.time)
        except UserError as e:
            self._warn(str(e))

    def _on_step(self, agent: Agent, msg: TwistStamped) -> None:
        """Lockstep: the behaviour's command for the next step and the sim time it may run to."""
        self._on_cmd(agent, msg.twist)
        self.pacing.behaviour_grants(self.runtime.step_at(convert.seconds(msg.header.stamp)))

    def _on_query(self, request: AddDiagnostics.Request, response: AddDiagnostics.Response):
        reply = self.runtime.query(request.load_namespace)
        response.success, response.message = bool(reply["ok"]), json.dumps(reply)
        return response

    def _on_appearance(self, request: AddDiagnostics.Request, response: AddDiagnostics.Response):
        start = time.monotonic()
        # read and checked here (cheap, no state), so a bad or a refused request never waits for a frame
        reply = self.runtime.appearance_refusal(request.load_namespace, self.budget.busy)
        if reply is None:
            # on the render thread: a renderer reads the world's appearance while it renders
            reply = self.render_thread.call(self.runtime.change_appearance, request.load_namespace)
        if reply["ok"]:
            self.latched.publish_footprint()     # /map follows on the next step if doors changed
            self.budget.changed([(agent.name, port.name) for agent in self.runtime.agents for port in SENSORS],
                                time.monotonic() - start)
        response.success, response.message = bool(reply["ok"]), json.dumps(reply)
        return response

    def _on_get_map(self, response: GetMap.Response, grid: Callable[[], Grid]):
        t = self.topics.now()
        response.map = convert.occupancy_grid(grid(), convert.header(t, n.MAP_FRAME), t)
        return response

    def _on_get_plan(self, request: GetPlan.Request, response: GetPlan.Response):
        rt = self.runtime
        start, goal = (request.start.pose.position, request.goal.pose.position)
        frames = (request.start.header.frame_id, request.goal.header.frame_id)
        response.plan.header = convert.header(self.topics.now(), n.MAP_FRAME)
        try:       # start and goal in map, odom or an agent's frame; the plan in map; an unknown frame: no plan
            path = rt.plan((start.x, start.y, start.z), (goal.x, goal.y, goal.z), frames)
        except UserError as e:
            self._warn(f"GetPlan: {e}")
            return response
        except Exception as e:  # never die from a request
            self._warn(f"GetPlan: {type(e).__name__}: {e}")
            return response
        pts = path.points
        for i, (x, y) in enumerate(pts):
            nx, ny = pts[min(i + 1, len(pts) - 1)]
            yaw = math.atan2(ny - y, nx - x) if (nx, ny) != (x, y) else 0.0
            response.plan.poses.append(convert.pose_stamped((x, y, yaw), response.plan.header))
        return response

    def _on_reset(self, request: Trigger.Request, response: Trigger.Response):
        try:
            self.render_thread.call(self.runtime.reset)
            self.latched.publish_footprint()
            response.success, response.message = True, "agents back at their start poses"
        except Exception as e:  # never die from a request
            response.success, response.message = False, f"{type(e).__name__}: {e}"
        return response

    async def _on_capture(self, agent: Agent, request: Trigger.Request, response: Trigger.Response):
        try:
            event = await self.captures.capture(agent)
            response.success, response.message = True, event.to_json()
        except Exception as e:  # never die from a request
            response.success, response.message = False, f"{type(e).__name__}: {e}"
        return response

    def in_flight(self) -> bool:
        """Whether a requested capture is still waiting for its stamp or its frame (spin_until_stopped
        finishes it)."""
        return self.captures.in_flight > 0

    def close(self) -> None:
        self.render_thread.call(self.runtime.close)
        self.render_thread.shutdown()


def main(argv: list[str] | None = None) -> int:
    return run_node(lambda args: SimNode(parse_args(args)), argv)


if __name__ == "__main__":
    raise SystemExit(main())
