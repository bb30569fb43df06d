"""A behaviour (Wanderer, Grid) as a separate ROS process that only uses the sim node's interface.

The node learns its agent from the footprint on /ravh/ground_truth (the first agent unless told; the
first one drives the plain topics, whatever its name), the house from the ground-truth service
(rooms, floors, ceiling lights) and /ravh/free_space, follows the robot on ground_truth/pose,
drives it with cmd_vel and asks for captures through the capture service. It runs on sim time, so it
keeps pace with a sim that runs faster than real time.
Every capture it gets back is logged with its pose and room (and written to ``--log`` as JSON lines).

With ``--wait-recorder`` (what ``ravh raid`` uses) a capture counts only once a recorder says it stored
it (``ravh/capture_recorded``): the behaviour holds the robot still until then, so at most one capture
is ever in flight and none can be lost under load; one that never arrives ends the run with an error.
With ``--lockstep`` (also ``ravh raid``'s, with a sim started with --lockstep) the behaviour drives sim
time: each control step it acts on the pose at the instant the sim stopped, then grants the next
step together with its command on ``ravh/step``; nothing depends on wall-clock timing, so the same
seed gives the same run.
The node also stops with an error when the sim goes away (no /clock for a few wall seconds).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from geometry_msgs.msg import PoseStamped, Twist, TwistStamped
from nav_msgs.msg import OccupancyGrid
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.task import Future
from std_msgs.msg import String
from std_srvs.srv import Trigger

from ravh_msgs_py import names as n
from ravh_msgs_py.capture import CaptureEvent, CaptureFormatError, CaptureRecorded
from ravh_msgs_py.client import RavhClient
from ravh_sim.behaviours.waypoints import Layout
from ravh_sim.errors import UserError
from ravh_sim.nav.follower import PathFollower
from ravh_sim.nav.grid import Grid
from ravh_sim.nav.planner import Path as PlannedPath
from ravh_sim.nav.planner import plan_path
from ravh_sim.nodes import convert
from ravh_sim.nodes.common import COMMAND_QOS, HANDOVER_QOS, LATCHED_QOS, RECORDED_QOS, STATE_QOS, SimWatchdog
from ravh_sim.poses import Pose2D
from ravh_sim.robot.profile import load_profile

CONTROL_HZ = 20.0                # sim-time control rate (as nav2's controllers)
STARTUP_TIMEOUT_S = 60.0
RECORD_TIMEOUT_S = 60.0          # wall seconds a recorder may take to confirm a capture


class RosRobot:
    """The robot as the behaviours see it (``pose``, ``set_command``), over ROS topics."""

    def __init__(self, node: Node, agent: str, first: bool, lockstep: bool = False) -> None:
        self._pub = None if lockstep else node.create_publisher(Twist, n.agent_name(n.CMD_VEL, agent, first),
                                                                COMMAND_QOS)
        self.command = (0.0, 0.0)             # lockstep: sent with the next step instead of on cmd_vel
        self.pose_msg: PoseStamped | None = None
        self.on_pose: Callable[[PoseStamped], None] | None = None
        node.create_subscription(PoseStamped, n.agent_name(n.GROUND_TRUTH_POSE, agent, first),
                                 self._on_pose, STATE_QOS)

    def _on_pose(self, msg: PoseStamped) -> None:
        self.pose_msg = msg
        if self.on_pose:
            self.on_pose(msg)

    @property
    def pose(self) -> Pose2D:
        assert self.pose_msg is not None, "no pose yet"
        return convert.pose_of(self.pose_msg.pose)

    def set_command(self, v: float, w: float) -> None:
        self.command = (float(v), float(w))
        if self._pub:
            msg = Twist()
            msg.linear.x, msg.angular.z = self.command
            self._pub.publish(msg)


class RosNavigation:
    """The robot's free space from /ravh/free_space (latched, republished when doors change) and plans on it."""

    def __init__(self, node: Node) -> None:
        self.grid: Grid | None = None
        node.create_subscription(OccupancyGrid, n.FREE_SPACE_MAP, self._on_map, LATCHED_QOS)

    def _on_map(self, msg: OccupancyGrid) -> None:
        self.grid = convert.grid_of(msg)

    def map(self) -> Grid:
        assert self.grid is not None, "no free-space map yet"
        return self.grid

    def plan(self, start: tuple[float, float], goal: tuple[float, float]) -> PlannedPath:
        return plan_path(self.map(), start, goal)


def read_footprint(node: Node) -> dict[str, Any]:
    """The sim's latched footprint (house number, settings, instances)."""
    import rclpy
    got: list[str] = []
    sub = node.create_subscription(String, n.GROUND_TRUTH, lambda m: got.append(m.data), LATCHED_QOS)
    end = time.monotonic() + STARTUP_TIMEOUT_S
    while not got and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    node.destroy_subscription(sub)
    if not got:
        raise UserError(f"no sim node published {n.GROUND_TRUTH} within {STARTUP_TIMEOUT_S:.0f} s "
                        f"(is `ravh sim` running on ROS_DOMAIN_ID {os.environ.get('ROS_DOMAIN_ID', '0')}?)")
    return json.loads(got[0])


def which_agent(node: Node, wanted: str | None, footprint: dict[str, Any] | None = None) -> tuple[str, bool, str]:
    """(name, first, profile) of the agent to drive: ``wanted`` or else the sim's first agent, as the
    latched footprint lists them (the first uses the plain topic names, whatever it is called)."""
    footprint = read_footprint(node) if footprint is None else footprint
    agents = n.footprint_agents(footprint)
    if not agents:
        raise UserError("the sim has no agents")
    name = wanted or agents[0]
    if name not in agents:
        raise UserError(f"unknown agent {name!r}; the sim has {', '.join(agents)}")
    spec = footprint["settings"]["agents"][agents.index(name)]
    return name, name == agents[0], str(spec.get("profile", n.DEFAULT_PROFILE))


def layout_from_ground_truth(client: RavhClient) -> Layout:
    """Room floors and ceiling lights from the sim's ground-truth queries."""
    rooms: dict[str, tuple[tuple[tuple[float, float], ...], ...]] = {}
    for summary in client.query("rooms"):
        room = client.query("room", id=summary["id"])
        rooms[room["id"]] = (tuple((float(x), float(y)) for x, y in room["floor"]),)
    lights = tuple((o["room"], tuple(o["position"][:2])) for o in client.query("objects_with_tag", tag="Light"))
    return Layout(rooms, lights)


class BehaviourNode(Node):
    """Hosts one behaviour: ``make_behaviour(follower, layout, grid, start_xy, footprint)`` builds it once
    the sim is up."""

    def __init__(self, name: str, make_behaviour: Callable[[PathFollower, Layout, Grid, tuple, dict], Any],
                 agent: str | None = None, profile: str | None = None, log_path: Path | None = None,
                 wait_recorder: bool = False, lockstep: bool = False) -> None:
        """``agent``: None drives the sim's first agent; ``profile``: None takes the agent's from the sim."""
        super().__init__(name, parameter_overrides=[Parameter("use_sim_time", value=True)])
        self.footprint = read_footprint(self)
        agent, first, agent_profile = which_agent(self, agent, self.footprint)
        self.robot = RosRobot(self, agent, first, lockstep)
        self.navigation = RosNavigation(self)
        self.client = RavhClient(self)
        self.capture_client = self.create_client(Trigger, n.agent_name(n.CAPTURE_SERVICE, agent, first))
        self.capture_count = 0
        self.finished = Future()                 # done when the behaviour ends (run_node returns then)
        self._pending: set[Future] = set()
        self.wait_recorder, self.lockstep = wait_recorder, lockstep
        self._unrecorded: dict[float, tuple[CaptureEvent, float]] = {}   # stamp -> (event, wall deadline)
        self._recorded_early: set[float] = set()     # confirmed before the capture's reply was handled
        if wait_recorder:
            self.create_subscription(String, n.agent_name(n.CAPTURE_RECORDED, agent, first), self._on_recorded,
                                     RECORDED_QOS)
        self._log_file = open(log_path, "a") if log_path else None
        SimWatchdog(self)
        self.create_timer(1.0, self._check_recorder, clock=Clock(clock_type=ClockType.STEADY_TIME))
        self._wait_for_sim()
        layout = layout_from_ground_truth(self.client)
        follower = PathFollower(self.robot, self.navigation, load_profile(profile or agent_profile))
        self.behaviour = make_behaviour(follower, layout, self.navigation.map(), self.robot.pose[:2], self.footprint)
        self._last_t: float | None = None
        self._rooms_seen: set[str] = set()
        self._granted: float | None = 0.0            # lockstep: sim time granted and not reached yet
        self._reached: float | None = None           # lockstep: sim time reached, next step not granted
        if lockstep:
            self._step_pub = self.create_publisher(TwistStamped, n.agent_name(n.STEP, agent, first), HANDOVER_QOS)
            self.robot.on_pose = self._on_pose_lockstep
        else:
            self.create_timer(1.0 / CONTROL_HZ, self._tick)
        self.get_logger().info(f"{name}: started at {tuple(round(v, 2) for v in self.robot.pose)}"
                               + (" (lockstep)" if lockstep else ""))

    def _wait_for_sim(self) -> None:
        import rclpy
        end = time.monotonic() + STARTUP_TIMEOUT_S
        while time.monotonic() < end:
            if self.robot.pose_msg and self.navigation.grid is not None and \
                    self.client.wait_for_services(0.1) and self.capture_client.service_is_ready():
                return
            rclpy.spin_once(self, timeout_sec=0.1)
        raise UserError(f"no sim node answered within {STARTUP_TIMEOUT_S:.0f} s "
                        f"(is `ravh sim` running on ROS_DOMAIN_ID {os.environ.get('ROS_DOMAIN_ID', '0')}?)")

    def _tick(self) -> None:
        """Sim-time timer (not lockstep): one control step, unless holding for the recorder."""
        now = self.get_clock().now().nanoseconds * 1e-9
        if self._holding():
            self.robot.set_command(0.0, 0.0)
            self._last_t = now
            return
        self._step(now)

    def _on_pose_lockstep(self, msg: PoseStamped) -> None:
        """Lockstep: the sim reached the granted time; act on its state there, then grant the next step."""
        t = convert.seconds(msg.header.stamp)
        if self._granted is None or t + 1e-6 < self._granted:
            return
        self._granted, self._reached = None, t
        self._step(t)
        self._grant_when_ready()

    def _grant_when_ready(self) -> None:
        """Lockstep: the sim waits while captures are on their way (they are taken at this instant)."""
        if self._reached is None or self._holding() or self.finished.done():
            return
        msg = TwistStamped()
        msg.header.stamp = convert.stamp(self._reached + 1.0 / CONTROL_HZ)
        msg.twist.linear.x, msg.twist.angular.z = self.robot.command
        self._granted = self._reached + 1.0 / CONTROL_HZ
        self._reached = None
        self._step_pub.publish(msg)

    def _step(self, now: float) -> None:
        dt = 1.0 / CONTROL_HZ if self._last_t is None else now - self._last_t
        self._last_t = now
        if dt <= 0 or self.finished.done():
            return
        if not self.behaviour.done:
            for reason in self.behaviour.update(dt):
                future = self.capture_client.call_async(Trigger.Request())
                self._pending.add(future)
                future.add_done_callback(lambda f, r=reason: self._on_capture(f, r))
        if self.behaviour.done:
            self.robot.set_command(0.0, 0.0)
            self._finish_when_answered()

    def _holding(self) -> bool:
        """Captures in flight hold the robot: with --wait-recorder until recorded, in lockstep until
        answered (so each is taken at the instant it was asked for)."""
        return bool(self._unrecorded) or bool(self._pending) and (self.wait_recorder or self.lockstep)

    def _check_recorder(self) -> None:
        """Wall-clock timer: a capture the recorder never confirms ends the run loudly."""
        for stamp, (_, deadline) in self._unrecorded.items():
            if time.monotonic() > deadline:
                raise UserError(f"the capture at t={stamp:.3f} s never reached a recorder within "
                                f"{RECORD_TIMEOUT_S:.0f} s (is `ravh recorder` running?)")

    def _finish_when_answered(self) -> None:
        """End once the behaviour is done and every capture it asked for has been answered (and, with
        --wait-recorder, recorded)."""
        if self.behaviour.done and not self._pending and not self._unrecorded and not self.finished.done():
            self.get_logger().info(f"done: {self.capture_count} captures, rooms {sorted(self._rooms_seen)}")
            self.finished.set_result(True)

    def _on_capture(self, future, reason: str) -> None:
        self._pending.discard(future)
        result = future.result()
        if result is None or not result.success:
            problem = f"capture failed: {getattr(result, 'message', 'no reply')}"
            if self.wait_recorder:                 # every capture asked for must reach the dataset
                raise UserError(problem)
            self.get_logger().warning(problem)
        else:
            event = replace(CaptureEvent.from_json(result.message), reason=reason)
            if self.wait_recorder and event.stamp not in self._recorded_early:
                self._unrecorded[event.stamp] = (event, time.monotonic() + RECORD_TIMEOUT_S)
            else:
                self._recorded_early.discard(event.stamp)
                self._record(event)
        self._finish_when_answered()
        self._grant_when_ready()

    def _on_recorded(self, msg: String) -> None:
        try:
            stamp = CaptureRecorded.from_json(msg.data).stamp
        except CaptureFormatError as e:
            self.get_logger().error(f"ignored a capture confirmation: {e}")
            return
        if stamp not in self._unrecorded:           # the recorder can be quicker than the capture's reply
            self._recorded_early.add(stamp)
        else:
            self._record(self._unrecorded.pop(stamp)[0])
            self._finish_when_answered()
            self._grant_when_ready()

    def _record(self, event: CaptureEvent) -> None:
        self.capture_count += 1
        if event.room:
            self._rooms_seen.add(event.room)
        x, y, yaw = event.pose
        self.get_logger().info(f"capture {self.capture_count} t={event.stamp:.2f} pose=({x:.2f}, {y:.2f}, "
                               f"{math.degrees(yaw):.0f} deg) room={event.room} [{event.reason}]")
        if self._log_file:
            self._log_file.write(event.to_json() + "\n")
            self._log_file.flush()

    def close(self) -> None:
        self.robot.set_command(0.0, 0.0)
        if self._log_file:
            self._log_file.close()


def common_args(prog: str, description: str) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=prog, description=description)
    p.add_argument("--agent", default=None,
                   help="agent to drive (default: the sim's first, whose topics have no prefix)")
    p.add_argument("--profile", default=None, help="robot profile of that agent (default: its profile in the sim)")
    p.add_argument("--log", type=Path, help="append every capture (pose, room) to this JSON-lines file")
    p.add_argument("--wait-recorder", action="store_true",
                   help="count a capture only once a recorder stored it; hold still until then")
    p.add_argument("--lockstep", action="store_true",
                   help="drive a sim started with --lockstep: sim time advances only step by step as "
                        "this behaviour grants it (reproducible runs)")
    return p
