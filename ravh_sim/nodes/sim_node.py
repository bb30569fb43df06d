"""The sim node: a :class:`~ravh_sim.runtime.SimRuntime` on ROS 2 topics and services.

``ros2 run ravh_sim sim --house 15`` (or ``ravh sim --house 15``). The node is the clock: it advances
physics so that sim time follows wall time times the real-time factor (0 = as fast as possible),
publishes /clock, and stamps everything with sim time, never ahead of the /clock it has published.
All names come from ``ravh_msgs_py.names``. Parameters are read-only (they shape the world at start-up).

``map_tf`` (auto|on|off) says who owns the map -> odom edge on /tf: ``on`` the sim (ground truth),
``off`` someone else, ``auto`` (default) the sim only while no other node (slam_toolbox, AMCL)
publishes that edge. The ground truth stays on ``map_to_odom`` and ``ground_truth/pose`` either way.
With ``--lockstep`` it advances only as far as a behaviour grants on ``ravh/step`` (which carries the
command for that step), so a run depends on sim time alone and repeats exactly with the same seed.
Sensor topics come from the sensor suite (ravh_sim.sensors.suite): each port's topics, published at
its rate (the robot profile's; ``camera_rate``, ``scan_rate``, ``odom_rate`` override them for every
agent when >= 0). A sensor topic nobody subscribes to costs nothing: a reading is taken only for the
topics that have subscribers (no render, no JPEG for nobody); requested captures always are.

Camera frames are rendered and converted on one render thread (it owns the GL context, the cameras'
renderers and every change to the world's appearance), so physics, /clock, odometry, /tf and scans
keep their rates while a frame renders (the renderer waits for llvmpipe with the GIL released); a frame
is stamped with the sim time of its pose.
``frame_policy`` says what happens when a frame falls due while the last one still renders: ``drop``
(default) skips it, keeping the real-time factor, as a real camera drops frames and as Nav2 and
slam_toolbox expect of a clock that follows the wall clock (logged once); ``wait`` keeps every frame
by holding sim time until the last frame is out (the camera's rate in sim time, a slower sim).
Requests never take it down: bad commands are refused with a throttled warning, bad service
requests get an error reply. Nor do frames: a frame the renderer refuses (non-finite radiance) or fails
is one dropped frame, logged once per cause and counted on ``/diagnostics`` (the node's health, see
ravh_sim.nodes.health); a capture whose frame fails replies ``success: false`` with the reason.

A capture is known by its stamp, and no two captures of an agent share one: a capture requested while
sim time still stands at the previous capture's stamp (a paused or lockstep sim, a loaded machine, two
requests back to back at ``--rtf 0``) waits for the next physics step (in lockstep the sim grants itself
that one step). So every message of a capture (image, depth, instances, camera_infos, scan, the event)
carries one stamp that names that capture alone, which is what rosbag2, message_filters' exact-time
synchroniser and our recorder match on; a ROS header has no sequence number to carry instead.
"""
from __future__ import annotations

import argparse
import json
import math
import threading
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from functools import partial
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from diagnostic_msgs.srv import AddDiagnostics
from geometry_msgs.msg import PoseStamped, TransformStamped, Twist, TwistStamped
from nav_msgs.msg import OccupancyGrid, Odometry
from nav_msgs.srv import GetMap, GetPlan
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_system_default
from rclpy.task import Future as RosFuture
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String
from std_srvs.srv import Trigger
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_msgs_py.capture import CaptureEvent
from ravh_msgs_py.query import MAX_REQUEST_CHARS
from ravh_sim.errors import UserError
from ravh_sim.nav.grid import Grid
from ravh_sim.nodes import convert
from ravh_sim.nodes.common import (
    COMMAND_QOS,
    HANDOVER_QOS,
    LATCHED_QOS,
    SENSOR_QOS,
    SERVICE_QOS,
    SERVICE_QUEUE,
    STATE_QOS,
    return_freed_memory,
    run_node,
)
from ravh_sim.nodes.health import SimHealth
from ravh_sim.render.backend import BACKENDS
from ravh_sim.runtime import ODOM, Agent, Schedule, SimRuntime
from ravh_sim.sensors.ports import SensorPort, Topic
from ravh_sim.sensors.suite import SENSORS

TICK_S = 0.005                          # wall period of the stepping timer
MAX_STEP_S = 0.1                        # sim time advanced per tick at most (keeps services responsive)
CMD_TIMEOUT_S = 0.5                     # stop a robot whose commands stop arriving (sim seconds)
WARN_THROTTLE_S = 2.0
MAP_TF_MODES = ("auto", "on", "off")
FRAME_POLICIES = ("drop", "wait")       # a frame due while the last renders: skip it | hold sim time
CAMERA = "camera"                       # the port rendered on the render thread (the others are cheap)
MAP_TF_RESUME_S = 2.0                   # wall s without another map -> odom publisher before the sim takes over
# Listening for other map -> odom publishers: best effort matches reliable and best-effort publishers.
TF_LISTEN_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT)

FROM_PROFILE = -1.0                     # a rate parameter's default: each agent's robot profile says
# parameter -> rate key: camera_rate, scan_rate (one per sensor port) and odom_rate
RATE_PARAMETERS = {f"{key}_rate": key for key in (*(port.name for port in SENSORS), ODOM)}
PARAMETERS: dict[str, Any] = {
    "house": 15, "seed": -1, "config": "", "footprint": "", "renderer": "auto", "real_time_factor": 1.0,
    **dict.fromkeys(RATE_PARAMETERS, FROM_PROFILE), "clock_rate": 100.0,
    "cmd_vel_stamped": False, "map_tf": "auto", "lockstep": False, "frame_policy": "drop",
}
HEARTBEAT_S = 0.5                       # lockstep: wall period of /clock and pose while waiting
# Appearance changes under a burst. A change costs its own work and more at the next readings (a light-map
# redo of ~0.1-0.7 s at the next camera frame, a new /map): the node measures that and lets changes take at
# most CHANGE_SHARE of its wall time (CHANGE_BURST_S at once), and of requests that wait together it makes
# at most CHANGES_PER_BATCH. The rest get a "busy" reply at once: every request is answered and /clock
# keeps its rate.
CHANGE_SHARE = 0.15
CHANGE_BURST_S = 1.0
CHANGES_PER_BATCH = 1
DIAGNOSTICS_PERIOD_S = 1.0              # wall seconds between /diagnostics messages (the ROS habit: 1 Hz)


class SimNode(Node):
    def __init__(self, overrides: dict[str, Any] | None = None) -> None:
        params = [Parameter(k, value=v) for k, v in (overrides or {}).items()]
        super().__init__("ravh_sim", parameter_overrides=params)
        read_only = ParameterDescriptor(read_only=True)
        p = {k: self.declare_parameter(k, v, read_only).value for k, v in PARAMETERS.items()}
        self.rtf = float(p["real_time_factor"])
        if not math.isfinite(self.rtf) or self.rtf < 0:
            raise UserError(f"real_time_factor must be >= 0 (0 = as fast as possible), got {self.rtf}")
        self.map_tf = str(p["map_tf"])
        if self.map_tf not in MAP_TF_MODES:
            raise UserError(f"map_tf must be one of {', '.join(MAP_TF_MODES)}, got {self.map_tf!r}")
        rates = {key: float(p[param]) for param, key in RATE_PARAMETERS.items() if p[param] != FROM_PROFILE}
        for param, key in RATE_PARAMETERS.items():
            if key in rates and not (math.isfinite(rates[key]) and rates[key] >= 0):
                raise UserError(f"{param} must be >= 0 Hz (0 = never), got {rates[key]}")
        self.frame_policy = str(p["frame_policy"])
        if self.frame_policy not in FRAME_POLICIES:
            raise UserError(f"frame_policy must be one of {', '.join(FRAME_POLICIES)}, got {self.frame_policy!r}")
        clock_rate = max(float(p["clock_rate"]), 1e-3)
        self.clock_period = 1.0 / clock_rate
        # The one thread that touches the renderers: the process's GL context is made, and stays current,
        # on the thread that builds the runtime (ravh_sim.render.backend), so the runtime is built there.
        self.render_thread = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ravh_render")
        self.runtime = self._on_render_thread(
            SimRuntime, int(p["house"]), p["config"] or None, None if p["seed"] == -1 else p["seed"],
            renderer=p["renderer"], rates=rates, footprint=p["footprint"] or None)
        self._frames: dict[str, Future] = {}          # agent -> its camera frame being rendered
        self._dropping = False
        self._captures_rendering = 0
        self._captures_waiting = 0                    # for a step past the agent's last capture stamp
        self._capture_stamps: dict[str, float] = {}   # agent -> its last capture's stamp
        self._step_waiters: list[RosFuture] = []      # done at the next physics step
        rt = self.runtime
        self.get_logger().info(
            f"house {rt.house.number}: {len(rt.house.rooms)} rooms, {len(rt.house.objects)} objects, "
            f"renderer {rt.world.renderer}, seed {rt.world.state.seed}, real-time factor {self.rtf:g}")
        self.lockstep = bool(p["lockstep"])
        self._allowed, self._heartbeat = rt.steps, 0.0    # lockstep: the step granted; last wall beat
        self._max_steps = round(MAX_STEP_S * rt.world.physics_hz)
        self._make_publishers()
        self._make_subscriptions(bool(p["cmd_vel_stamped"]))
        self._make_services()
        self._published_map = -1
        self._last_warn = 0.0
        self._last_cmd: dict[str, float] = {}
        self._wall0, self._sim0 = time.monotonic(), rt.time
        self._clock_due = Schedule.every(clock_rate, rt.world.physics_hz)
        self._clock_sent = -math.inf
        self._changes_in_batch = 0
        self._change_budget = WorkBudget(CHANGE_BURST_S, CHANGE_SHARE)
        self._charged: set[tuple[str, str]] = set()      # (agent, port): next reading's time is a change's
        self._own_map_odom: deque[tuple] = deque(maxlen=256)      # what this node put on /tf lately
        self._foreign_map_odom: dict[str, float] = {}              # odom frame -> wall time last seen
        self._publishing_map_tf = {agent.name: self.map_tf != "off" for agent in rt.agents}
        if self.map_tf == "auto":
            self.create_subscription(TFMessage, n.TF, self._on_tf, TF_LISTEN_QOS)
        self.health = SimHealth(self.rtf, self.get_logger().warning)
        self.diagnostics_pub = self.create_publisher(DiagnosticArray, n.DIAGNOSTICS, qos_profile_system_default)
        self._publish_latched()
        self.timer = self.create_timer(TICK_S, self._tick)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._publish_diagnostics)

    def _on_render_thread(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """``fn(*args, **kwargs)`` run on the render thread (after the frames queued before it); its result."""
        return self.render_thread.submit(fn, *args, **kwargs).result()

    # ------------------------------------------------------------------ set-up
    def _make_publishers(self) -> None:
        pub = self.create_publisher
        self.clock_pub = pub(Clock, n.CLOCK, STATE_QOS)
        self.map_pub = pub(OccupancyGrid, n.MAP, LATCHED_QOS)
        self.free_space_pub = pub(OccupancyGrid, n.FREE_SPACE_MAP, LATCHED_QOS)
        self.footprint_pub = pub(String, n.GROUND_TRUTH, LATCHED_QOS)
        self.labels_pub = pub(String, n.INSTANCE_LABELS, LATCHED_QOS)
        self.tf_pub = pub(TFMessage, n.TF, STATE_QOS)
        self.tf_static_pub = pub(TFMessage, n.TF_STATIC, LATCHED_QOS)
        self.agent_pubs: dict[str, dict[str, Any]] = {}
        for agent in self.runtime.agents:
            def name(base: str, a: Agent = agent) -> str:
                return n.agent_name(base, a.name, a.first)
            self.agent_pubs[agent.name] = {
                **{topic.key: pub(convert.KINDS[topic.kind].msg_type, name(topic.base), SENSOR_QOS)
                   for port in SENSORS for topic in port.topics},
                "odom": pub(Odometry, name(n.ODOM), STATE_QOS),
                "gt_pose": pub(PoseStamped, name(n.GROUND_TRUTH_POSE), STATE_QOS),
                "odom_tf": pub(TransformStamped, name(n.ODOM_TRANSFORM), STATE_QOS),
                "map_odom": pub(TransformStamped, name(n.MAP_TO_ODOM), STATE_QOS),
                "room": pub(String, name(n.ROOM), LATCHED_QOS),
                "capture": pub(String, name(n.CAPTURE_EVENT), STATE_QOS),
                "static": {child: pub(TransformStamped, name(n.TF_STATIC_TOPIC.format(child=child)), LATCHED_QOS)
                           for _, child, _, _ in self.runtime.static_transforms(agent)},
                "last_room": None,
            }

    def _make_subscriptions(self, stamped: bool) -> None:
        for agent in self.runtime.agents:
            topic = n.agent_name(n.CMD_VEL, agent.name, agent.first)
            if stamped:
                self.create_subscription(TwistStamped, topic,
                                         lambda m, a=agent: self._on_cmd(a, m.twist), COMMAND_QOS)
            else:
                self.create_subscription(Twist, topic, lambda m, a=agent: self._on_cmd(a, m), COMMAND_QOS)
            if self.lockstep:
                self.create_subscription(TwistStamped, n.agent_name(n.STEP, agent.name, agent.first),
                                         lambda m, a=agent: self._on_step(a, m), HANDOVER_QOS)

    def _make_services(self) -> None:
        srv = self.create_service
        self._json_service(n.QUERY_SERVICE, self._on_query)
        self._json_service(n.APPEARANCE_SERVICE, self._on_appearance)
        srv(GetMap, n.GET_MAP_SERVICE, lambda req, res: self._on_get_map(res, self.runtime.navigation.obstacle_map))
        srv(GetMap, n.GET_FREE_SPACE_SERVICE, lambda req, res: self._on_get_map(res, self.runtime.navigation.map))
        srv(GetPlan, n.GET_PLAN_SERVICE, self._on_get_plan)
        srv(Trigger, n.RESET_SERVICE, self._on_reset)
        # Captures in a group of their own: the executor runs the tick while a capture waits for its frame.
        captures = MutuallyExclusiveCallbackGroup()
        for agent in self.runtime.agents:
            srv(Trigger, n.agent_name(n.CAPTURE_SERVICE, agent.name, agent.first),
                partial(self._on_capture, agent), callback_group=captures)

    def _json_service(self, name: str, handler: Callable) -> None:
        """A JSON service that answers every request waiting for it: the executor takes one request
        per service per wait, so a burst faster than the node's ticks would pile up in the queue."""
        def callback(request: AddDiagnostics.Request, response: AddDiagnostics.Response):
            self._changes_in_batch = 0
            response = handler(request, response)
            self._answer_waiting(service, handler)
            return response
        service = self.create_service(AddDiagnostics, name, callback, qos_profile=SERVICE_QOS)

    @staticmethod
    def _answer_waiting(service: Any, handler: Callable) -> None:
        for _ in range(SERVICE_QUEUE):
            with service.handle:
                request, header = service.handle.service_take_request(AddDiagnostics.Request)
            if header is None:
                return
            service.send_response(handler(request, AddDiagnostics.Response()), header)

    def _busy(self) -> str | None:
        """Why an appearance change must wait (None: it can be made now)."""
        if self._changes_in_batch >= CHANGES_PER_BATCH:
            return "the sim is busy: requests came faster than it steps; send this one again in a moment"
        wait = self._change_budget.wait_s()
        if wait > 0:
            return (f"the sim is busy with earlier appearance changes (they may take {CHANGE_SHARE:.0%} of its "
                    f"time); send this one again in {wait:.1f} s")
        return None

    # ------------------------------------------------------------------ stepping
    def _tick(self) -> None:
        """Advance sim time towards wall time x RTF, publishing whatever falls due on the way."""
        rt = self.runtime
        if self.rtf == 0 and self._captures_rendering:
            return           # as fast as possible, yet not past a capture: readers would miss its parts
        last = rt.steps + self._max_steps
        if self.rtf > 0:
            last = min(last, rt.step_at(self._sim0 + self.rtf * (time.monotonic() - self._wall0)))
        if self.lockstep:
            last = min(last, self._allowed)
        deadline, first = time.monotonic() + MAX_STEP_S, rt.steps
        while rt.steps < last and time.monotonic() < deadline:
            self._watchdog()
            rt.step()
            self._publish_due()
        self.health.sim_time(rt.time)
        if rt.steps > first:
            waiters, self._step_waiters = self._step_waiters, []
            for step in waiters:
                step.set_result(None)
        if self.lockstep and rt.steps >= self._allowed and time.monotonic() - self._heartbeat > HEARTBEAT_S:
            self._arrived()
        if self.rtf > 0 and rt.time + MAX_STEP_S < self._sim0 + self.rtf * (time.monotonic() - self._wall0):
            self._wall0, self._sim0 = time.monotonic(), rt.time       # fell behind: do not try to catch up

    def _on_step(self, agent: Agent, msg: TwistStamped) -> None:
        """Lockstep: the behaviour's command for the next step and the sim time it may run to."""
        self._on_cmd(agent, msg.twist)
        self._allowed = max(self._allowed, self.runtime.step_at(convert.seconds(msg.header.stamp)))
        self._heartbeat = 0.0

    def _arrived(self) -> None:
        """Lockstep: at the granted time, the pose the behaviour acts on (repeated while waiting, with
        /clock, so late subscribers get it and nobody takes the pause for a dead sim)."""
        rt, self._heartbeat = self.runtime, time.monotonic()
        self.clock_pub.publish(convert.clock(rt.time))
        for agent in rt.agents:
            self.agent_pubs[agent.name]["gt_pose"].publish(convert.pose_stamped(agent.robot.pose,
                                                                                convert.header(rt.time, n.MAP_FRAME)))

    def _watchdog(self) -> None:
        for agent in self.runtime.agents:
            last = self._last_cmd.get(agent.name)
            if last is not None and self.runtime.time - last > CMD_TIMEOUT_S:
                agent.robot.set_command(0.0, 0.0)
                del self._last_cmd[agent.name]

    def _publish_due(self) -> None:
        rt = self.runtime
        if self._clock_due.due(rt.steps):
            self._now()
        if rt.map_version != self._published_map:
            start = time.monotonic()
            self._publish_map()                  # a door or a model changed: the change's cost
            self._change_budget.spend(time.monotonic() - start)
        for agent in rt.agents:
            if rt.due(agent, ODOM):
                self._publish_state(agent)
            for port in SENSORS:
                if rt.due(agent, port.name):
                    self._stream(agent, port)

    # ------------------------------------------------------------------ publishing
    def _now(self) -> float:
        """The sim time to stamp with, announced on /clock first if it is not yet: a stamp ahead of
        the clock subscribers have cannot be transformed on arrival (tf2 would extrapolate)."""
        t = self.runtime.time
        if t > self._clock_sent:
            self.clock_pub.publish(convert.clock(t))
            self._clock_sent = t
        return t

    def _publish_latched(self) -> None:
        footprint = self._publish_footprint()
        labels = {str(row["id"]): {"name": row["name"], "kind": row["kind"], "type": row["type"],
                                   "tags": row["tags"], "room": row["room"], "mask_color": row["mask_color"]}
                  for row in footprint["instances"]}
        self.labels_pub.publish(String(data=json.dumps(labels)))
        self._publish_map()
        self._publish_static()

    def _publish_map(self) -> None:
        """/map (the obstacle map) and /ravh/free_space (the robot's inflated free space)."""
        rt = self.runtime
        self._published_map = rt.map_version
        t = self._now()
        for publisher, grid in ((self.map_pub, rt.navigation.obstacle_map()),
                                (self.free_space_pub, rt.navigation.map())):
            publisher.publish(convert.occupancy_grid(grid, convert.header(t, n.MAP_FRAME), t))

    def _publish_footprint(self) -> dict[str, Any]:
        """The latched footprint: republished after every appearance change so it stays true."""
        footprint = self.runtime.footprint()
        self.footprint_pub.publish(String(data=json.dumps(footprint)))
        return footprint

    def _frame(self, agent: Agent, frame: str) -> str:
        return n.agent_name(frame, agent.name, agent.first)

    def _publish_static(self) -> None:
        """Every agent's sensor mounts in one latched /tf_static message: a latched topic keeps only its
        last message, so one message per agent would leave late joiners with the last agent's only."""
        t = self._now()
        transforms = []
        for agent in self.runtime.agents:
            for parent, child, xyz, quat in self.runtime.static_transforms(agent):
                tf = convert.transform(convert.header(t, self._frame(agent, parent)), self._frame(agent, child),
                                       xyz, quat)
                self.agent_pubs[agent.name]["static"][child].publish(tf)
                transforms.append(tf)
        self.tf_static_pub.publish(TFMessage(transforms=transforms))

    def _publish_state(self, agent: Agent) -> None:
        rt, pubs = self.runtime, self.agent_pubs[agent.name]
        t = self._now()
        odom_pose, true_pose = agent.robot.odometry, agent.robot.pose
        v, w = agent.robot.velocity
        odom_hdr = convert.header(t, self._frame(agent, n.ODOM_FRAME))
        base = self._frame(agent, n.BASE_FRAME)
        pubs["odom"].publish(convert.odometry(odom_pose, v, w, odom_hdr, base,
                                              (agent.profile.odom_linear_sigma, agent.profile.odom_angular_sigma)))
        pubs["gt_pose"].publish(convert.pose_stamped(true_pose, convert.header(t, n.MAP_FRAME)))
        odom_tf = convert.transform_2d(odom_hdr, base, odom_pose)
        map_odom = convert.transform_2d(convert.header(t, n.MAP_FRAME), odom_hdr.frame_id,
                                        rt.map_to_odom(agent))
        pubs["odom_tf"].publish(odom_tf)
        pubs["map_odom"].publish(map_odom)
        tf = [odom_tf]
        if self._owns_map_tf(agent):
            tf.append(map_odom)
            self._own_map_odom.append(_tf_key(map_odom))
        self.tf_pub.publish(TFMessage(transforms=tf))
        room = rt.room_of(agent)
        if room != pubs["last_room"]:
            pubs["last_room"] = room
            pubs["room"].publish(String(data=room or ""))

    def _stream(self, agent: Agent, port: SensorPort) -> None:
        """A reading of ``port`` that fell due: published on the topics that have subscribers (none:
        not taken); a camera frame goes to the render thread, as ``frame_policy`` says when it is busy."""
        pubs, rt = self.agent_pubs[agent.name], self.runtime
        topics = tuple(t for t in port.topics if pubs[t.key].get_subscription_count() > 0)
        if not topics:
            rt.skip(agent, port.name)
            return
        if port.name != CAMERA:
            start = time.monotonic()
            self._publish_sensor(agent, port, rt.read(agent, port.name), self._now(), topics)
            self._note_reading((agent.name, port.name), time.monotonic() - start)
            return
        busy = self._frames.get(agent.name)
        if busy is not None and not busy.done() and self.frame_policy == "drop":
            rt.skip(agent, port.name)
            self.health.frame_skipped()
            if not self._dropping:
                self._dropping = True
                self.get_logger().warning(
                    f"the camera cannot keep {agent.rates[port.name]:g} Hz at real-time factor {self.rtf:g}: "
                    "frames that fall due while one renders are dropped (frame_policy:=wait keeps every "
                    "frame by slowing the sim)")
            return
        if busy is not None:
            busy.result()                 # wait: sim time holds until the frame is out
        self._frames[agent.name] = self.render_thread.submit(
            self._stream_frame, agent, port, rt.frame_later(agent), self._now(), topics)

    def _stream_frame(self, agent: Agent, port: SensorPort, frame: Callable[[], Any], stamp: float,
                      topics: tuple[Topic, ...]) -> None:
        """On the render thread: a streamed frame; one that fails is dropped (counted, its cause logged
        once) and the stream goes on with the next."""
        try:
            self._render_frame(agent, port, frame, stamp, topics)
        except Exception:  # never die from a frame: _render_frame counted it
            pass

    def _render_frame(self, agent: Agent, port: SensorPort, frame: Callable[[], Any], stamp: float,
                      topics: tuple[Topic, ...]) -> None:
        """On the render thread: render ``frame`` and publish it on ``topics``, stamped ``stamp`` (when it
        was asked for: the sim time of its pose). A frame that fails is counted on /diagnostics and raised."""
        start = time.monotonic()
        try:
            data = frame()
        except Exception as e:
            self.health.frame_failed(f"{agent.name}'s {port.name} frame at t={stamp:.3f} s", e)
            raise
        self._publish_sensor(agent, port, data, stamp, topics)
        seconds = time.monotonic() - start
        self.health.frame_rendered(seconds)
        self._note_reading((agent.name, port.name), seconds)

    def _publish_sensor(self, agent: Agent, port: SensorPort, data: Any, stamp: float,
                        topics: tuple[Topic, ...]) -> None:
        """One reading ``data`` of ``agent``'s sensor of ``port`` on ``topics``, all with one stamp."""
        pubs, frame = self.agent_pubs[agent.name], self._frame(agent, port.frame)
        hdr = convert.header(stamp, frame)
        for topic in topics:
            value = port.value(topic.key, data, agent.sensors[port.name], frame)
            pubs[topic.key].publish(convert.KINDS[topic.kind].to_message(value, hdr))

    def _note_reading(self, key: tuple[str, str], seconds: float) -> None:
        """Charge the whole first reading of each sensor after an appearance change to the change (the
        renderer redoing its light maps). Only the excess is the change's, but under load every frame
        slows and the excess over a usual time measured then was too little: the charge errs high."""
        if key in self._charged:             # (the camera's frames are noted on the render thread)
            self._charged.discard(key)
            self._change_budget.spend(seconds)

    async def _publish_capture(self, agent: Agent) -> CaptureEvent:
        """A requested capture: every sensor of the agent at one stamp on every topic, subscribed or
        not, then the event on ravh/capture (pose, room) so recorders can store it as one dataset
        sample. Everything is taken now (stamp, pose, the frame's number); the camera frame is rendered
        on the render thread, after the frames already queued, and the event waits for it, the tick
        not: physics and /clock go on meanwhile. At real-time factor 0 (as fast as possible) the tick
        does wait: there is no rate to keep, and a sim racing on would push the capture's readings out
        of its readers' queues before they took them."""
        rt, stamp = self.runtime, await self._capture_stamp(agent)
        event = rt.capture_event(agent)
        rendered = []
        self._captures_rendering += 1
        try:
            for port in SENSORS:
                if port.name == CAMERA:
                    rendered.append(self.render_thread.submit(
                        self._render_frame, agent, port, rt.frame_later(agent), stamp, port.topics))
                else:
                    self._publish_sensor(agent, port, rt.read(agent, port.name), stamp, port.topics)
            for frame in rendered:
                await _awaitable(frame)
        finally:
            self._captures_rendering -= 1
        self.agent_pubs[agent.name]["capture"].publish(String(data=event.to_json()))
        return event

    async def _capture_stamp(self, agent: Agent) -> float:
        """Sim time now, once it is past ``agent``'s last capture stamp (waiting for the next physics step
        if need be; in lockstep the sim grants itself that step): every capture has a stamp of its own."""
        rt = self.runtime
        self._captures_waiting += 1
        try:
            while rt.time <= self._capture_stamps.get(agent.name, -math.inf):
                if self.lockstep:
                    self._allowed = max(self._allowed, rt.steps + 1)
                step = RosFuture()
                self._step_waiters.append(step)
                await step
        finally:
            self._captures_waiting -= 1
        stamp = self._capture_stamps[agent.name] = self._now()
        return stamp

    def _publish_diagnostics(self) -> None:
        self.diagnostics_pub.publish(self.health.array(self.runtime.time,
                                                       self._captures_waiting + self._captures_rendering))

    # ------------------------------------------------------------------ map -> odom ownership
    def _on_tf(self, msg: TFMessage) -> None:
        """Note map -> odom edges that this node did not publish (a SLAM or localisation node)."""
        for tf in msg.transforms:
            if tf.header.frame_id.lstrip("/") == n.MAP_FRAME and _tf_key(tf) not in self._own_map_odom:
                self._foreign_map_odom[tf.child_frame_id.lstrip("/")] = time.monotonic()

    def _owns_map_tf(self, agent: Agent) -> bool:
        """Whether the sim publishes ``agent``'s map -> odom on /tf now (see ``map_tf``); logs each
        hand-over once."""
        if self.map_tf != "auto":
            return self.map_tf == "on"
        odom = self._frame(agent, n.ODOM_FRAME)
        seen = self._foreign_map_odom.get(odom)
        owns = seen is None or time.monotonic() - seen > MAP_TF_RESUME_S
        if owns != self._publishing_map_tf[agent.name]:
            self._publishing_map_tf[agent.name] = owns
            self.get_logger().info(
                f"map_tf auto: no other node has published {n.MAP_FRAME} -> {odom} for {MAP_TF_RESUME_S:g} s; "
                "the sim publishes its ground truth on /tf again" if owns else
                f"map_tf auto: another node publishes {n.MAP_FRAME} -> {odom}; the sim stops publishing "
                f"its ground truth on /tf (still on {self._frame(agent, n.MAP_TO_ODOM)})")
        return owns

    # ------------------------------------------------------------------ callbacks
    def _warn(self, text: str) -> None:
        now = time.monotonic()
        if now - self._last_warn >= WARN_THROTTLE_S:
            self._last_warn = now
            self.get_logger().warning(text)

    def _on_cmd(self, agent: Agent, twist: Twist) -> None:
        try:
            self.runtime.command(agent, twist.linear.x, twist.angular.z)
            self._last_cmd[agent.name] = self.runtime.time
        except UserError as e:
            self._warn(str(e))

    def _on_query(self, request: AddDiagnostics.Request, response: AddDiagnostics.Response):
        reply = self.runtime.query(request.load_namespace)
        response.success, response.message = bool(reply["ok"]), json.dumps(reply)
        _forget_if_oversized(request)
        return response

    def _on_appearance(self, request: AddDiagnostics.Request, response: AddDiagnostics.Response):
        start = time.monotonic()
        # read and checked here (cheap, no state), so a bad or a refused request never waits for a frame
        reply = self.runtime.appearance_refusal(request.load_namespace, self._busy)
        if reply is None:
            # on the render thread: a renderer reads the world's appearance while it renders
            reply = self._on_render_thread(self.runtime.change_appearance, request.load_namespace)
        if reply["ok"]:
            self._changes_in_batch += 1
            self._publish_footprint()            # /map follows on the next step if doors changed
            self._charged = {(agent.name, port.name) for agent in self.runtime.agents for port in SENSORS}
            self._change_budget.spend(time.monotonic() - start)
        response.success, response.message = bool(reply["ok"]), json.dumps(reply)
        _forget_if_oversized(request)
        return response

    def _on_get_map(self, response: GetMap.Response, grid: Callable[[], Grid]):
        t = self._now()
        response.map = convert.occupancy_grid(grid(), convert.header(t, n.MAP_FRAME), t)
        return response

    def _on_get_plan(self, request: GetPlan.Request, response: GetPlan.Response):
        rt = self.runtime
        start, goal = (request.start.pose.position, request.goal.pose.position)
        frames = (request.start.header.frame_id, request.goal.header.frame_id)
        response.plan.header = convert.header(self._now(), n.MAP_FRAME)
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
            self._on_render_thread(self.runtime.reset)
            self._publish_footprint()
            response.success, response.message = True, "agents back at their start poses"
        except Exception as e:  # never die from a request
            response.success, response.message = False, f"{type(e).__name__}: {e}"
        return response

    async def _on_capture(self, agent: Agent, request: Trigger.Request, response: Trigger.Response):
        try:
            event = await self._publish_capture(agent)
            response.success, response.message = True, event.to_json()
        except Exception as e:  # never die from a request
            response.success, response.message = False, f"{type(e).__name__}: {e}"
        return response

    def in_flight(self) -> bool:
        """Whether a requested capture is still waiting for its stamp or its frame (spin_until_stopped
        finishes it)."""
        return self._captures_rendering + self._captures_waiting > 0

    def close(self) -> None:
        self._on_render_thread(self.runtime.close)
        self.render_thread.shutdown()


class WorkBudget:
    """Wall time some work may take from a loop: ``burst`` seconds at once, refilled at ``share`` seconds
    per second (a token bucket counted in seconds)."""

    def __init__(self, burst: float, share: float) -> None:
        self.burst, self.share = burst, share
        self.level, self._at = burst, time.monotonic()
        self._lock = threading.Lock()               # spent from the render thread too

    def _refill(self) -> None:
        now = time.monotonic()
        self.level, self._at = min(self.burst, self.level + self.share * (now - self._at)), now

    def spend(self, seconds: float) -> None:
        with self._lock:
            self._refill()
            self.level -= seconds

    def wait_s(self) -> float:
        """How long until the work may run again (0: now)."""
        with self._lock:
            self._refill()
            return 0.0 if self.level > 0 else -self.level / self.share


def _awaitable(future: Future) -> RosFuture:
    """A future of another thread as one an rclpy coroutine callback can await (the executor resumes
    the callback on its turns until the future is done); its result or exception."""
    awaited = RosFuture()

    def hand_over(done: Future) -> None:
        error = done.exception()
        if error is None:
            awaited.set_result(done.result())
        else:
            awaited.set_exception(error)
    future.add_done_callback(hand_over)
    return awaited


def _forget_if_oversized(request: AddDiagnostics.Request) -> None:
    """After an oversized request (refused by its length) drop its text and return the memory it took."""
    if len(request.load_namespace) > MAX_REQUEST_CHARS:
        request.load_namespace = ""
        return_freed_memory()


def _tf_key(tf: TransformStamped) -> tuple:
    """What tells one transform message from another (stamp, child and values)."""
    t, r = tf.transform.translation, tf.transform.rotation
    return (tf.child_frame_id, tf.header.stamp.sec, tf.header.stamp.nanosec, t.x, t.y, t.z, r.x, r.y, r.z, r.w)


def parse_args(argv: list[str]) -> dict[str, Any]:
    """Command-line flags (each also a ROS parameter: ``--ros-args -p house:=15`` works too)."""
    p = argparse.ArgumentParser(prog="sim", description="ravh_sim: a Robot@VirtualHome house on ROS 2")
    p.add_argument("--house", type=int)
    p.add_argument("--seed", type=int)
    p.add_argument("--config")
    p.add_argument("--footprint", help="rebuild the world of this footprint file (house and settings)")
    p.add_argument("--renderer", choices=BACKENDS)
    p.add_argument("--rtf", "--real-time-factor", dest="real_time_factor", type=float,
                   help="sim seconds per wall second; 0 = as fast as possible (default 1)")
    for param in RATE_PARAMETERS:
        p.add_argument("--" + param.replace("_", "-"), dest=param, type=float,
                       help="Hz of sim time for every agent (default: its robot profile's; 0 = never)")
    p.add_argument("--cmd-vel-stamped", dest="cmd_vel_stamped", action="store_true", default=None)
    p.add_argument("--map-tf", dest="map_tf", choices=MAP_TF_MODES,
                   help="who publishes map -> odom on /tf: auto (default: the sim unless another node "
                        "does), on (always the sim), off (never the sim)")
    p.add_argument("--lockstep", action="store_true", default=None,
                   help="advance sim time only as far as a behaviour grants on ravh/step (reproducible runs)")
    p.add_argument("--frame-policy", dest="frame_policy", choices=FRAME_POLICIES,
                   help="a camera frame due while the last one renders: drop (default: keep the real-time "
                        "factor, publish fewer frames) or wait (keep the camera rate, slow the sim)")
    args = p.parse_args(argv)
    return {k: v for k, v in vars(args).items() if v is not None}


def main(argv: list[str] | None = None) -> int:
    return run_node(lambda args: SimNode(parse_args(args)), argv)


if __name__ == "__main__":
    raise SystemExit(main())
