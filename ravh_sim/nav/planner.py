"""Global path planning on the free-space map: A* with a clearance cost, then shortcutting.

The map from :func:`ravh_sim.nav.freespace.free_space` is already inflated by the robot radius, so
the robot is a point and any FREE cell is a valid position. Planning has three steps:

1. Check both ends: a start slightly inside the inflation (robots start at a station next to a
   wall) moves to the nearest free cell within ``start_snap``; a goal may move within
   ``goal_tolerance`` to the nearest cell the start can reach. A start and goal in different free
   components are reported at once (connected components are cheap in cv2), with the rooms
   involved and the closed doors the caller says may be in the way, instead of letting A* exhaust
   the house.
2. A* on the 8-connected grid (no corner cutting, so every step stays in free cells). Each step costs
   its length times ``1 + clearance_weight * (1 - d / clearance)^2`` where ``d`` is the cell's
   distance to the nearest non-free cell (capped at ``clearance``): paths keep to the middle of
   corridors and away from furniture where there is room, and still squeeze through doorways.
3. Shortcutting: the cell chain becomes a few waypoints joined by straight segments that cross only
   free cells (every cell a segment touches is checked) and keep about the clearance the A* path had.

Pure Python + numpy (no scipy): flat cell indices on a grid padded with a blocked border, neighbour
offsets and costs as Python lists, and blocked cells of infinite cost, so the inner loop has no
bounds checks.
"""
from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from ravh_sim.errors import UserError
from ravh_sim.nav.grid import FREE, UNKNOWN, Grid, distance_to_obstacle
from ravh_sim.world.house import House

Point = tuple[float, float]
_SQRT2 = math.sqrt(2.0)
_TIE_BREAK = 1.0 + 1e-3        # favour cells nearer the goal among equal f: far fewer expansions


class Unreachable(UserError):
    """No path: ``end`` ('start' or 'goal') names the end that is the problem."""

    def __init__(self, end: str, message: str) -> None:
        self.end = end
        super().__init__(message)


@dataclass(frozen=True)
class Path:
    """Waypoints from the requested start to the goal (or the free point nearest it within the
    goal tolerance). Straight segments between them cross only free cells, except the first one
    when the start had to be moved off the inflation."""
    points: tuple[Point, ...]

    @property
    def length(self) -> float:
        return sum(math.dist(a, b) for a, b in zip(self.points, self.points[1:]))


def plan_path(grid: Grid, start_xy: Point, goal_xy: Point, *, house: House | None = None,
              blocked_by: Sequence[str] = (), clearance: float = 0.3,
              clearance_weight: float = 2.0, start_snap: float = 0.3,
              goal_tolerance: float = 0.0) -> Path:
    """A short, smooth path over the FREE cells of ``grid`` from ``start_xy`` to ``goal_xy``.

    ``house`` (optional) names the rooms of both ends in error messages; ``blocked_by`` lists the
    closed doors the caller knows of, quoted when the goal is cut off from the start.
    Raises :class:`Unreachable` when either end is unusable or no path joins them.
    """
    start_xy, goal_xy = (float(start_xy[0]), float(start_xy[1])), (float(goal_xy[0]), float(goal_xy[1]))
    free = grid.data == FREE
    start, goal = _end_cells(grid, free, start_xy, goal_xy, start_snap, goal_tolerance, house,
                             blocked_by)
    clear = distance_to_obstacle(grid)
    cells = _astar(_step_costs(free, clear, clearance, clearance_weight), start, goal)
    start_moved = grid.cell_of(*start_xy) != start
    first = grid.center_of(*start) if start_moved else start_xy
    last = grid.center_of(*goal) if grid.cell_of(*goal_xy) != goal else goal_xy
    if len(cells) == 1:                                    # start and goal in one cell
        cells = cells * 2
    points = [first, *(grid.center_of(r, c) for r, c in cells[1:-1]), last]
    path_clear = np.minimum([clear[r, c] for r, c in cells], clearance)
    smooth = _shortcut(grid, free, clear, points, path_clear, clearance)
    return Path(tuple([start_xy, *smooth] if start_moved else smooth))


def densify(waypoints: Sequence[Point], step: float) -> list[Point]:
    """The polyline through ``waypoints`` resampled so consecutive points are at most ``step`` apart
    (every waypoint is kept), e.g. for a follower that tracks nearby points."""
    if step <= 0:
        raise ValueError(f"step must be > 0, got {step}")
    out = list(waypoints[:1])
    for a, b in zip(waypoints, waypoints[1:]):
        n = max(1, math.ceil(math.dist(a, b) / step))
        out += [(a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n) for k in range(1, n + 1)]
    return out


# --------------------------------------------------------------------------- ends

def _end_cells(grid: Grid, free: np.ndarray, start_xy: Point, goal_xy: Point, start_snap: float,
               goal_tolerance: float, house: House | None,
               blocked_by: Sequence[str]) -> tuple[tuple[int, int], tuple[int, int]]:
    """The start cell (snapped within ``start_snap``) and a goal cell in the start's free component
    (within ``goal_tolerance``), or :class:`Unreachable` saying which end is the problem."""
    start = _nearest_cell(grid, free, start_xy, start_snap)
    if start is None:
        raise _bad_end(grid, start_xy, start_snap, "start", house)
    # 4-connectivity matches A*'s moves: a diagonal step needs both orthogonal cells free.
    _, labels = cv2.connectedComponents(free.astype(np.uint8), connectivity=4)
    goal = _nearest_cell(grid, labels == labels[start], goal_xy, goal_tolerance)
    if goal is not None:
        return start, goal
    if _nearest_cell(grid, free, goal_xy, goal_tolerance) is None:
        raise _bad_end(grid, goal_xy, goal_tolerance, "goal", house)
    cause = f"closed doors: {', '.join(blocked_by)}" if blocked_by else "walls or furniture"
    raise Unreachable("goal", f"goal {_fmt(goal_xy)}{_in_room(goal_xy, house)} is not reachable from "
                              f"start {_fmt(start_xy)}{_in_room(start_xy, house)}: every path is "
                              f"blocked ({cause})")


def _nearest_cell(grid: Grid, allowed: np.ndarray, xy: Point, snap: float) -> tuple[int, int] | None:
    """The cell of ``xy`` if allowed, else the allowed cell whose centre is nearest ``xy`` within
    ``snap`` metres, else None."""
    r, c = grid.cell_of(*xy)
    if grid.inside(r, c) and allowed[r, c]:
        return r, c
    k = math.floor(snap / grid.resolution) + 1
    r0, c0 = max(r - k, 0), max(c - k, 0)
    rr, cc = np.nonzero(allowed[r0:max(r + k + 1, 0), c0:max(c + k + 1, 0)])
    if rr.size == 0:
        return None
    rr, cc = rr + r0, cc + c0
    dist = np.hypot(grid.origin[0] + (cc + 0.5) * grid.resolution - xy[0],
                    grid.origin[1] + (rr + 0.5) * grid.resolution - xy[1])
    best = int(np.argmin(dist))
    return (int(rr[best]), int(cc[best])) if dist[best] <= snap else None


def _bad_end(grid: Grid, xy: Point, snap: float, end: str, house: House | None) -> Unreachable:
    """The error for an end with no free cell within ``snap``: outside the house, or blocked."""
    r, c = grid.cell_of(*xy)
    if not grid.inside(r, c) or grid.data[r, c] == UNKNOWN:
        return Unreachable(end, f"{end} {_fmt(xy)} is outside the house (unknown area of the map)")
    nearby = f" (no free cell within {snap:.2f} m)" if snap > 0 else ""
    return Unreachable(end, f"{end} {_fmt(xy)}{_in_room(xy, house)} is inside an obstacle or closer "
                            f"than the robot radius to one{nearby}")


def _fmt(xy: Point) -> str:
    return f"({xy[0]:.2f}, {xy[1]:.2f})"


def _in_room(xy: Point, house: House | None) -> str:
    room = house.room_at(*xy) if house is not None else None
    return f" in room {room.id}" if room is not None else ""


# --------------------------------------------------------------------------- A*

def _step_costs(free: np.ndarray, clear: np.ndarray, clearance: float,
                weight: float) -> np.ndarray:
    """Cost per metre of entering each cell: 1 far from obstacles, up to 1 + weight next to them,
    infinite where blocked."""
    shortfall = 1.0 - np.minimum(clear, clearance) / clearance if clearance > 0 else 0.0
    cost = 1.0 + weight * np.square(shortfall)
    return np.where(free, cost, np.inf)


def _astar(cost: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> list[tuple[int, int]]:
    """Cells from ``start`` to ``goal`` (both free and connected) of least total cost."""
    width = cost.shape[1] + 2                              # padded with a blocked border
    padded = np.pad(cost, 1, constant_values=np.inf)
    flat_cost = padded.ravel().tolist()
    s = (start[0] + 1) * width + start[1] + 1
    t = (goal[0] + 1) * width + goal[1] + 1
    h = _octile_to(padded.shape, goal[0] + 1, goal[1] + 1).ravel().tolist()
    straight = (1, -1, width, -width)
    diagonal = ((width + 1, width, 1), (width - 1, width, -1),
                (-width + 1, -width, 1), (-width - 1, -width, -1))
    g = [math.inf] * len(flat_cost)
    parent = [-1] * len(flat_cost)
    closed = bytearray(len(flat_cost))
    g[s] = 0.0
    heap = [(h[s], s)]
    pop, push, inf = heapq.heappop, heapq.heappush, math.inf
    while heap:
        _, n = pop(heap)
        if n == t:
            break
        if closed[n]:
            continue
        closed[n] = 1
        gn = g[n]
        for d in straight:
            m = n + d
            ng = gn + flat_cost[m]
            if ng < g[m]:
                g[m] = ng
                parent[m] = n
                push(heap, (ng + h[m], m))
        for d, a, b in diagonal:
            if flat_cost[n + a] == inf or flat_cost[n + b] == inf:
                continue                                   # no corner cutting
            m = n + d
            ng = gn + _SQRT2 * flat_cost[m]
            if ng < g[m]:
                g[m] = ng
                parent[m] = n
                push(heap, (ng + h[m], m))
    chain = [t]
    while chain[-1] != s:
        chain.append(parent[chain[-1]])
    return [(n // width - 1, n % width - 1) for n in reversed(chain)]


def _octile_to(shape: tuple[int, int], row: int, col: int) -> np.ndarray:
    """Octile distance (cells) from every cell to (row, col), slightly inflated for tie-breaking."""
    dy = np.abs(np.arange(shape[0]) - row)[:, None]
    dx = np.abs(np.arange(shape[1]) - col)[None, :]
    return (np.maximum(dx, dy) + (_SQRT2 - 1.0) * np.minimum(dx, dy)) * _TIE_BREAK


# --------------------------------------------------------------------------- shortcutting

def _shortcut(grid: Grid, free: np.ndarray, clear: np.ndarray, points: list[Point],
              path_clear: np.ndarray, clearance: float) -> list[Point]:
    """Keep the fewest points such that each kept pair is joined by a straight segment over free
    cells that keeps about the clearance the path had there (see :func:`_keeps_clearance`).

    Greedy from each kept point: gallop forward while the segment is valid, then binary-search the
    last valid point in the gap; a second pass drops kept points whose neighbours see each other.
    Each accepted segment is checked in full.
    """
    xy = np.asarray(points)

    def valid(i: int, j: int) -> bool:
        return _keeps_clearance(grid, free, clear, xy[i:j + 1], path_clear[i:j + 1], clearance)

    kept = [0]
    last = len(points) - 1
    while kept[-1] < last:
        i = kept[-1]
        good, step = i + 1, 1
        while good < last:
            probe = min(good + step, last)
            if not valid(i, probe):
                bad = probe
                while bad - good > 1:
                    mid = (good + bad) // 2
                    good, bad = (mid, bad) if valid(i, mid) else (good, mid)
                break
            good, step = probe, step * 2
        kept.append(good)
    k = 1
    while k < len(kept) - 1:                               # second pass: drop needless corners
        if valid(kept[k - 1], kept[k + 1]):
            del kept[k]
        else:
            k += 1
    return [points[k] for k in kept]


def _keeps_clearance(grid: Grid, free: np.ndarray, clear: np.ndarray, path: np.ndarray,
                     path_clear: np.ndarray, clearance: float) -> bool:
    """Whether the straight segment from ``path[0]`` to ``path[-1]`` may replace ``path`` (points
    (n, 2) whose clearances, capped at ``clearance``, are ``path_clear``).

    Every cell the segment touches must be free. Its clearance must reach, less a cell, what the
    path promises there: clearance changes at most a metre per metre, so a point q of the segment
    is held to min over path points p of (clearance at p + |q - p|), capped at ``clearance``. A
    segment may thus leave a doorway or pass one as the path did, but not cut along a wall or a
    piece of furniture that the path kept away from.
    """
    rows, cols, t = _segment_cells(grid, path[0], path[-1])
    if not free[rows, cols].all():
        return False
    res = grid.resolution
    floor = clearance - res
    low = clear[rows, cols] < floor                        # only these cells can fail
    if not low.any():
        return True
    rows, cols = rows[low], cols[low]
    q = path[0] + t[low, None] * (path[-1] - path[0])
    gap = np.hypot(q[:, None, 0] - path[None, :, 0], q[:, None, 1] - path[None, :, 1])
    need = np.minimum((gap + path_clear[None, :]).min(axis=1) - res, floor)
    # clearance is known at cell centres; at q it is at most that plus q's distance to the centre
    off_centre = np.hypot(q[:, 0] - grid.origin[0] - (cols + 0.5) * res,
                          q[:, 1] - grid.origin[1] - (rows + 0.5) * res)
    return bool((clear[rows, cols] + off_centre >= need).all())


def _segment_cells(grid: Grid, a: Point, b: Point) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rows, cols, t) of every cell the segment a-b touches, t in [0, 1] along it: the cells at each
    crossing of a grid line and between consecutive crossings (an exact supercover, corners
    included)."""
    res, (ox, oy) = grid.resolution, grid.origin
    ux, uy = (a[0] - ox) / res, (a[1] - oy) / res
    vx, vy = (b[0] - ox) / res - ux, (b[1] - oy) / res - uy
    ts = [np.array([0.0, 1.0])]
    for u, v in ((ux, vx), (uy, vy)):
        if v != 0.0:
            lines = np.arange(math.ceil(min(u, u + v)), math.floor(max(u, u + v)) + 1)
            ts.append((lines - u) / v)
    t = np.unique(np.concatenate(ts))
    t = np.concatenate([t, (t[:-1] + t[1:]) / 2])
    cols = np.floor(ux + vx * t).astype(np.intp)
    rows = np.floor(uy + vy * t).astype(np.intp)
    return rows, cols, t
