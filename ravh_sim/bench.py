"""Benchmarks printed as JSON: absolute times plus ratios against a baseline taken in the same run.

Timed tests are flaky on a shared 2-core machine; ratios measured side by side are not. Each
``bench_*`` function returns a flat dict; ``ravh bench WHAT --json`` prints it.
"""
from __future__ import annotations

import math
import os
import statistics
import tempfile
import time
from collections.abc import Callable
from typing import Any

LOAD_TARGET_S = 2.0
TRIANGLE_TARGET_HOUSE23 = 60_000
FREE_SPACE_TARGET_S = 1.0
PLAN_TARGET_S = 0.1
STEP_TARGET_S = 0.001
NAV_HOUSE = 23
STEP_SAMPLES = 2400             # physics steps timed (10 s of simulated time at 240 Hz)


BENCHES = ("load", "nav", "sensors", "node", "raid")


def run(what: str, houses: list[int] | None = None) -> dict[str, Any]:
    from ravh_sim import bench_ros
    benches: dict[str, Callable[..., dict[str, Any]]] = {"load": bench_load, "nav": bench_nav,
                                                          "sensors": bench_sensors,
                                                          "node": bench_ros.bench_node,
                                                          "raid": bench_raid}
    return benches[what](houses=houses)


def _timed(fn: Callable[..., Any], *args: Any) -> tuple[float, Any]:
    t0 = time.perf_counter()
    value = fn(*args)
    return time.perf_counter() - t0, value


def bench_load(houses: list[int] | None = None) -> dict[str, Any]:
    """Build time (house file to a ready pybullet world) and triangle count per house.

    Baselines: the same build with an empty asset cache (first run on a machine), and a bare pybullet
    client with the renderer loaded (the fixed cost every build pays).
    """
    from ravh_sim.world.house import available_houses, load_house
    from ravh_sim.world.scene import World
    from ravh_sim.world.settings import load_settings, resolve

    settings = load_settings()
    numbers = houses or available_houses()

    def build(n: int) -> tuple[float, int]:
        def make() -> int:
            house = load_house(n)
            world = World(house, resolve(settings, house))
            tris = world.triangle_count
            world.close()
            return tris
        return _timed(make)

    build(numbers[0])                                   # warm the asset cache and imports
    per_house = {}
    for n in numbers:
        seconds, tris = build(n)
        per_house[str(n)] = {"build_s": round(seconds, 3), "triangles": tris}

    empty_s, _ = _timed(_bare_client)
    with tempfile.TemporaryDirectory() as tmp:
        old = os.environ.get("RAVH_CACHE")
        os.environ["RAVH_CACHE"] = tmp
        cold_house = 15 if 15 in numbers else numbers[0]       # the main job's house where measured
        try:
            cold_s, _ = build(cold_house)
        finally:
            if old is None:
                del os.environ["RAVH_CACHE"]
            else:
                os.environ["RAVH_CACHE"] = old
    times = [v["build_s"] for v in per_house.values()]
    warm = per_house[str(cold_house)]["build_s"]
    return {
        "houses": per_house,
        "build_s_max": max(times), "build_s_median": round(statistics.median(times), 3),
        "build_s_target": LOAD_TARGET_S, "max_over_target": round(max(times) / LOAD_TARGET_S, 3),
        "bare_client_s": round(empty_s, 3),
        "cold_cache_house": cold_house,
        "cold_cache_build_s": round(cold_s, 3),
        "cold_over_warm": round(cold_s / warm, 2),
        "triangles_house23": per_house.get("23", {}).get("triangles"),
        "triangles_target_house23": TRIANGLE_TARGET_HOUSE23,
    }


def _bare_client() -> None:
    from ravh_sim.world.scene import connect, disconnect
    disconnect(connect())


def bench_nav(houses: list[int] | None = None) -> dict[str, Any]:
    """Navigation and physics speed.

    * free-space map per house (target < 1 s each), against rasterising the obstacles alone;
    * a cross-house plan in house 23, station to the farthest room (target < 100 ms), against a
      plan along the first straight stretch of the same path;
    * one physics step with the robot driving in circles (target < 1 ms), against a step of the
      same house with no robot;
    * the real-time factor of that cross-house drive with the path follower and no sensors
      (simulated seconds per wall second), against stepping the same house with no robot.
    """
    from ravh_sim.nav.follower import PathFollower, drive
    from ravh_sim.nav.freespace import free_space, obstacles
    from ravh_sim.nav.navigation import Navigation
    from ravh_sim.nav.planner import plan_path
    from ravh_sim.robot.profile import load_profile
    from ravh_sim.robot.simulation import Simulation
    from ravh_sim.world.house import available_houses, load_house
    from ravh_sim.world.scene import World
    from ravh_sim.world.settings import load_settings, resolve

    settings = load_settings()
    profile = load_profile()
    per_house = {}
    for n in houses or available_houses():
        house = load_house(n)
        resolved = resolve(settings, house)
        raster_s, _ = _timed(obstacles, house, resolved.doors, resolved.models, profile.height)
        map_s, _ = _timed(free_space, house, resolved.doors, resolved.models, profile.radius, profile.height)
        per_house[str(n)] = {"free_space_s": round(map_s, 4), "obstacles_only_s": round(raster_s, 4)}
    map_times = [v["free_space_s"] for v in per_house.values()]

    house = load_house(NAV_HOUSE)
    world = World(house, resolve(settings, house))
    try:
        empty = Simulation(world, agents=[])
        empty_step_s = _timed(lambda: empty.step(STEP_SAMPLES))[0] / STEP_SAMPLES
        sim = Simulation(world)
        robot = next(iter(sim.robots.values()))
        navigation = Navigation(house, world.state, robot.profile)
        grid = navigation.map()
        start, goal = robot.pose[:2], _farthest_goal(navigation, robot.pose[:2])
        plan_s, path = _best_of(3, lambda: plan_path(grid, start, goal, house=house))
        straight_s, _ = _best_of(3, lambda: plan_path(grid, start, path.points[1], house=house))
        follower = PathFollower(robot, navigation, robot.profile)
        follower.navigate_to(goal)
        t0 = sim.time
        timeout = 4 * path.length / profile.max_linear_speed
        drive_s, status = _timed(lambda: drive(sim, follower, timeout))
        drive_sim_s = sim.time - t0
        robot.teleport(*goal, 0.0)             # the roomiest spot: circles there touch nothing
        robot.set_command(profile.max_linear_speed, profile.max_angular_speed)
        step_s = _timed(lambda: sim.step(STEP_SAMPLES))[0] / STEP_SAMPLES
    finally:
        world.close()
    empty_rtf = 1.0 / (empty_step_s * world.physics_hz)
    drive_rtf = drive_sim_s / drive_s
    return {
        "houses": per_house,
        "free_space_s_max": max(map_times), "free_space_s_median": round(statistics.median(map_times), 4),
        "free_space_target_s": FREE_SPACE_TARGET_S,
        "free_space_max_over_target": round(max(map_times) / FREE_SPACE_TARGET_S, 3),
        "free_space_over_obstacles_only_median": round(statistics.median(
            v["free_space_s"] / v["obstacles_only_s"] for v in per_house.values()), 2),
        f"plan_s_house{NAV_HOUSE}": round(plan_s, 4),
        f"plan_length_m_house{NAV_HOUSE}": round(path.length, 2),
        "plan_target_s": PLAN_TARGET_S, "plan_over_target": round(plan_s / PLAN_TARGET_S, 3),
        "straight_plan_s": round(straight_s, 4), "plan_over_straight_plan": round(plan_s / straight_s, 2),
        "step_with_robot_s": round(step_s, 7), "step_empty_s": round(empty_step_s, 7),
        "step_target_s": STEP_TARGET_S, "step_over_target": round(step_s / STEP_TARGET_S, 3),
        "step_with_robot_over_empty": round(step_s / empty_step_s, 2),
        "drive_status": status.value, "drive_sim_s": round(drive_sim_s, 1), "drive_wall_s": round(drive_s, 2),
        "drive_real_time_factor": round(drive_rtf, 1), "empty_world_real_time_factor": round(empty_rtf, 1),
        "drive_over_empty_world": round(drive_rtf / empty_rtf, 2),
    }


def _best_of(n: int, fn: Callable[[], Any]) -> tuple[float, Any]:
    """The least time of ``n`` runs (the others are noise from the machine) and the value."""
    runs = [_timed(fn) for _ in range(n)]
    return min(t for t, _ in runs), runs[0][1]


def _farthest_goal(navigation: Any, start: tuple[float, float]) -> tuple[float, float]:
    """The goal of the room whose path from ``start`` is longest."""
    from ravh_sim.nav.planner import Unreachable

    best = (-1.0, start)
    for room in navigation.house.rooms:
        try:
            goal = navigation.room_goal(room.id, start)
            best = max(best, (navigation.plan(start, goal).length, goal))
        except Unreachable:
            continue
    return best[1]


SENSOR_HOUSES = (15, 23)
CAMERA_TARGET_MS = 55.0             # realistic; the paper's camera took 55.54 ms on a laptop GPU
FAST_TARGET_MS = 30.0
SCAN_TARGET_MS = 2.0
SENSOR_REPEATS = 3


ROUTE_STEP_M = 1.0                  # a frame every metre along the route


def route_poses(world: Any, profile: Any, step: float = ROUTE_STEP_M) -> list[tuple[float, float, float]]:
    """Poses along the route ``ravh bench node`` drives (the wanderer, ``--order cyclic``: from the
    station to every room in house order), one every ``step`` metres, heading along the path."""
    from ravh_sim.nav.navigation import Navigation
    from ravh_sim.nav.planner import Unreachable

    house = world.house
    navigation = Navigation(house, world.state, profile)
    at = house.station.position[:2]
    poses = [(at[0], at[1], house.station.yaw)]
    for room in house.rooms:
        try:
            points = navigation.plan(at, navigation.room_goal(room.id, at)).points
        except Unreachable:
            continue
        for (x0, y0), (x1, y1) in zip(points, points[1:]):
            length, yaw = math.dist((x0, y0), (x1, y1)), math.atan2(y1 - y0, x1 - x0)
            poses += [(x0 + (x1 - x0) * d / length, y0 + (y1 - y0) * d / length, yaw)
                      for d in [i * step for i in range(int(length / step))] if length > 0]
        at = points[-1]
    return poses


def bench_sensors(houses: list[int] | None = None) -> dict[str, Any]:
    """Sensor speed: one camera capture (RGB + depth + instance, 640x480) as the sim publishes it with
    each camera profile: realistic (the giraff profile: the realistic GL renderer and its sensor
    model), fast (giraff_fast: fast GL, no sensor) and pybullet's TinyRenderer (the baseline, its
    frames developed through the same sensor in numpy), on the same poses in the same run, and their
    ratios; realistic at night with every light on (its worst case); the realistic ideal camera
    (giraff_ideal: no sensor model); one 360-ray laser scan.

    Poses: the station and every room centre that lies inside its room, headings turning by 90
    degrees, default settings (day, ceiling lights on), the robot still; and, as ``route_*``, frames
    every metre along the route ``ravh bench node`` drives, the robot moving at its cruise speed (its
    sensor blurs them). Medians over all poses and repeats.
    """
    from dataclasses import replace

    from ravh_msgs_py import names
    from ravh_sim.render.backend import resolve_backend
    from ravh_sim.robot.profile import load_profile
    from ravh_sim.sensors.camera import PORT
    from ravh_sim.sensors.laser import Laser
    from ravh_sim.world.appearance import Appearance
    from ravh_sim.world.geometry import polygon_centroid
    from ravh_sim.world.house import load_house
    from ravh_sim.world.scene import World
    from ravh_sim.world.settings import load_settings, resolve

    settings = load_settings()
    profile = load_profile()
    detail: dict[str, Any] = {}
    sensor = profile.camera.sensor           # the giraff profile's; giraff_fast and giraff_ideal have none
    configs = {"realistic": ("gl", "realistic", sensor), "fast": ("gl", "fast", None),
               "tiny": ("tiny", "fast", sensor), "realistic_night_all_lights": ("gl", "realistic", sensor),
               "realistic_ideal": ("gl", "realistic", None)}
    camera_ms: dict[str, list[float]] = {name: [] for name in configs}
    route_ms: dict[str, list[float]] = {name: [] for name in configs}
    scan_ms: list[float] = []
    for n in houses or SENSOR_HOUSES:
        house = load_house(n)
        poses = [(house.station.position[0], house.station.position[1], house.station.yaw)]
        for i, room in enumerate(house.rooms):
            cx, cy = polygon_centroid(room.floor)
            if room.contains(cx, cy):
                poses.append((cx, cy, i * math.pi / 2))
        for name, (backend, quality, with_sensor) in configs.items():
            if resolve_backend(backend) != backend:
                continue
            world = World(house, resolve(settings, house))
            if name.endswith("night_all_lights"):
                appearance = Appearance(world)
                appearance.set_knob("sun_angle", "night")
                appearance.set_lights("all", "on")
            spec = replace(profile.camera, quality=quality, sensor=with_sensor)
            camera = PORT.build(world, spec, names.DEFAULT_AGENT, backend)
            camera.capture(*poses[0])                         # shadow maps and buffers are made once
            times = [_timed(camera.capture, *pose)[0] * 1000
                     for _ in range(SENSOR_REPEATS) for pose in poses]
            camera_ms[name] += times
            detail[f"house{n}_camera_ms_{name}"] = round(statistics.median(times), 2)
            route, cruise = route_poses(world, profile), (profile.max_linear_speed, 0.0)
            route_ms[name] += [_timed(camera.capture, *pose, None, cruise)[0] * 1000 for pose in route]
            detail[f"house{n}_route_frames"] = len(route)
            if name == "tiny":
                laser = Laser(world, profile.laser)
                scan_ms += [_timed(laser.scan, *pose)[0] * 1000
                            for _ in range(SENSOR_REPEATS * 5) for pose in poses]
            camera.close()
            world.close()
    medians = {name: round(statistics.median(ms), 2) if ms else None for name, ms in camera_ms.items()}
    on_route = {name: round(statistics.median(ms), 2) if ms else None for name, ms in route_ms.items()}
    tiny = medians["tiny"]
    return {
        **{f"camera_ms_{name}": ms for name, ms in medians.items()},
        **{f"route_camera_ms_{name}": ms for name, ms in on_route.items()},
        "route_speedup_realistic_vs_tiny": _ratio(on_route["tiny"], on_route["realistic"]),
        "speedup_realistic_vs_tiny": _ratio(tiny, medians["realistic"]),
        "speedup_fast_vs_tiny": _ratio(tiny, medians["fast"]),
        "scan_ms": round(statistics.median(scan_ms), 3) if scan_ms else None,
        "camera_ms_target_realistic": CAMERA_TARGET_MS, "camera_ms_target_fast": FAST_TARGET_MS,
        "scan_ms_target": SCAN_TARGET_MS, "image": [profile.camera.width, profile.camera.height_px],
        "laser_rays": profile.laser.ray_count, **detail,
    }


def _ratio(baseline: float | None, value: float | None) -> float | None:
    return round(baseline / value, 2) if baseline and value else None


RAID_HOUSE = 20
RAID_RATIO_TARGET = 4.0
DATASET_HOURS_TARGET = 2.0


def bench_raid(houses: list[int] | None = None) -> dict[str, Any]:
    """Raid speed, direct engine against the ROS engine, and what the whole dataset would take.

    * House 20, raid 1 (wanderer, day): captures per wall second and per CPU second (all threads
      and processes of the engine: the measure that holds on a loaded machine) with the direct
      engine (one process) and the ROS engine (``ravh raid --fast``: three processes over DDS), same
      preset and seed, one after the other in this run; their ratios (target >= 4). The same raid
      again at the dataset camera quality (the library's finer level): its rate and the ratio.
    * The paper's 113K captures (Table 2) at the sample's captures per CPU second, on this machine's
      cores, at both qualities (the dataset quality's cost as measured on house 20).
    * The whole 150-raid dataset: every raid (0-4) of each sample house (``--houses``, default 20)
      with the direct engine, one at a time; CPU seconds per square metre of floor, times the floor
      area of all 30 houses (raid length grows with the area: grid nodes cover the free floor, the
      wanderer walks room to room), divided by 1, this machine's cores, 8 and 64 (raids are
      independent single-process jobs: 150 of them keep 64 cores busy).
    """
    import resource
    from pathlib import Path

    from ravh_sim.paper import table2
    from ravh_sim.raids.build import BuildOptions, Job, raid_seed, run_job
    from ravh_sim.raids.raid import PRESETS, run_raid
    from ravh_sim.world.house import available_houses, load_house

    def floor_area(n: int) -> float:
        return sum(room.area for room in load_house(n).rooms)

    def children_cpu() -> float:
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        return usage.ru_utime + usage.ru_stime

    sample = houses or [RAID_HOUSE]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        direct = {(h, r): run_job(Job(h, r, raid_seed(h, r, None)), root / "direct", BuildOptions())
                  for h in sorted(set(sample) | {RAID_HOUSE}) for r in range(len(PRESETS))
                  if h in sample or r == 1}
        finer = run_job(Job(RAID_HOUSE, 1, raid_seed(RAID_HOUSE, 1, None)), root / "dataset_quality",
                        BuildOptions(quality="dataset"))
        cpu0 = children_cpu()
        ros = run_raid(RAID_HOUSE, 1, root / "ros", fast=True, seed=raid_seed(RAID_HOUSE, 1, None), quiet=True)
        ros_cpu = children_cpu() - cpu0
    ours = direct[(RAID_HOUSE, 1)]
    rates = {"direct_captures_per_s": ours["captures"] / ours["wall_s"],
             "direct_captures_per_cpu_s": ours["captures"] / ours["cpu_s"],
             "ros_captures_per_s": ros["captures"] / ros["wall_s"] if ros["wall_s"] else math.nan,
             "ros_captures_per_cpu_s": ros["captures"] / ros_cpu if ros_cpu else math.nan,
             "dataset_quality_captures_per_cpu_s": finer["captures"] / finer["cpu_s"]}
    sampled = [s for (h, _), s in direct.items() if h in sample]
    sample_area = sum(floor_area(h) for h in sample)
    total_area = sum(floor_area(n) for n in available_houses())
    cpu_hours = sum(s["cpu_s"] for s in sampled) * total_area / sample_area / 3600
    cores = os.cpu_count() or 1
    sample_rate = sum(s["captures"] for s in sampled) / sum(s["cpu_s"] for s in sampled)
    paper_captures = sum(sum(raids.values()) for raids in table2().values())
    finer_cost = rates["direct_captures_per_cpu_s"] / rates["dataset_quality_captures_per_cpu_s"]
    return {
        "house": RAID_HOUSE, "raid": 1, "load_average_1min": round(os.getloadavg()[0], 1),
        "direct_captures": ours["captures"], "direct_wall_s": ours["wall_s"], "direct_cpu_s": ours["cpu_s"],
        "ros_status": ros["status"], "ros_captures": ros["captures"], "ros_wall_s": ros["wall_s"],
        "ros_cpu_s": round(ros_cpu, 1),
        **{k: round(v, 2) for k, v in rates.items()},
        "direct_over_ros_wall": round(rates["direct_captures_per_s"] / rates["ros_captures_per_s"], 2),
        "direct_over_ros_cpu": round(rates["direct_captures_per_cpu_s"] / rates["ros_captures_per_cpu_s"], 2),
        "direct_over_ros_target": RAID_RATIO_TARGET,
        "dataset_quality_captures": finer["captures"], "dataset_quality_cpu_s": finer["cpu_s"],
        "realistic_over_dataset_quality_cpu": round(finer_cost, 2),
        "sample_houses": sample,
        "sample_raids": {f"house{h}_raid{r}": {k: s[k] for k in ("status", "captures", "wall_s", "cpu_s")}
                         for (h, r), s in direct.items() if h in sample},
        "sample_captures_per_cpu_s": round(sample_rate, 2),
        "floor_m2_sample": round(sample_area, 1), "floor_m2_all_houses": round(total_area, 1),
        "dataset_captures_estimate": round(sum(s["captures"] for s in sampled) * total_area / sample_area),
        "paper_captures": paper_captures,
        "paper_captures_hours_this_machine": round(paper_captures / sample_rate / 3600 / cores, 2),
        "paper_captures_hours_this_machine_dataset_quality": round(paper_captures * finer_cost / sample_rate
                                                                   / 3600 / cores, 2),
        "dataset_cpu_hours": round(cpu_hours, 2), "cores": cores,
        "dataset_hours_this_machine": round(cpu_hours / cores, 2),
        "dataset_hours_8_cores": round(cpu_hours / 8, 2), "dataset_hours_64_cores": round(cpu_hours / 64, 2),
        "dataset_hours_target": DATASET_HOURS_TARGET,
        "extrapolation": "CPU seconds per m2 of floor on the sample houses x floor area of all 30 houses, "
                         "divided by the cores (independent raids, one process each)",
    }
