"""Navigation: the free-space map, the planner and the map files, on all 30 houses."""
from __future__ import annotations

import dataclasses
import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ravh_sim.errors import UnknownNameError, UserError
from ravh_sim.nav.freespace import free_space, inflate, obstacles
from ravh_sim.nav.grid import FREE, OCCUPIED, UNKNOWN, Grid, distance_to_obstacle
from ravh_sim.nav.mapio import read_map, write_map
from ravh_sim.nav.planner import Path, Unreachable, densify, plan_path
from ravh_sim.world.geometry import points_in_polygon

HOUSES = list(range(1, 31))
MIN_ROOM_AREA = 2.0
CUT_OFF_BY_FURNITURE = {
    # house: rooms a 0.25 m robot cannot reach with every door open (data, not rasterisation):
    23: {"UtilityRoom_1"},   # its only door opens onto a 0.44 m gap between Refrigerator_0 and the sink
    25: {"Balcony_1"},       # reached only past Bed_1, where Lamp_6 overhangs Dresser_3: 0.43 m left
}


def all_open(house) -> dict[str, bool]:
    return {d.id: True for d in house.doors}


def cell_centres(grid: Grid, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    xs, ys = grid.cell_centres()
    return xs[mask], ys[mask]


def room_mask(grid: Grid, room) -> np.ndarray:
    return grid.polygons_mask((room.floor, *room.extra_floors))


def roomiest_point(grid: Grid, room, within: np.ndarray | None = None) -> tuple[float, float] | None:
    """The free cell of ``room`` (and of ``within``) farthest from obstacles: a natural goal."""
    usable = room_mask(grid, room) & (grid.data == FREE) & (True if within is None else within)
    clear = np.where(usable, distance_to_obstacle(grid), -1.0)
    r, c = np.unravel_index(int(np.argmax(clear)), clear.shape)
    return grid.center_of(int(r), int(c)) if clear[r, c] > 0 else None


def home_component(grid: Grid, start: tuple[float, float]) -> np.ndarray:
    """The free cells connected (4-connected, as the planner moves) to the free cell nearest start."""
    _, labels = cv2.connectedComponents((grid.data == FREE).astype(np.uint8), connectivity=4)
    xs, ys = cell_centres(grid, grid.data == FREE)
    nearest = int(np.argmin(np.hypot(xs - start[0], ys - start[1])))
    return labels == labels[grid.cell_of(xs[nearest], ys[nearest])]


def assert_segments_free(grid: Grid, path: Path, skip_first: bool = False) -> None:
    waypoints = path.points[1:] if skip_first else path.points
    for a, b in zip(waypoints, waypoints[1:]):
        n = max(2, math.ceil(math.dist(a, b) / 0.005))
        for t in np.linspace(0.0, 1.0, n + 1):
            x, y = a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t
            assert grid.is_free(x, y), f"segment {a} -> {b} leaves free space at ({x:.3f}, {y:.3f})"


def segment_distance(p, a, b) -> float:
    (ax, ay), (bx, by) = a, b
    dx, dy = bx - ax, by - ay
    t = ((p[0] - ax) * dx + (p[1] - ay) * dy) / (dx * dx + dy * dy) if dx or dy else 0.0
    t = min(max(t, 0.0), 1.0)
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy)


# --------------------------------------------------------------------------- free space

@pytest.mark.parametrize("number", HOUSES)
def test_walls_and_open_doors_connect_every_room(houses, number):
    """Rasterisation check: without furniture, every room of 2 m² or more has free cells and they
    form one component (4-connected, as the planner moves) with all doors open."""
    house = dataclasses.replace(houses[number], objects=())
    grid = free_space(house, all_open(house))
    _, labels = cv2.connectedComponents((grid.data == FREE).astype(np.uint8), connectivity=4)
    components = {}
    for room in house.rooms:
        if room.area >= MIN_ROOM_AREA:
            found = set(np.unique(labels[room_mask(grid, room) & (grid.data == FREE)]).tolist())
            assert found, f"house {number}: room {room.id} has no free cell"
            components[room.id] = found
    assert len(set().union(*components.values())) == 1, f"house {number}: {components}"


@pytest.mark.parametrize("number", HOUSES)
def test_station_reaches_every_room_with_doors_open(houses, number):
    """With furniture: a robot at the station reaches every room of 2 m² or more, except the few
    that furniture closes off (listed, so a change in the data shows up here). The goal in each
    room is its roomiest cell that the station's free component reaches, if any."""
    house = houses[number]
    grid = free_space(house, all_open(house))
    start = house.station.position[:2]
    home = home_component(grid, start)
    cut_off = set()
    for room in house.rooms:
        if room.area < MIN_ROOM_AREA:
            continue
        anywhere = roomiest_point(grid, room)
        assert anywhere is not None, f"house {number}: room {room.id} has no free cell"
        goal = roomiest_point(grid, room, within=home)
        if goal is None:
            cut_off.add(room.id)
            with pytest.raises(Unreachable, match=f"in room {room.id} is not reachable"):
                plan_path(grid, start, anywhere, house=house)
            continue
        path = plan_path(grid, start, goal, house=house)
        assert path.points[0] == pytest.approx(start) and path.points[-1] == pytest.approx(goal)
    assert cut_off == CUT_OFF_BY_FURNITURE.get(number, set())


@pytest.mark.parametrize("number", HOUSES)
def test_free_cells_lie_on_floors_or_in_open_doorways(houses, number):
    house = houses[number]
    grid = free_space(house, {})
    xs, ys = cell_centres(grid, grid.data == FREE)
    ok = np.zeros(xs.shape, bool)
    for room in house.rooms:
        for poly in (room.floor, *room.extra_floors):
            ok |= points_in_polygon(xs, ys, poly)
    for door in house.doors:
        if door.default_open:
            ok |= np.hypot(xs - door.position[0], ys - door.position[1]) <= 0.5
    assert ok.all(), f"house {number}: free cells off the floors, e.g. {(xs[~ok][0], ys[~ok][0])}"


def test_free_space_values_and_frame(houses):
    house = houses[15]
    grid = free_space(house, {})
    assert grid.data.dtype == np.int8
    assert set(np.unique(grid.data).tolist()) == {UNKNOWN, FREE, OCCUPIED}
    xmin, ymin, xmax, ymax = house.bounds
    rows, cols = grid.shape
    assert grid.origin[0] <= xmin - 0.5 and grid.origin[0] + cols * grid.resolution >= xmax + 0.5
    assert grid.origin[1] <= ymin - 0.5 and grid.origin[1] + rows * grid.resolution >= ymax + 0.5
    assert (grid.data[[0, -1], :] == UNKNOWN).all() and (grid.data[:, [0, -1]] == UNKNOWN).all()


def test_furniture_blocks(houses):
    for house in (houses[1], houses[14], houses[23]):
        grid, raw = free_space(house, {}), obstacles(house, {})
        for obj in house.objects:
            if obj.type in ("Bed", "Sofa", "Refrigerator", "Closet", "Toilet"):
                assert not grid.is_free(*obj.position[:2]), obj.id
                r, c = raw.cell_of(*obj.position[:2])
                assert raw.data[r, c] == OCCUPIED, obj.id


def _inside_box(grid: Grid, obj, margin: float) -> np.ndarray:
    """Cells whose centre lies in ``obj``'s default box shrunk by ``margin`` on every side."""
    box = obj.box(None)
    xs, ys = grid.cell_centres()
    c, s = math.cos(obj.yaw), math.sin(obj.yaw)
    u = (xs - box.position[0]) * c + (ys - box.position[1]) * s
    v = -(xs - box.position[0]) * s + (ys - box.position[1]) * c
    return (np.abs(u) <= box.size[0] / 2 - margin) & (np.abs(v) <= box.size[1] / 2 - margin)


def test_parts_block_not_boxes(houses):
    """The map blocks the furniture parts a robot would touch, not their boxes: the empty corner of
    a corner sofa is free floor; a dining table blocks a tall robot with its top, a short robot that
    fits under the top only with its legs."""
    house = houses[1]
    sofa = house.object("Sofa_1")                              # 'Corner Sofa', 2.66 x 1.92 m
    raw = obstacles(dataclasses.replace(house, objects=(sofa,)), {})
    inside = _inside_box(raw, sofa, 0.05)
    free = (raw.data[inside] == FREE).mean()
    assert 0.15 < free < 0.6, free
    table = next(o for o in houses[15].objects if o.type == "Table" and o.size[2] > 0.6)
    alone = dataclasses.replace(houses[15], objects=(table,))
    tall, short = obstacles(alone, {}, height=1.6), obstacles(alone, {}, height=0.5)
    inside = _inside_box(tall, table, 0.05)
    assert (tall.data[inside] == OCCUPIED).all()
    assert (short.data[inside] == OCCUPIED).mean() < 0.3


def test_objects_out_of_reach_do_not_block(houses):
    """Lights, windows, doors' own objects and the station change nothing; a short robot passes
    under a wall cabinet that blocks a tall one."""
    house = houses[23]
    kept = tuple(o for o in house.objects if o.type not in ("Light", "Wall", "Door", "Station"))
    assert len(kept) < len(house.objects)
    pruned = dataclasses.replace(house, objects=kept)
    assert np.array_equal(obstacles(house, {}).data, obstacles(pruned, {}).data)
    cabinet = house.object("KitchenFurniture_9")               # wall cabinet, 1.41-2.04 m high
    alone = dataclasses.replace(house, objects=(cabinet,))
    tall, short = obstacles(alone, {}, height=1.6), obstacles(alone, {}, height=1.0)
    assert tall.data[tall.cell_of(*cabinet.position[:2])] == OCCUPIED
    assert short.data[short.cell_of(*cabinet.position[:2])] != OCCUPIED


def test_closed_door_is_an_obstacle(houses):
    house = houses[23]
    door = house.door_by_id["Door_1"]
    closed = obstacles(house, {door.id: False})
    opened = obstacles(house, {door.id: True})
    r, c = closed.cell_of(*door.position[:2])
    assert closed.data[r, c] == OCCUPIED and opened.data[r, c] == FREE


def test_model_choice_changes_the_footprint(houses):
    house = houses[23]
    sink = house.object("Sink_1")                              # variants 0.40 x 0.38 and 0.57 x 0.88
    small = obstacles(dataclasses.replace(house, objects=(sink,)), {}, models={"Sink_1": 0})
    big = obstacles(dataclasses.replace(house, objects=(sink,)), {}, models={"Sink_1": 1})
    assert (big.data == OCCUPIED).sum() > (small.data == OCCUPIED).sum()


def test_unknown_names_are_user_errors(houses):
    with pytest.raises(UnknownNameError, match="door 'Door_99'"):
        free_space(houses[1], {"Door_99": False})
    with pytest.raises(UnknownNameError, match="object 'Bed_99'"):
        free_space(houses[1], {}, models={"Bed_99": 1})


def test_bigger_radius_fewer_free_cells(houses):
    house = houses[7]
    counts = [int((free_space(house, {}, radius=r).data == FREE).sum()) for r in (0.0, 0.15, 0.25, 0.35)]
    assert counts == sorted(counts, reverse=True) and len(set(counts)) == 4


def test_inflation_keeps_the_radius_from_walls(houses):
    """Free cell centres are at least the radius (less the grid's error, one cell) from every wall."""
    house = houses[4]
    radius, res = 0.3, 0.05
    grid = free_space(dataclasses.replace(house, objects=()), all_open(house), radius=radius,
                      resolution=res)
    xs, ys = cell_centres(grid, grid.data == FREE)
    for wall in house.walls:
        if wall.kind == "lintel":
            continue
        (ax, ay), (bx, by) = wall.a, wall.b
        ux, uy = (bx - ax) / wall.length, (by - ay) / wall.length
        along = (xs - (ax + bx) / 2) * ux + (ys - (ay + by) / 2) * uy
        across = -(xs - (ax + bx) / 2) * uy + (ys - (ay + by) / 2) * ux
        dist = np.hypot(np.maximum(np.abs(along) - wall.length / 2, 0),
                        np.maximum(np.abs(across) - wall.thickness / 2, 0))
        assert dist.min() > radius - res, wall


def test_resolution_is_respected(houses):
    house = houses[12]
    fine, coarse = free_space(house, {}, resolution=0.05), free_space(house, {}, resolution=0.1)
    assert coarse.resolution == 0.1
    assert abs(coarse.shape[0] * 2 - fine.shape[0]) <= 2 and abs(coarse.shape[1] * 2 - fine.shape[1]) <= 2
    fine_area = (fine.data == FREE).sum() * 0.05 ** 2
    coarse_area = (coarse.data == FREE).sum() * 0.1 ** 2
    assert coarse_area == pytest.approx(fine_area, rel=0.25)     # coarse cells round walls coarsely


def test_inflate_and_distance_on_a_small_grid():
    data = np.zeros((21, 21), np.int8)
    data[10, 10] = OCCUPIED
    grid = Grid(data, (0.0, 0.0), 0.1)
    clear = distance_to_obstacle(grid)
    assert clear[10, 10] == 0 and clear[10, 13] == pytest.approx(0.3) and clear[13, 14] == pytest.approx(0.5)
    inflated = inflate(grid, 0.3)
    assert inflated.data[10, 13] == OCCUPIED and inflated.data[10, 14] == FREE
    assert inflated.data[12, 12] == OCCUPIED and inflated.data[12, 13] == FREE   # 0.28 m vs 0.36 m
    assert grid.data[10, 13] == FREE                                          # input untouched


# --------------------------------------------------------------------------- planner

@pytest.mark.parametrize("number", [3, 5, 14, 23, 25])
def test_paths_stay_free_and_change_room_only_at_openings(houses, number):
    """Paths from the station to every room it reaches cross only free cells, and pass from one
    room to another only in a doorway (near a door, or under a lintel where there is no door)."""
    house = houses[number]
    grid = free_space(house, all_open(house))
    lintels = [w for w in house.walls if w.kind == "lintel"]
    start = house.station.position[:2]
    home = home_component(grid, start)
    for room in house.rooms:
        goal = roomiest_point(grid, room, within=home)
        if goal is None:
            continue
        path = plan_path(grid, start, goal, house=house)
        assert_segments_free(grid, path, skip_first=not grid.is_free(*start))
        samples = densify(path.points, 0.02)
        rooms = [house.room_at(*p) for p in samples]
        for p, r0, r1 in zip(samples[1:], rooms, rooms[1:]):
            if r0 is not r1:
                at_door = any(math.dist(p, d.position[:2]) <= d.width / 2 + 0.05 for d in house.doors)
                at_opening = any(segment_distance(p, w.a, w.b) < 0.1 for w in lintels)
                assert at_door or at_opening, f"house {number}: {r0 and r0.id} -> {r1 and r1.id} at {p}"


@pytest.mark.parametrize("number, detours", [
    (23, set()),                                           # rooms in a tree: every door is a cut
    (27, {"Door_0", "Door_4", "Door_6", "Door_11"}),       # a ring of rooms: these have a way around
])
def test_closing_a_door_removes_paths_through_it(houses, number, detours):
    """A path between the two sides of an open door goes through it; once the door is closed the
    path goes around (never through the doorway) or the planner says the door blocks it."""
    house = houses[number]
    grid = free_space(house, all_open(house))
    rerouted = set()
    for door in house.doors:
        if len(door.rooms) < 2:
            continue
        normal = (-math.sin(door.yaw), math.cos(door.yaw))
        ends = [(door.position[0] + s * 0.5 * normal[0], door.position[1] + s * 0.5 * normal[1])
                for s in (1, -1)]
        try:
            through = plan_path(grid, ends[0], ends[1], goal_tolerance=0.3)
        except Unreachable:
            continue                                       # furniture right at the door
        assert any(_in_door(p, door) for p in densify(through.points, 0.02)), door.id
        closed = free_space(house, {**all_open(house), door.id: False})
        try:
            around = plan_path(closed, ends[0], ends[1], goal_tolerance=0.3, blocked_by=[door.id])
        except Unreachable as e:
            assert e.end == "goal" and f"closed doors: {door.id}" in str(e)
            continue
        assert not any(_in_door(p, door) for p in densify(around.points, 0.02)), door.id
        assert around.length > through.length + 2.0
        rerouted.add(door.id)
    assert rerouted == detours


def _in_door(p, door) -> bool:
    dx, dy = p[0] - door.position[0], p[1] - door.position[1]
    along = dx * math.cos(door.yaw) + dy * math.sin(door.yaw)
    across = -dx * math.sin(door.yaw) + dy * math.cos(door.yaw)
    return abs(along) <= door.width / 2 and abs(across) <= 0.1


def single_door_rooms(house):
    """Rooms whose only opening is one door: every lintel of the room sits over that door."""
    for room in house.rooms:
        doors = [d for d in house.doors if room.id in d.rooms]
        lintels = [w for w in house.walls if w.kind == "lintel" and w.room == room.id]
        if len(doors) == 1 and lintels and all(
                segment_distance(doors[0].position[:2], w.a, w.b) < 0.2 for w in lintels):
            yield room, doors[0]


def test_closing_the_only_door_makes_a_room_unreachable(houses):
    checked = 0
    for number in HOUSES:
        house = houses[number]
        station_room = house.room_at(*house.station.position[:2])
        for room, door in single_door_rooms(house):
            if room is station_room or room.id in CUT_OFF_BY_FURNITURE.get(number, ()):
                continue
            grid = free_space(house, {**all_open(house), door.id: False})
            goal = roomiest_point(grid, room)
            if goal is None:
                continue
            with pytest.raises(Unreachable) as err:
                plan_path(grid, house.station.position[:2], goal, house=house, blocked_by=[door.id])
            message = str(err.value)
            assert err.value.end == "goal"
            assert f"goal ({goal[0]:.2f}, {goal[1]:.2f}) in room {room.id} is not reachable" in message
            assert f"in room {station_room.id}: every path is blocked (closed doors: {door.id})" in message
            checked += 1
    assert checked >= 30                                   # bathrooms, bedrooms, offices...


def test_unreachable_names_the_end(houses):
    house = houses[1]
    grid = free_space(house, {})
    bed = house.object("Bed_2").position[:2]
    free = house.station.position[:2]
    with pytest.raises(Unreachable, match=r"^start \(.*\) in room \w+ is inside an obstacle") as err:
        plan_path(grid, bed, free, house=house)
    assert err.value.end == "start" and isinstance(err.value, UserError)
    with pytest.raises(Unreachable, match=r"^goal \(.*\) in room \w+ is inside an obstacle") as err:
        plan_path(grid, free, bed, house=house)
    assert err.value.end == "goal"
    xmax = house.bounds[2]
    with pytest.raises(Unreachable, match=r"^goal \(.*\) is outside the house"):
        plan_path(grid, free, (xmax + 3.0, 0.0), house=house)
    with pytest.raises(Unreachable, match=r"^start \(.*\) is outside the house"):
        plan_path(grid, (xmax + 3.0, 0.0), free, house=house)


def test_start_next_to_a_wall_is_snapped(houses):
    """Stations sit against walls, inside the inflation: the path starts there and leaves at once."""
    snapped = 0
    for number in HOUSES:
        house = houses[number]
        grid = free_space(house, {})
        start = house.station.position[:2]
        goal = roomiest_point(grid, house.room_at(*start), within=home_component(grid, start))
        path = plan_path(grid, start, goal, house=house)
        assert path.points[0] == pytest.approx(start)
        if not grid.is_free(*start):
            snapped += 1
            assert math.dist(path.points[0], path.points[1]) <= 0.3 + 1e-9
            assert grid.is_free(*path.points[1])
    assert snapped >= 1


def test_goal_tolerance(houses):
    house = houses[1]
    grid = free_space(house, {})
    bed = house.object("Bed_2")
    near = (bed.position[0], bed.position[1])
    path = plan_path(grid, house.station.position[:2], near, goal_tolerance=2.0)
    assert grid.is_free(*path.points[-1]) and math.dist(path.points[-1], near) <= 2.0


def test_paths_keep_away_from_walls_where_there_is_room():
    data = np.zeros((40, 100), np.int8)                   # a 5 m x 2 m corridor at 0.05 m
    data[[0, -1], :] = OCCUPIED
    data[:, [0, -1]] = OCCUPIED
    grid = inflate(Grid(data, (0.0, 0.0), 0.05), 0.25)
    path = plan_path(grid, (0.5, 0.4), (4.5, 0.4))
    middle = [p for p in densify(path.points, 0.05) if 1.5 < p[0] < 3.5]
    assert min(p[1] for p in middle) >= 0.5               # about 0.3 m clearance beyond the inflation
    straight = plan_path(grid, (0.5, 0.4), (4.5, 0.4), clearance_weight=0.0)
    assert straight.points == ((0.5, 0.4), (4.5, 0.4))


def test_cross_house_plan(houses):
    """A long plan across house 23 (its speed is `ravh bench nav`'s business, not a test's)."""
    house = houses[23]
    grid = free_space(house, all_open(house))
    start, goal = house.station.position[:2], roomiest_point(grid, house.room("DressingRoom_1"))
    path = plan_path(grid, start, goal)
    assert path.length > 12.0 and len(path.points) < 30


@pytest.fixture(scope="module")
def main_component_23(houses) -> tuple[Grid, np.ndarray, np.ndarray]:
    """House 23 with doors open, and the centres of the cells of its largest free component."""
    grid = free_space(houses[23], all_open(houses[23]))
    _, labels = cv2.connectedComponents((grid.data == FREE).astype(np.uint8), connectivity=4)
    main = np.argmax(np.bincount(labels.ravel())[1:]) + 1
    return (grid, *cell_centres(grid, labels == main))


@settings(max_examples=25, deadline=None)
@given(i=st.integers(0, 10**9), j=st.integers(0, 10**9))
def test_random_plans_are_valid(main_component_23, i, j):
    grid, xs, ys = main_component_23
    start, goal = (xs[i % xs.size], ys[i % xs.size]), (xs[j % xs.size], ys[j % xs.size])
    path = plan_path(grid, start, goal)
    assert path.points[0] == start and path.points[-1] == goal
    assert path.length >= math.dist(start, goal) - 1e-9
    assert_segments_free(grid, path)


def test_densify():
    points = densify([(0.0, 0.0), (1.0, 0.0), (1.0, 0.25)], 0.1)
    assert points[0] == (0.0, 0.0) and points[-1] == (1.0, 0.25) and (1.0, 0.0) in points
    assert max(math.dist(a, b) for a, b in zip(points, points[1:])) <= 0.1 + 1e-12
    assert densify([(2.0, 3.0)], 0.1) == [(2.0, 3.0)]
    with pytest.raises(ValueError):
        densify([(0.0, 0.0)], 0.0)


# --------------------------------------------------------------------------- map files

def test_map_round_trip(houses, tmp_path):
    grid = free_space(houses[23], {})
    pgm, yaml_path = write_map(grid, tmp_path / "maps", "house23")
    assert pgm.name == "house23.pgm" and yaml_path.name == "house23.yaml"
    back = read_map(yaml_path)
    assert np.array_equal(back.data, grid.data) and back.data.dtype == np.int8
    assert back.origin == grid.origin and back.resolution == grid.resolution


def test_map_file_format(tmp_path):
    import yaml
    data = np.array([[FREE, OCCUPIED, UNKNOWN], [UNKNOWN, UNKNOWN, FREE]], np.int8)   # row 0 = low y
    pgm, yaml_path = write_map(Grid(data, (-1.5, 2.25), 0.05), tmp_path)
    raw = pgm.read_bytes()
    assert raw.startswith(b"P5\n") and raw.endswith(bytes([205, 205, 254, 254, 0, 205]))
    assert b"\n3 2\n255\n" in raw
    meta = yaml.safe_load(yaml_path.read_text())
    assert meta == {"image": "map.pgm", "mode": "trinary", "resolution": 0.05,
                    "origin": [-1.5, 2.25, 0.0], "negate": 0, "occupied_thresh": 0.65,
                    "free_thresh": 0.196}
    assert cv2.imread(str(pgm), cv2.IMREAD_UNCHANGED).tolist() == [[205, 205, 254], [254, 0, 205]]


def test_read_map_reports_bad_files(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("image: missing.pgm\nmode: scale\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(UserError, match="mode"):
        read_map(bad)
    bad.write_text("image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                   "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    with pytest.raises(UserError, match="missing.pgm: -: cannot read"):
        read_map(bad)
    for name, body in (("short.pgm", b"P5\n3 2\n255\n" + bytes(5)), ("wide.pgm", b"P5\n3 2\n65535\n" + bytes(12)),
                       ("picture.pgm", b"\x89PNG\r\n")):
        (tmp_path / name).write_bytes(body)
        bad.write_text(f"image: {name}\nresolution: 0.05\norigin: [0, 0, 0]\n")
        with pytest.raises(UserError, match=f"{name}: header: (not a greyscale PGM|expected 8-bit pixels)"):
            read_map(bad)


def test_unreachable_names_only_the_doors_that_cut_the_way(houses):
    from ravh_sim.nav.navigation import Navigation
    from ravh_sim.robot.profile import load_profile
    from ravh_sim.world.settings import load_settings, resolve
    from ravh_sim.world.state import WorldState
    house = houses[20]
    settings = resolve(load_settings(), house, 0)
    doors = {**settings.doors, "Door_1": False, "Door_2": False}   # Door_2 is the bathroom's, not on the way
    nav = Navigation(house, WorldState(settings.changed(doors=doors)), load_profile("giraff"))
    goal = nav.room_goal("Bedroom_1")
    with pytest.raises(Unreachable) as err:
        nav.plan(house.station.position[:2], goal)
    assert "closed doors: Door_1)" in str(err.value)
    house23 = houses[23]
    nav23 = Navigation(house23, WorldState(resolve(load_settings(), house23, 0)), load_profile("giraff"))
    grid = nav23.map()
    r, c = np.argwhere(grid.polygons_mask((house23.room("UtilityRoom_1").floor,)) & (grid.data == FREE))[0]
    with pytest.raises(Unreachable, match=r"blocked \(walls or furniture\)"):
        nav23.plan(house23.station.position[:2], grid.center_of(r, c))


def test_navigation_rebuilds_its_maps_only_when_the_layout_changes(houses):
    """The maps are cached on the state's layout revision: paint or light changes keep them, a door
    that closes gives new ones that block its doorway."""
    from ravh_sim.nav.navigation import Navigation
    from ravh_sim.robot.profile import load_profile
    from ravh_sim.world.settings import load_settings, resolve
    from ravh_sim.world.state import WorldState
    house = houses[15]
    settings = resolve(load_settings(), house, 0)
    state = WorldState(settings.changed(doors=dict.fromkeys(settings.doors, True)))
    nav = Navigation(house, state, load_profile("giraff"))
    free, obstacle = nav.map(), nav.obstacle_map()
    state.write(sun_angle=200.0, paint={"Bedroom_1": {"walls": "brick"}})
    assert nav.map() is free and nav.obstacle_map() is obstacle
    door = next(d for d in house.doors if len(d.rooms) == 2)
    state.write(doors={door.id: False})
    closed = nav.map()
    assert closed is not free and nav.obstacle_map() is not obstacle
    r, c = closed.cell_of(*door.position[:2])
    assert free.data[r, c] == FREE and closed.data[r, c] != FREE
    assert nav.map() is closed
