"""The sim node's parts on their own, without a ROS graph: parameters, pacing, the frame policy, unique
capture stamps, the appearance budget, map -> odom ownership and the command watchdog."""
from __future__ import annotations

import threading
import time
from concurrent.futures import Future
from types import SimpleNamespace

import pytest
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_sim.errors import UserError
from ravh_sim.nodes import convert
from ravh_sim.nodes.appearance_budget import CHANGE_BURST_S, AppearanceBudget
from ravh_sim.nodes.captures import Captures
from ravh_sim.nodes.command_watchdog import CMD_TIMEOUT_S, CommandWatchdog
from ravh_sim.nodes.frame_stream import FramePolicy
from ravh_sim.nodes.map_odom import MAP_TF_RESUME_S, MapOdomOwnership
from ravh_sim.nodes.pacing import HEARTBEAT_S, MAX_STEP_S, Pacing
from ravh_sim.nodes.sim_params import PARAMETERS, SimParams, parse_args


class Clock:
    """A wall clock the test moves (time.monotonic, patched)."""

    def __init__(self, monkeypatch) -> None:
        self.t = 1000.0
        monkeypatch.setattr(time, "monotonic", lambda: self.t)


@pytest.fixture
def clock(monkeypatch) -> Clock:
    return Clock(monkeypatch)


def _agent(name: str = "robot", first: bool = True) -> SimpleNamespace:
    return SimpleNamespace(name=name, first=first, robot=SimpleNamespace(command=None))


# --------------------------------------------------------------------------- parameters

def test_parameters_are_checked_and_shaped_for_the_node():
    p = SimParams.check({**PARAMETERS, "camera_rate": 2.0, "clock_rate": 0.0})
    assert p.house == 15 and p.seed is None and p.config is None and p.footprint is None
    assert p.rates == {"camera": 2.0}                 # only the rates given override the profiles
    assert p.clock_rate == 1e-3 and p.map_tf == "auto" and p.frame_policy == "drop"
    assert SimParams.check({**PARAMETERS, "seed": 0}).seed == 0


@pytest.mark.parametrize("name, value, message", [
    ("real_time_factor", -1.0, "real_time_factor must be >= 0"),
    ("real_time_factor", float("nan"), "real_time_factor must be >= 0"),
    ("map_tf", "maybe", "map_tf must be one of auto, on, off"),
    ("scan_rate", -2.0, "scan_rate must be >= 0 Hz"),
    ("frame_policy", "queue", "frame_policy must be one of drop, wait"),
])
def test_a_bad_parameter_is_one_user_error(name, value, message):
    with pytest.raises(UserError, match=message):
        SimParams.check({**PARAMETERS, name: value})


def test_flags_set_parameters_and_only_those_given():
    assert parse_args([]) == {}
    args = parse_args(["--rtf", "0", "--camera-rate", "3", "--lockstep", "--map-tf", "off"])
    assert args == {"real_time_factor": 0.0, "camera_rate": 3.0, "lockstep": True, "map_tf": "off"}
    assert set(args) <= set(PARAMETERS)


# --------------------------------------------------------------------------- pacing

def _step_at(t: float) -> int:
    return round(t * 100)                            # 100 Hz physics


def test_pacing_follows_wall_time_times_the_real_time_factor(clock):
    pacing = Pacing(rtf=2.0, lockstep=False, physics_hz=100, steps=0, sim_time=0.0)
    assert pacing.last_step(0, _step_at) == 0
    clock.t += 0.02                                  # 0.04 s of sim time asked
    assert pacing.last_step(0, _step_at) == 4
    clock.t += 10.0                                  # far behind: at most MAX_STEP_S per tick
    assert pacing.last_step(4, _step_at) == 4 + round(MAX_STEP_S * 100)
    pacing.settle(0.5)                               # fell behind: no catching up from here
    assert pacing.last_step(50, _step_at) == 50


def test_pacing_at_factor_zero_runs_a_whole_tick_and_lockstep_only_as_granted(clock):
    assert Pacing(0.0, False, 100, 0, 0.0).last_step(7, _step_at) == 7 + round(MAX_STEP_S * 100)
    pacing = Pacing(0.0, True, 100, steps=3, sim_time=0.03)
    assert pacing.last_step(3, _step_at) == 3
    pacing.grant(5)
    pacing.grant(4)                                  # a grant never takes time back
    assert pacing.last_step(3, _step_at) == 5


def test_lockstep_beats_while_waiting_and_at_once_after_a_behaviour_grants(clock):
    pacing = Pacing(1.0, True, 100, steps=0, sim_time=0.0)
    assert pacing.beat_due(0)
    assert not pacing.beat_due(0)                    # within HEARTBEAT_S of the last beat
    clock.t += HEARTBEAT_S + 0.01
    assert pacing.beat_due(0)
    pacing.behaviour_grants(10)
    assert not pacing.beat_due(9)                    # not there yet
    assert pacing.beat_due(10)                       # arrived: announced without waiting for a beat
    assert not Pacing(1.0, False, 100, 0, 0.0).beat_due(0)


# --------------------------------------------------------------------------- frame policy

def test_the_drop_policy_skips_a_frame_due_while_the_last_renders():
    policy, busy = FramePolicy("drop"), Future()
    assert policy.may_start("robot")
    policy.started("robot", busy)
    assert not policy.may_start("robot") and policy.may_start("other")
    busy.set_result(None)
    assert policy.may_start("robot")


def test_the_wait_policy_holds_the_next_frame_until_the_last_is_out():
    policy, busy = FramePolicy("wait"), Future()
    policy.started("robot", busy)
    timer = threading.Timer(0.2, busy.set_result, (None,))
    start = time.monotonic()
    timer.start()
    assert policy.may_start("robot")
    assert busy.done() and time.monotonic() - start >= 0.15


# --------------------------------------------------------------------------- capture stamps

class FakeSim:
    """What Captures.stamp reads: the sim time, its step, and a stamp (SimTopics.now)."""

    def __init__(self) -> None:
        self.runtime = SimpleNamespace(time=1.0, steps=100)

    def now(self) -> float:
        return self.runtime.time


def _run(coroutine, sim: FakeSim, captures: Captures) -> float:
    """Drive ``coroutine`` as the executor would, stepping the sim whenever it waits."""
    while True:
        try:
            coroutine.send(None)
        except StopIteration as done:
            return done.value
        sim.runtime.time += 0.01
        sim.runtime.steps += 1
        captures.stepped()


def test_two_captures_at_one_sim_time_get_stamps_of_their_own():
    sim, granted = FakeSim(), []
    captures = Captures(sim, frames=None, grant_step=granted.append)     # type: ignore[arg-type]
    robot, other = _agent(), _agent("other", first=False)
    first = _run(captures.stamp(robot), sim, captures)
    assert first == 1.0 and granted == []            # a first stamp waits for nothing
    waiting = captures.stamp(robot)
    waiting.send(None)                               # sim time still stands at the last stamp: it waits
    assert captures.waiting == 1 and captures.in_flight == 1 and granted == [101]
    assert _run(captures.stamp(other), sim, captures) == 1.0     # another agent's stamps are its own
    second = _run(waiting, sim, captures)
    assert second > first and captures.in_flight == 0


# --------------------------------------------------------------------------- appearance budget

def test_one_appearance_change_per_batch():
    budget = AppearanceBudget()
    assert budget.busy() is None
    budget.changed([("robot", "camera")], 0.01)
    assert "requests came faster than it steps" in budget.busy()
    budget.new_batch()
    assert budget.busy() is None


def test_changes_that_cost_more_than_their_share_are_busy_until_paid_back(clock):
    budget = AppearanceBudget()
    budget.changed([("robot", "camera"), ("robot", "laser")], CHANGE_BURST_S + 0.3)
    budget.new_batch()
    assert "send this one again in 2.0 s" in budget.busy()       # 0.3 s over at 15 %
    clock.t += 2.1
    assert budget.busy() is None


def test_only_the_first_reading_after_a_change_is_charged_to_it(clock):
    budget = AppearanceBudget()
    budget.changed([("robot", "camera")], 0.0)
    budget.new_batch()
    budget.note_reading(("robot", "laser"), 5.0)                 # not a reading the change affects
    assert budget.busy() is None
    budget.note_reading(("robot", "camera"), CHANGE_BURST_S + 0.3)   # the light-map redo: the change's
    assert "send this one again" in budget.busy()
    clock.t += 100.0
    budget.note_reading(("robot", "camera"), 5.0)                # the next frames are the camera's own
    assert budget.busy() is None


# --------------------------------------------------------------------------- map -> odom ownership

def _map_odom(odom: str, x: float, sec: int = 1) -> TransformStamped:
    return convert.transform_2d(convert.header(sec, n.MAP_FRAME), odom, (x, 0.0, 0.0))


def test_the_sim_hands_map_odom_over_while_another_node_publishes_it(clock):
    said: list[str] = []
    robot, other = _agent(), _agent("other", first=False)
    ownership = MapOdomOwnership("auto", [robot, other], said.append)
    assert ownership.listens and ownership.owns(robot) and said == []
    own = _map_odom(n.ODOM_FRAME, 1.0)
    ownership.published(own)
    ownership.heard(TFMessage(transforms=[own]))                 # its own edge heard back: still the sim's
    assert ownership.owns(robot)
    ownership.heard(TFMessage(transforms=[_map_odom("/" + n.ODOM_FRAME, 1.5)]))     # slam_toolbox's
    assert not ownership.owns(robot) and not ownership.owns(robot)
    assert ownership.owns(other)                                 # another agent's odom frame is unaffected
    assert len(said) == 1 and "another node publishes" in said[0]
    clock.t += MAP_TF_RESUME_S + 0.1
    assert ownership.owns(robot) and "publishes its ground truth on /tf again" in said[-1] and len(said) == 2


@pytest.mark.parametrize("mode, owns", [("on", True), ("off", False)])
def test_a_fixed_map_tf_mode_does_not_listen(mode, owns):
    ownership = MapOdomOwnership(mode, [_agent()], lambda _text: None)
    ownership.heard(TFMessage(transforms=[_map_odom(n.ODOM_FRAME, 1.0)]))
    assert not ownership.listens and ownership.owns(_agent()) is owns


# --------------------------------------------------------------------------- command watchdog

class Robot:
    def __init__(self) -> None:
        self.commands: list[tuple[float, float]] = []

    def set_command(self, v: float, w: float) -> None:
        self.commands.append((v, w))


def test_a_robot_whose_commands_stop_is_stopped_once():
    watchdog = CommandWatchdog()
    robot, idle = SimpleNamespace(name="robot", robot=Robot()), SimpleNamespace(name="idle", robot=Robot())
    watchdog.commanded(robot, 10.0)
    watchdog.check([robot, idle], 10.0 + CMD_TIMEOUT_S)          # not yet older than the timeout
    assert robot.robot.commands == []
    watchdog.check([robot, idle], 10.0 + CMD_TIMEOUT_S + 0.01)
    watchdog.check([robot, idle], 20.0)
    assert robot.robot.commands == [(0.0, 0.0)] and idle.robot.commands == []
