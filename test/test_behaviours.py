"""Behaviours without ROS: waypoints, the Wanderer, the Grid sweep and teleop keys, on real physics."""
from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import resolved

from ravh_sim.behaviours.grid import GridSweep
from ravh_sim.behaviours.teleop import Teleop
from ravh_sim.behaviours.wanderer import Wanderer
from ravh_sim.behaviours.waypoints import (
    PAPER_AGENT_RADIUS,
    PAPER_NEAR,
    Layout,
    grid_nodes,
    light_waypoints,
    nearest_reachable_cells,
    paper_grid_nodes,
    paper_lattice,
)
from ravh_sim.nav.follower import PathFollower
from ravh_sim.nav.grid import FREE, reachable
from ravh_sim.nav.navigation import Navigation
from ravh_sim.robot.simulation import Simulation
from ravh_sim.world.scene import World
from ravh_sim.world.state import WorldState

CONTROL_STEPS = 12          # 20 Hz control at 240 Hz physics


@pytest.fixture
def rig(houses):
    def make(n: int):
        house = houses[n]
        world = World(house, resolved(house))
        sim = Simulation(world)
        robot = sim.robot("robot")
        nav = Navigation(house, world.state, robot.profile)
        return house, world, sim, robot, nav, PathFollower(robot, nav, robot.profile)
    made = []
    yield lambda n: made.append(make(n)) or made[-1]
    for m in made:
        m[1].close()


def run(sim, behaviour, robot, limit_s: float):
    """Step until done; returns (time, pose, speed) at each requested capture."""
    shots = []
    while not behaviour.done and sim.time < limit_s:
        for _ in behaviour.update(CONTROL_STEPS * sim.dt):
            shots.append((sim.time, robot.pose, robot.velocity))
        sim.step(CONTROL_STEPS)
    return shots


def test_light_waypoints_lie_in_free_space_in_their_room(houses):
    for n in (1, 15, 23):
        house = houses[n]
        nav = Navigation(house, WorldState(resolved(house)), _profile())
        grid = nav.map()
        start = house.station.position[:2]
        waypoints = light_waypoints(Layout.of(house), grid, start)
        reach = reachable(grid, start)
        for room_id, points in waypoints.items():
            assert points
            for x, y in points:
                r, c = grid.cell_of(x, y)
                assert reach[r, c] and grid.data[r, c] == FREE
                assert house.room(room_id).contains(x, y)


def test_wanderer_visits_every_room_and_captures_while_moving(rig):
    house, _, sim, robot, nav, follower = rig(20)
    waypoints = light_waypoints(Layout.of(house), nav.map(), robot.pose[:2])
    wanderer = Wanderer(follower, waypoints, order="once", capture_period=0.5)
    shots = run(sim, wanderer, robot, 600)
    assert wanderer.done and not wanderer.skipped
    assert wanderer.visited == {r.id for r in house.rooms}
    rooms_seen = {house.room_at(*pose[:2]).id for _, pose, _ in shots if house.room_at(*pose[:2])}
    assert rooms_seen == {r.id for r in house.rooms}
    gaps = np.diff([t for t, _, _ in shots])
    assert np.median(gaps) == pytest.approx(0.5, abs=0.06)
    assert all(abs(v) > 0.01 or abs(w) > 0.01 for _, _, (v, w) in shots)


def test_grid_nodes_cover_the_free_area_at_the_spacing(houses):
    house = houses[20]
    grid = Navigation(house, WorldState(resolved(house)), _profile()).map()
    start = house.station.position[:2]
    nodes = grid_nodes(Layout.of(house), grid, start, spacing=0.5)
    pts = np.array(nodes)
    cells = np.array([grid.cell_of(x, y) for x, y in nodes])
    on_lattice = np.all((cells - 5) % 10 == 0, axis=1)             # 0.5 m = 10 cells of 5 cm
    assert on_lattice.mean() > 0.6                                 # a lattice, plus fill-ins by walls
    assert len(set(map(tuple, cells))) == len(cells)
    free = np.argwhere(reachable(grid, start))
    centres = np.array([grid.center_of(r, c) for r, c in free])
    nearest = np.min(np.linalg.norm(centres[:, None, :] - pts[None, :, :], axis=2), axis=1)
    assert nearest.max() <= 0.5 + 1e-6                              # every free cell near a node
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert np.median(steps) <= 0.75                                # consecutive nodes are neighbours


def test_paper_node_rule_keeps_lattice_points_a_thin_agent_reaches_and_stops_the_robot_nearby(houses):
    house = houses[29]                        # the smallest house: 4 rooms, the paper's 320 grid captures
    nav = Navigation(house, WorldState(resolved(house)), _profile())
    walkable, grid = nav.walkable(PAPER_AGENT_RADIUS), nav.map()
    start = house.station.position[:2]
    kept = paper_lattice(walkable, start)
    assert all(abs(v / 0.5 - round(v / 0.5)) < 1e-9 for p in kept for v in p)     # the house frame's 0.5 m lattice
    reach = reachable(walkable, start)
    on_mesh = [p for p in kept if reach[walkable.cell_of(*p)]]
    off_mesh = [p for p in kept if not reach[walkable.cell_of(*p)]]
    assert on_mesh and off_mesh                                      # points near but off the mesh are kept too
    every = [(x * 0.5, y * 0.5) for x in range(-40, 41) for y in range(-40, 41)]
    inside = [p for p in every if walkable.inside(*walkable.cell_of(*p)) and reach[walkable.cell_of(*p)]]
    assert inside and set(inside) <= set(kept)                                # every lattice point on the mesh is kept
    free_cells = np.argwhere(reach)
    for p in off_mesh:
        gap = np.min(np.linalg.norm(np.array([walkable.center_of(r, c) for r, c in free_cells]) - p, axis=1))
        assert gap <= PAPER_NEAR + walkable.resolution
    wider = paper_lattice(walkable, start, near=0.3)
    assert len(wider) > len(kept)                                    # the allowance decides, not chance
    nodes = paper_grid_nodes(Layout.of(house), walkable, grid, start)
    assert len(nodes) == len(kept)
    robot_reach = reachable(grid, start)
    assert all(robot_reach[grid.cell_of(*n)] for n in nodes)         # the robot stops where it can go
    stops = nearest_reachable_cells(grid, start, kept)
    for p, (r, c) in zip(kept, stops):
        own = grid.cell_of(*p)
        if grid.inside(*own) and robot_reach[own]:
            assert (r, c) == own                                     # a point the robot reaches is its own stop
    assert 0.9 <= len(nodes) * 10 / 320 <= 1.3                       # Table 2: 320 grid captures in house 29


def test_grid_sweep_takes_n_captures_per_node_all_around(rig):
    house, _, sim, robot, nav, follower = rig(20)
    nodes = grid_nodes(Layout.of(house), nav.map(), robot.pose[:2])[:3]
    sweep = GridSweep(follower, nodes, captures_per_node=10)
    shots = run(sim, sweep, robot, 300)
    assert sweep.done and len(sweep.visited_nodes) == 3 and len(shots) == 30
    for k, node in enumerate(nodes):
        node_shots = shots[10 * k:10 * (k + 1)]
        headings = sorted((pose[2] - node_shots[0][1][2]) % (2 * math.pi) for _, pose, _ in node_shots)
        assert np.allclose(np.diff(headings), 2 * math.pi / 10, atol=math.radians(4))
        for _, pose, (v, w) in node_shots:
            assert math.dist(pose[:2], node) < 0.15 and abs(v) < 0.02 and abs(w) < 0.05


def test_teleop_keys():
    t = Teleop(max_linear=0.25, max_angular=0.4)
    for _ in range(10):
        t.press("w")
    assert t.v == pytest.approx(0.25)
    t.press("a")
    assert t.w == pytest.approx(0.1)
    assert t.press("c") == "capture" and t.press(" ") is None and (t.v, t.w) == (0.0, 0.0)
    for _ in range(10):
        t.press("x")
        t.press("d")
    assert (t.v, t.w) == (pytest.approx(-0.25), pytest.approx(-0.4))
    assert t.press("q") == "quit" and (t.v, t.w) == (0.0, 0.0)


def _profile():
    from ravh_sim.robot.profile import load_profile
    return load_profile("giraff")
