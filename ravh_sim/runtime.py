"""The simulator without ROS: one house, its robots and sensors on one sim clock.

:class:`SimRuntime` is what the sim node wraps: it builds the World from a house and settings, keeps
the Simulation (physics + agents), each agent's sensors (one per port of
:data:`~ravh_sim.sensors.suite.SENSORS`), the Navigation Manager and the ground truth, and says which
sensors are due at the current physics step (rates from each agent's robot profile, as whole steps:
:class:`Schedule`). Everything here is plain
Python, so the whole data path (house file -> World -> sensors) is tested without a ROS graph, and the
node only converts and publishes.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ravh_msgs_py import appearance as appearance_lang
from ravh_msgs_py import names
from ravh_msgs_py.capture import CaptureEvent
from ravh_msgs_py.query import BAD_REQUEST, BUSY, INTERNAL, MAX_COORDINATE, QueryError, error_reply, ok_reply
from ravh_sim.errors import UserError
from ravh_sim.nav.navigation import Navigation
from ravh_sim.nav.planner import Path as PlannedPath
from ravh_sim.poses import compose, matrix_from_quaternion, relative
from ravh_sim.render.backend import resolve_backend
from ravh_sim.robot.profile import RobotProfile, load_profile
from ravh_sim.robot.robot import Robot
from ravh_sim.robot.simulation import Simulation
from ravh_sim.schema import shown
from ravh_sim.sensors.camera import Capture
from ravh_sim.sensors.ports import Mount
from ravh_sim.sensors.readings import Scan
from ravh_sim.sensors.suite import SENSORS
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.footprint import load_footprint, make_footprint
from ravh_sim.world.ground_truth import GroundTruth
from ravh_sim.world.house import House, load_house
from ravh_sim.world.scene import World
from ravh_sim.world.settings import load_settings, resolve

# Commands beyond these magnitudes are refused as nonsense rather than clamped (clamping a
# 1e9 m/s command would hide a unit bug in the sender); smaller overshoots are clamped by the robot.
ABSURD_LINEAR = 10.0      # m/s
ABSURD_ANGULAR = 20.0     # rad/s
ODOM = "odom"             # the rate key of odometry, the true pose and /tf (a sensor's key is its port's name)
PORTS = {port.name: port for port in SENSORS}
STAMP_RESOLUTION = 1e-9   # s: a ROS stamp's resolution (a stamp within it of a physics step is that step)
RATE_DENOMINATOR = 10**6  # rates are read as the fractions they were written as (7.3 Hz = 73/10 Hz)


@dataclass
class Schedule:
    """When the readings of one rate fall due, in whole physics steps (as gym-pybullet-drones schedules
    control, so sim time = step x dt and nothing drifts or needs a float tolerance): reading j at the
    first step at or after j / rate seconds, step ceil(j x physics Hz / rate), exactly in fractions
    (30 Hz at 240 Hz physics: every 8 steps; 100 Hz: steps 0, 3, 5, 8, 10, ...). Asked after each
    step; a reading due at a step not asked about is taken at the next one, and none is made up."""
    steps_per_reading: Fraction | None     # None: never (rate 0)
    next_reading: int = 0

    @staticmethod
    def every(rate: float, physics_hz: float) -> Schedule:
        if rate <= 0:
            return Schedule(None)
        return Schedule(Fraction(physics_hz).limit_denominator(RATE_DENOMINATOR)
                        / Fraction(rate).limit_denominator(RATE_DENOMINATOR))

    def due(self, step: int) -> bool:
        """True (and the reading taken) when a reading is due at physics step ``step``."""
        per = self.steps_per_reading
        if per is None or step < math.ceil(self.next_reading * per):
            return False
        self.next_reading = math.floor(step / per) + 1       # the first reading due after this step
        return True


@dataclass
class Agent:
    name: str
    robot: Robot
    profile: RobotProfile
    sensors: dict[str, Any]          # port name -> the sensor (a SmartCamera, a Laser, ...)
    rates: dict[str, float]          # Hz of sim time by rate key (ODOM and each port's name); 0 = never
    schedules: dict[str, Schedule]   # when each rate key's readings fall due
    first: bool                      # the first agent uses the plain topic names


class SimRuntime:
    """A running house: physics, agents, sensors, appearance, navigation and ground truth."""

    def __init__(self, house: int | str | House, config: str | Path | None = None, seed: int | None = None,
                 renderer: str = "auto", rates: Mapping[str, float] | None = None,
                 footprint: str | Path | None = None) -> None:
        """``footprint``: rebuild exactly the world a footprint file describes (its house and its
        resolved settings); ``house``, ``config`` and ``seed`` are then ignored. ``rates``: Hz by rate
        key (ODOM, a port's name) for every agent, over those of its robot profile."""
        unknown = set(rates or {}) - {ODOM, *PORTS}
        if unknown:
            raise UserError(f"unknown rate {', '.join(sorted(unknown))}; valid: {', '.join([ODOM, *PORTS])}")
        if footprint:
            number, resolved = load_footprint(Path(footprint))
            self.house = load_house(number)
        else:
            self.house = house if isinstance(house, House) else load_house(house)
            resolved = resolve(load_settings(config), self.house, seed, str(config or "config/default.yaml"))
        self.initial = resolved
        self.backend = resolve_backend(renderer)          # gl | tiny: what every camera here draws with
        self.world = World(self.house, resolved)
        self.appearance = Appearance(self.world)
        self.sim = Simulation(self.world)
        self.agents = []
        for i, spec in enumerate(resolved.agents):
            profile = load_profile(spec.profile)
            sensors = {port.name: port.build(self.world, profile.spec(port), spec.name, self.backend)
                       for port in SENSORS}
            own = {ODOM: profile.odom_rate, **{port.name: port.rate(profile.spec(port)) for port in SENSORS}}
            agent_rates = {**own, **(rates or {})}
            schedules = {key: Schedule.every(rate, self.world.physics_hz) for key, rate in agent_rates.items()}
            self.agents.append(Agent(spec.name, self.sim.robot(spec.name), profile, sensors, agent_rates,
                                     schedules, i == 0))
        self.navigation = Navigation(self.house, self.world.state, self.agents[0].profile
                                     if self.agents else load_profile(names.DEFAULT_PROFILE))
        self.ground_truth = GroundTruth(self.house, self.world.state)

    @property
    def map_version(self) -> int:
        """Changes when a door or an object model changed (the node republishes /map)."""
        return self.world.state.layout_revision

    # ------------------------------------------------------------------ time
    @property
    def time(self) -> float:
        return self.sim.time

    @property
    def steps(self) -> int:
        """Physics steps since the start (sim time = steps x dt)."""
        return self.sim.steps

    def step_at(self, t: float) -> int:
        """The first physics step at or after sim time ``t`` seconds (a stamp: to its resolution)."""
        return math.ceil((t - STAMP_RESOLUTION) * self.world.physics_hz)

    def step(self, n: int = 1) -> None:
        self.sim.step(n)

    def due(self, agent: Agent, what: str) -> bool:
        """True (and the reading taken) when ``what`` (a rate key: ODOM or a port's name) is due for
        ``agent`` at the current step."""
        return agent.schedules[what].due(self.steps)

    # ------------------------------------------------------------------ sensing
    def read(self, agent: Agent, port: str) -> Any:
        """The data of ``agent``'s sensor of port ``port`` now (a Capture, a Scan, ...)."""
        return PORTS[port].read(agent.sensors[port], agent.robot)

    def skip(self, agent: Agent, port: str) -> None:
        """A reading due but not taken (nobody listens, or the camera is busy): it still uses up its
        number, so the noise of later readings, captures among them, does not depend on who listened."""
        agent.sensors[port].count += 1

    def frame_later(self, agent: Agent) -> Callable[[], Capture]:
        """``agent``'s camera frame as of now (pose, velocity and frame number fixed now), rendered when
        called: the sim node renders on its own thread while physics goes on."""
        camera, robot = agent.sensors["camera"], agent.robot
        (x, y, yaw), velocity, index = robot.pose, robot.velocity, camera.take_index()
        return lambda: camera.capture(x, y, yaw, velocity=velocity, index=index)

    def capture(self, agent: Agent) -> Capture:
        return self.read(agent, "camera")

    def scan(self, agent: Agent) -> Scan:
        return self.read(agent, "scan")

    def sample(self, agent: Agent) -> tuple[CaptureEvent, dict[str, Any]]:
        """One synchronised capture as a dataset sample: its event and every sensor's dataset values
        by topic key, the values the recorder decodes from the topics (frames named as published)."""
        values: dict[str, Any] = {}
        for port in SENSORS:
            data, frame = self.read(agent, port.name), names.agent_name(port.frame, agent.name, agent.first)
            values.update({t.key: port.value(t.key, data, agent.sensors[port.name], frame)
                           for t in port.topics if t.dataset})
        return self.capture_event(agent), values

    def capture_event(self, agent: Agent) -> CaptureEvent:
        """What ``ravh/capture`` says about a capture taken now: where the agent stands, truly and by odometry."""
        return CaptureEvent(agent.name, self.time, agent.robot.pose, self.room_of(agent), agent.robot.odometry)

    def map_to_odom(self, agent: Agent) -> tuple[float, float, float]:
        """The map -> odom transform: where odometry's origin lies given its drift so far."""
        return compose(agent.robot.pose, relative(agent.robot.odometry, (0.0, 0.0, 0.0)))

    def static_transforms(self, agent: Agent) -> list[Mount]:
        """(parent, child, xyz, quaternion xyzw) of every sensor mount on base_link (at floor level)."""
        return [mount for port in SENSORS for mount in port.mounts(agent.profile.spec(port))]

    def room_of(self, agent: Agent) -> str | None:
        room = self.house.room_at(*agent.robot.pose[:2])
        return None if room is None else room.id

    # ------------------------------------------------------------------ commands
    def command(self, agent: Agent, v: float, w: float) -> None:
        """Velocity command; non-finite or absurd values raise UserError (the node warns)."""
        if not (math.isfinite(v) and math.isfinite(w)):
            raise UserError(f"rejected non-finite velocity command v={v}, w={w}")
        if abs(v) > ABSURD_LINEAR or abs(w) > ABSURD_ANGULAR:
            raise UserError(f"rejected absurd velocity command v={v:.3g} m/s, w={w:.3g} rad/s "
                            f"(limits {agent.profile.max_linear_speed} m/s, "
                            f"{agent.profile.max_angular_speed:.3g} rad/s)")
        agent.robot.set_command(v, w)

    def plan(self, start: tuple[float, ...], goal: tuple[float, ...],
             frames: tuple[str, str] = (names.MAP_FRAME, names.MAP_FRAME)) -> PlannedPath:
        """A GetPlan request: start and goal (x, y[, z]) in ``frames`` (map, an agent's odom, base_link or
        sensor frame, as on /tf; empty means map), planned in map. Numbers and frames are checked here,
        before they reach numpy and the planner."""
        points = []
        for name, point, frame in (("start", start, frames[0]), ("goal", goal, frames[1])):
            if not all(-MAX_COORDINATE <= v <= MAX_COORDINATE for v in point):   # False for NaN too
                raise UserError(f"rejected {name} ({', '.join(shown(v) for v in point)}): coordinates must be "
                                f"finite and within +-{MAX_COORDINATE:g} m")
            try:
                points.append(self.to_map(frame, *point))
            except UserError as e:
                raise UserError(f"rejected {name}: {e}") from None
        return self.navigation.plan(points[0], points[1])

    def to_map(self, frame: str, x: float, y: float, z: float = 0.0) -> tuple[float, float]:
        """(x, y) in map of a point given in ``frame``: map (or empty), an agent's odom, base_link or one
        of its sensor frames, named as the sim publishes them on /tf (``robot2/odom`` for a second agent).
        The transforms are the ones on /tf now: the ground-truth map -> odom, odometry, the mounts."""
        name = frame.lstrip("/")
        if name in ("", names.MAP_FRAME):
            return (x, y)
        known = [names.MAP_FRAME]
        for agent in self.agents:
            def own(base: str, a: Agent = agent) -> str:
                return names.agent_name(base, a.name, a.first)
            mounts = {own(child): (own(parent), xyz, quat)
                      for parent, child, xyz, quat in self.static_transforms(agent)}
            known += [own(names.ODOM_FRAME), own(names.BASE_FRAME), *mounts]
            if name == own(names.ODOM_FRAME):
                ox, oy, _ = compose(self.map_to_odom(agent), (x, y, 0.0))
                return (ox, oy)
            point, at = np.array([x, y, z]), name
            while at in mounts:                       # up the mounts to base_link
                parent, xyz, (qx, qy, qz, qw) = mounts[at]
                point = matrix_from_quaternion((qx, qy, qz, qw)) @ point + np.asarray(xyz, float)
                at = parent
            if at == own(names.BASE_FRAME):
                base = compose(self.map_to_odom(agent), agent.robot.odometry)     # map -> odom -> base_link
                bx, by, _ = compose(base, (float(point[0]), float(point[1]), 0.0))
                return (bx, by)
        raise UserError(f"unknown frame {shown(frame)}; known: {', '.join(known)}")

    def reset(self) -> None:
        """Agents back to their start poses, stopped; appearance back to the initial settings."""
        self.appearance.apply(self.initial)
        for spec, agent in zip(self.initial.agents, self.agents):
            agent.robot.set_command(0.0, 0.0)
            agent.robot.teleport(*spec.pose)

    # ------------------------------------------------------------------ JSON services
    def query(self, text: str) -> dict[str, Any]:
        return self.ground_truth.answer(text)

    def appearance_refusal(self, text: str | dict, busy: Callable[[], str | None]) -> dict[str, Any] | None:
        """The error reply to an appearance request refused without touching the world (None: go on
        with :meth:`change_appearance`): one that does not parse or names what the house lacks gets its
        own error; then ``busy()``, a reason it cannot be done now, makes a "busy" reply. Cheap, and
        safe on any thread: it reads only the request and the house."""
        refused = _replying(lambda: self.appearance.check_names(appearance_lang.parse(text)))
        if refused is not None:
            return refused
        why = busy()
        return None if why is None else error_reply(BUSY, why)

    def change_appearance(self, text: str | dict) -> dict[str, Any]:
        """Apply an appearance request (ravh_msgs_py.appearance); never raises."""
        reply = _replying(lambda: ok_reply(self.appearance.change(appearance_lang.parse(text))))
        assert reply is not None, "an ok reply or an error reply"
        return reply

    def footprint(self) -> dict[str, Any]:
        """The footprint of the world as the sensors see it now."""
        return make_footprint(self.house, self.world.state.settings())

    def close(self) -> None:
        for agent in self.agents:
            for sensor in agent.sensors.values():
                close = getattr(sensor, "close", None)     # sensors that hold resources (GL objects)
                if close is not None:
                    close()
        self.world.close()


def _replying(act: Callable[[], dict[str, Any] | None]) -> dict[str, Any] | None:
    """What ``act`` returns, or the error reply of what it raised: a request never takes the node down."""
    try:
        return act()
    except QueryError as e:
        return e.reply()
    except UserError as e:
        return error_reply(BAD_REQUEST, str(e), getattr(e, "valid", None))
    except Exception as e:
        return error_reply(INTERNAL, f"{type(e).__name__}: {e}")
