"""The ROS-free runtime and the message conversions the node uses."""
from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from ravh_msgs_py import appearance
from ravh_msgs_py.query import QueryError
from ravh_sim.errors import UserError
from ravh_sim.runtime import Schedule, SimRuntime
from ravh_sim.sensors.camera import OPTICAL_ROTATION


@pytest.fixture(scope="module")
def runtime():
    rt = SimRuntime(20, renderer="tiny")
    yield rt
    rt.close()


def test_sensors_fall_due_at_their_rates(runtime):
    agent = runtime.agents[0]
    counts = {"camera": 0, "scan": 0, "odom": 0}
    start = runtime.time
    while runtime.time < start + 2.0:
        runtime.step()
        for what in counts:
            counts[what] += runtime.due(agent, what)
    assert counts == {"camera": pytest.approx(20, abs=1), "scan": pytest.approx(20, abs=1),
                      "odom": pytest.approx(100, abs=1)}


def _float_schedule(rate: float, physics_hz: float, steps: int) -> list[int]:
    """The steps readings fell due at before step counters: float sim time with a tolerance, asked
    after each step as the sim node does (the reference the schedule must keep)."""
    period, next_due, due = 1.0 / rate, 0.0, []
    for step in range(1, steps + 1):
        t = step * (1.0 / physics_hz)
        if t + 1e-9 >= next_due:
            due.append(step)
            next_due = max(next_due + period, t + period * 0.5)
    return due


@pytest.mark.parametrize("rate", [30.0, 10.0, 50.0, 100.0, 120.0, 7.0, 7.3, 29.97, 3.0, 0.7])
def test_step_schedules_keep_the_float_schedule(rate):
    """Rates that divide the physics rate and rates that do not (100 Hz: 2.4 steps; 7.3 Hz, 29.97 Hz)
    fall due at the steps they did when sim time was a float, over ten simulated minutes."""
    physics_hz, steps = 240.0, 240 * 600
    schedule = Schedule.every(rate, physics_hz)
    assert [step for step in range(1, steps + 1) if schedule.due(step)] == _float_schedule(rate, physics_hz, steps)


def test_a_step_schedule_counts_whole_steps():
    camera, clock, never = (Schedule.every(rate, 240.0) for rate in (30.0, 100.0, 0.0))
    assert [step for step in range(1, 50) if camera.due(step)] == [1, 8, 16, 24, 32, 40, 48]
    assert [step for step in range(1, 20) if clock.due(step)] == [1, 3, 5, 8, 10, 12, 15, 17]
    assert not any(never.due(step) for step in range(1000))
    late = Schedule.every(30.0, 240.0)
    assert [step for step in (1, 20, 23, 24, 30, 32) if late.due(step)] == [1, 20, 24, 32]   # none made up


def test_a_frame_not_taken_still_uses_up_its_number(runtime):
    """Lazy sensors skip frames nobody listens to; with camera noise on, a later capture must be the
    bytes it would have been had every frame been rendered."""
    agent = runtime.agents[0]
    camera = agent.sensors["camera"]
    options, start = camera.options, camera.count
    camera.options = replace(options, pixel_noise=8.0)
    try:
        eager = [runtime.capture(agent) for _ in range(3)]
        camera.count = start
        runtime.skip(agent, "camera")
        runtime.skip(agent, "camera")
        lazy = runtime.frame_later(agent)()
        assert lazy.index == eager[2].index == start + 2
        assert np.array_equal(lazy.rgb, eager[2].rgb) and not np.array_equal(eager[1].rgb, eager[2].rgb)
    finally:
        camera.options = options


def test_a_frame_asked_for_shows_the_pose_it_was_asked_at(runtime):
    agent = runtime.agents[0]
    before = agent.robot.pose
    frame = runtime.frame_later(agent)
    agent.robot.teleport(before[0], before[1], before[2] + 1.0)
    try:
        assert frame().robot_pose == before
    finally:
        runtime.reset()


def test_commands_are_validated(runtime):
    agent = runtime.agents[0]
    for v, w in ((math.nan, 0.0), (0.0, math.inf), (1e6, 0.0), (0.0, -1e3)):
        with pytest.raises(UserError, match="rejected"):
            runtime.command(agent, v, w)
    runtime.command(agent, 0.1, 0.0)
    assert agent.robot.command == pytest.approx((0.1, 0.0))
    runtime.command(agent, 0.0, 0.0)


def _matrix(pose) -> np.ndarray:
    x, y, yaw = pose
    return np.array([[math.cos(yaw), -math.sin(yaw), x], [math.sin(yaw), math.cos(yaw), y], [0.0, 0.0, 1.0]])


def test_map_to_odom_follows_the_odometry_drift_to_the_true_pose(runtime):
    """Odometry drifts (the profile's 6 cm/m, 1°/rad), so map -> odom must move by that drift: applied to
    the odometry it gives the true pose. Checked with homogeneous matrices, not with poses.compose."""
    agent = runtime.agents[0]
    runtime.step()
    m0, odom0, true0 = runtime.map_to_odom(agent), agent.robot.odometry, agent.robot.pose
    assert np.allclose(_matrix(m0) @ _matrix(odom0), _matrix(true0), atol=1e-9)
    runtime.command(agent, 0.2, 0.3)
    runtime.step(480)
    runtime.command(agent, 0.0, 0.0)
    m1, odom1, true1 = runtime.map_to_odom(agent), agent.robot.odometry, agent.robot.pose
    true_motion = np.linalg.inv(_matrix(true0)) @ _matrix(true1)
    odom_motion = np.linalg.inv(_matrix(odom0)) @ _matrix(odom1)
    assert np.abs(true_motion[:2, 2]).max() > 0.01                     # the robot drove
    assert not np.allclose(true_motion, odom_motion, atol=1e-4)        # and its odometry drifted
    assert np.allclose(_matrix(m1) @ _matrix(odom1), _matrix(true1), atol=1e-9)
    assert 1e-5 < math.dist(m1[:2], m0[:2]) < 0.2


def test_optical_frame_rotation_is_rep103():
    # camera_link x (forward) must become optical z; camera_link -y (right) optical x; -z (down) optical y
    x, y, z, w = OPTICAL_ROTATION
    rot = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                    [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                    [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    assert rot @ [0, 0, 1] == pytest.approx([1, 0, 0])            # optical z = link x
    assert rot @ [1, 0, 0] == pytest.approx([0, -1, 0])           # optical x = link -y
    assert rot @ [0, 1, 0] == pytest.approx([0, 0, -1])           # optical y = link -z


def test_appearance_requests_change_only_what_they_name(runtime):
    before = runtime.world.state.settings().model_dump(mode="json")
    reply = runtime.change_appearance({"doors": {"Door_1": "closed"}, "lights": {"ceiling": "off"}})
    assert reply["ok"], reply
    after = runtime.world.state
    assert after.doors["Door_1"] is False and not any(after.lights[lt.id] for lt in runtime.house.lights
                                                       if lt.kind == "ceiling")
    assert after.paint == before["paint"] and after.models == before["models"]
    assert runtime.map_version >= 1
    runtime.reset()
    assert runtime.world.state.settings().model_dump(mode="json") == runtime.initial.model_dump(mode="json")


def test_the_map_version_moves_with_doors_and_models_only(runtime):
    """The node republishes /map when the map version moves: not for paint, sun or lights."""
    before = runtime.map_version
    reply = runtime.change_appearance({"paint": {"all": {"walls": "brick"}}, "sun_angle": "night",
                                       "lights": {"all": "on"}})
    assert reply["ok"], reply
    assert runtime.map_version == before
    is_open = runtime.world.state.doors["Door_1"]
    assert runtime.change_appearance({"doors": {"Door_1": not is_open}})["ok"]
    assert runtime.map_version > before
    runtime.reset()


@pytest.mark.parametrize("request_, code", [
    ("{", "bad_json"), ({}, "bad_request"), ({"sun": 3}, "bad_request"), ({"sun_angle": 999}, "bad_request"),
    ({"doors": {"Door_42": "open"}}, "unknown_id"), ({"lights": {"Light_0": "dim"}}, "bad_request"),
    ({"paint": {"Bedroom_1": {"walls": "plaid"}}}, "bad_request"), ({"models": {"Bed_0": 99}}, "bad_request"),
])
def test_bad_appearance_requests_get_structured_errors(runtime, request_, code):
    before = runtime.world.state.settings().model_dump(mode="json")
    reply = runtime.change_appearance(request_)
    assert reply["ok"] is False and reply["error"]["code"] == code
    assert runtime.world.state.settings().model_dump(mode="json") == before                 # nothing half-applied


def test_appearance_syntax_is_checked_offline():
    assert appearance.parse('{"sun_angle": "night", "seed": 3}')["seed"] == 3
    with pytest.raises(QueryError):
        appearance.parse('{"models": {"Bed_0": -1}}')


def test_a_footprint_rebuilds_the_same_world(runtime, tmp_path):
    from ravh_sim.world.footprint import dump_footprint, write_footprint
    runtime.change_appearance({"models": {"Bed_0": 2}, "paint": {"Bedroom_1": {"walls": "brick"}}})
    path = tmp_path / "fp.json"
    write_footprint(runtime.footprint(), path)
    again = SimRuntime(1, footprint=path, renderer="tiny")
    try:
        assert again.house.number == 20
        assert dump_footprint(again.footprint()) == dump_footprint(runtime.footprint())
        a, b = runtime.agents[0], again.agents[0]
        pose = (-2.0, 1.0, 0.3)
        a.robot.teleport(*pose)
        b.robot.teleport(*pose)
        assert np.array_equal(runtime.scan(a).ranges, again.scan(b).ranges)
        ca, cb = runtime.capture(a), again.capture(b)
        while cb.index < ca.index:            # the sensor's noise is seeded per capture number
            cb = again.capture(b)
        assert cb.index == ca.index
        assert np.array_equal(ca.instance, cb.instance) and np.array_equal(ca.rgb, cb.rgb)
    finally:
        again.close()
        runtime.reset()


def test_profile_camera_effects_are_validated(tmp_path):
    import yaml

    from ravh_sim.errors import FileFieldError
    from ravh_sim.paths import ROBOTS_DIR
    from ravh_sim.robot.profile import load_profile
    data = yaml.safe_load((ROBOTS_DIR / "giraff.yaml").read_text())
    data["camera"]["effects"] = {"pixel_noise": 3.0, "distortion": [-0.1, 0.01, 0.0, 0.0, 0.0]}
    good = tmp_path / "noisy.yaml"
    good.write_text(yaml.safe_dump(data))
    effects = dict(load_profile(good).camera.effects)
    assert effects["pixel_noise"] == 3.0 and effects["distortion"] == (-0.1, 0.01, 0.0, 0.0, 0.0)
    data["camera"]["effects"] = {"pixel_noise": None, "distortion": None}      # null: the camera's default
    good.write_text(yaml.safe_dump(data))
    assert dict(load_profile(good).camera.effects) == {}
    data["camera"]["effects"] = {"distortion": [0.0, 0.0, 0.0, 0.0, 99.0]}
    good.write_text(yaml.safe_dump(data))
    with pytest.raises(FileFieldError, match="camera.effects.distortion"):
        load_profile(good)
    data["camera"]["effects"] = {"sparkle": 1}
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    with pytest.raises(FileFieldError, match="camera.effects.sparkle"):
        load_profile(bad)


# ------------------------------------------------------------------ requests with extreme numbers
# The core checks every number a request carries before numpy or the planner see it (issue 13, item 4):
# a bad request is a structured bad_request (never internal) that does not quote a huge input back.

EXTREMES = [1e308, -1e308, math.nan, math.inf, -math.inf, 5e-324, -0.0, 10**400, -(10**30), 2**63]
HUGE = "x" * 10_000_000


@pytest.mark.parametrize("x", EXTREMES)
def test_plans_to_extreme_points_are_refused(runtime, x):
    """Every extreme is far outside house 20 (or not a number, or 5e-324/-0.0 at the origin, which is
    outside its free space too): each plan is refused with one line."""
    for start, goal in (((x, 0.0), (0.0, 0.0)), ((-3.0, 1.6), (x, x))):
        with pytest.raises(UserError) as refused:
            runtime.plan(start, goal)
        assert "\n" not in str(refused.value)


@pytest.mark.parametrize("x", EXTREMES)
def test_queries_with_extreme_numbers_are_bad_requests(runtime, x):
    import json
    reply = runtime.query(json.dumps({"query": "room_at", "x": x, "y": 0.0}))
    assert reply["ok"] == (abs(x) < 1e6), reply
    if not reply["ok"]:
        assert reply["error"]["code"] == "bad_request"


@pytest.mark.parametrize("request_", [
    '{"query": {"a": 1}}', '{"query": [1]}', '{"query": "room", "id": 7}', '{"query": "room", "id": [1]}',
    '{"query": "rooms", "type": {"x": 1}}', '{"query": "room_at", "x": "1", "y": 2}', "[1, 2]", "7",
])
def test_wrong_typed_queries_are_bad_requests(runtime, request_):
    assert runtime.query(request_)["error"]["code"] in ("bad_request", "unknown_query")


@pytest.mark.parametrize("request_", [
    HUGE, '{"query": "' + HUGE + '"}', '{"query": "room", "id": "' + HUGE + '"}',
    '{"sun_angle": "' + HUGE + '"}', '{"doors": {"' + HUGE + '": "open"}}', "[" * 60_000,
])
def test_huge_requests_are_refused_without_echo(runtime, request_):
    for reply in (runtime.query(request_), runtime.change_appearance(request_)):
        assert not reply["ok"] and reply["error"]["code"] != "internal"
        assert len(json.dumps(reply)) < 2_000


@pytest.mark.parametrize("key, value", [("seed", -5), ("seed", 10**30), ("randomise", 2**40), ("seed", 1.5),
                                        ("sun_angle", 1e308), ("sun_angle", math.nan), ("models", {"Bed_0": 10**400})])
def test_appearance_numbers_are_checked(runtime, key, value):
    reply = runtime.change_appearance(json.dumps({key: value}))
    assert reply["error"]["code"] in ("bad_request", "unknown_id"), reply


# ------------------------------------------------------------------ GetPlan frames (issue 24)

def test_points_in_odom_and_agent_frames_are_transformed_into_map(runtime):
    agent = runtime.agents[0]
    runtime.command(agent, 0.3, 0.4)
    runtime.step(600)                                           # odometry drifts away from the truth
    runtime.command(agent, 0.0, 0.0)
    x, y, yaw = agent.robot.pose
    ox, oy, _ = agent.robot.odometry
    assert runtime.to_map("odom", ox, oy) == pytest.approx((x, y), abs=1e-9)  # odom -> base_link is odometry
    assert runtime.to_map("base_link", 0.0, 0.0) == pytest.approx((x, y), abs=1e-9)
    assert runtime.to_map("/base_link", 1.0, 0.0) == pytest.approx((x + math.cos(yaw), y + math.sin(yaw)))
    assert runtime.to_map("map", 2.5, -1.0) == runtime.to_map("", 2.5, -1.0) == (2.5, -1.0)
    # 1 m along the optical axis: ahead of the camera (pitched down a little), whatever the mount height
    cx, cy = runtime.to_map("camera_optical_frame", 0.0, 0.0, 1.0)
    ahead = (cx - x) * math.cos(yaw) + (cy - y) * math.sin(yaw)
    assert 0.9 < ahead < 1.1 and abs((cy - y) * math.cos(yaw) - (cx - x) * math.sin(yaw)) < 1e-6
    assert runtime.to_map("laser_link", 0.5, 0.0) == pytest.approx(runtime.to_map("base_link", 0.5, 0.0))


@pytest.mark.parametrize("frame", ["kitchen", "robot2/odom", "odom_combined", "world"])
def test_unknown_frames_are_refused_with_the_known_ones(runtime, frame):
    with pytest.raises(UserError, match=f"unknown frame '{frame}'; known: map, odom, base_link"):
        runtime.to_map(frame, 0.0, 0.0)
    with pytest.raises(UserError, match="rejected goal: unknown frame"):
        runtime.plan((-3.0, 1.6), (-2.0, 1.6), ("map", frame))


def test_a_plan_from_the_robot_in_base_link_starts_where_the_robot_is(runtime):
    agent = runtime.agents[0]
    x, y, _ = agent.robot.pose
    goal = runtime.to_map("base_link", 0.0, 0.0)
    in_map = runtime.plan((x, y), (-3.0, 1.6))
    in_base = runtime.plan((0.0, 0.0, 0.0), (-3.0, 1.6, 0.0), ("base_link", "map"))
    ox, oy, _ = agent.robot.odometry
    in_odom = runtime.plan((ox, oy), (-3.0, 1.6), ("odom", "map"))
    assert in_base.points == in_map.points == in_odom.points and goal == pytest.approx((x, y))


def test_an_appearance_request_is_refused_as_busy_only_once_it_reads_well(runtime):
    asked = []

    def busy() -> str:
        asked.append(1)
        return "the sim is busy"

    bad = runtime.appearance_refusal({"doors": {"Door_99": "open"}}, busy)
    assert bad["error"]["code"] == "unknown_id" and "Door_0" in bad["error"]["valid"] and not asked
    assert runtime.appearance_refusal("{not json", busy)["error"]["code"] == "bad_json" and not asked
    refused = runtime.appearance_refusal({"sun_angle": "night"}, busy)
    assert refused == {"ok": False, "error": {"code": "busy", "message": "the sim is busy"}} and asked
    assert runtime.appearance_refusal({"sun_angle": "night"}, lambda: None) is None
