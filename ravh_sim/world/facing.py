"""Pick which way a piece of furniture faces from the walls around it.

Why: the upstream houses give each object an upright box and a yaw, but not
which side of the box is its front.  Furniture stands with its back to the
nearest wall (a wardrobe, a sofa, a bed's headboard, a picture on a wall),
so the front is the box side opposite the side closest to a wall.

Facing indices follow ``furniture.build_model``: 0, 1, 2, 3 mean the front
looks along the box's local +x, +y, -x, -y.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

Point = tuple[float, float]
Segment = tuple[Point, Point]

PARALLEL_COS = np.cos(np.radians(30.0))
"""Walls closer than 30 degrees to a side's outward direction cannot be behind that side."""

TIE_DECIMALS = 6
"""Distances are compared at micrometre resolution so ties break by index, not by noise."""

FRONT_CLEARANCE = 0.3
"""Metres a front that must open (an appliance's door) needs before a wall or a blocker."""

SWAP_RATIO = 1.15
"""How much longer than the other a box axis must be before 'short'/'long' fronts care."""


SHORT_FRONT = frozenset({
    'Bathtub', 'Cabinet', 'Closet', 'Desk', 'Door', 'Dresser', 'Drying', 'Keyboard', 'Laptop', 'Lighter',
    'Microwave', 'Mirror', 'Picture', 'Shelf', 'Sofa', 'Standard', 'Towel', 'Tv', 'Wall', 'Washbasin'})
LONG_FRONT = frozenset({'Bed', 'Toilet'})
OPENING_FRONT = frozenset({'Dishwasher', 'Oven', 'Refrigerator', 'WashingMachine'})
"""Appliances: near-square boxes whose front is a door, so the side it is on is never swapped for a
better fit of a model's proportions, and it opens into the room (``choose_facing``'s blockers)."""


def front_axis(object_type: str) -> str:
    """Which box side a type's front belongs on: 'short', 'long', 'door' (an appliance's: any side,
    but the one chosen stays) or 'any' (see :func:`suits_box`).

    Pass it to :func:`choose_facing` so that, say, a wardrobe in a corner backs onto the wall
    behind its long side.
    """
    if object_type in OPENING_FRONT:
        return 'door'
    return 'short' if object_type in SHORT_FRONT else 'long' if object_type in LONG_FRONT else 'any'


def suits_box(front: str, size: Sequence[float] | np.ndarray, facing: int) -> bool:
    """Whether ``facing`` suits a type whose front belongs on a given side of its box.

    ``front`` is 'short' (the front looks across the box's short horizontal
    axis: wardrobes, sofas, pictures), 'long' (along the long axis: beds,
    toilets), 'door' or 'any' (both suit every facing).  Nearly square boxes
    suit every facing.
    """
    depth, width = (abs(size[0]), abs(size[1])) if facing % 2 == 0 else (abs(size[1]), abs(size[0]))
    if front == 'short':
        return depth <= SWAP_RATIO * width
    if front == 'long':
        return width <= SWAP_RATIO * depth
    return True


def choose_facing(center_xy: Sequence[float], yaw: float, size: Sequence[float],
                  wall_segments: Sequence[Segment], front: str = 'any',
                  blockers: Sequence[Segment] = ()) -> int:
    """Facing index whose front points away from the nearest wall.

    For each of the box's four sides, sweep the side outwards along its
    normal and measure how far it travels before touching a wall segment;
    the side with the shortest distance is the back.  ``front`` (see
    ``suits_box``) limits the choice to facings that suit the type, so a
    wardrobe in a corner backs onto the wall behind its long side even when
    the wall at its end is nearer.  With ``blockers`` (the edges of what
    stands beside an appliance), a front with a wall or a blocker closer
    than FRONT_CLEARANCE is left out where another suitable front is open:
    a washing machine in a corner beside a sink unit opens into the room,
    not into the wall or the unit.  Ties go to the lowest index; with no
    wall in reach the facing is the lowest suitable one.
    """
    suitable = [f for f in range(4) if suits_box(front, size, f)]  # never empty
    if blockers:
        ahead = side_distances(center_xy, yaw, size, [*wall_segments, *blockers])
        suitable = [f for f in suitable if ahead[f] >= FRONT_CLEARANCE] or suitable
    distances = side_distances(center_xy, yaw, size, wall_segments)
    backs = [(f + 2) % 4 for f in suitable]
    if not np.isfinite(distances[backs]).any():
        return suitable[0]
    rounded = np.round(distances, TIE_DECIMALS)
    return min(suitable, key=lambda f: (rounded[(f + 2) % 4], (f + 2) % 4))


def side_distances(center_xy: Sequence[float], yaw: float, size: Sequence[float],
                   wall_segments: Sequence[Segment]) -> np.ndarray:
    """Distance from each box side (+x, +y, -x, -y local) to the first wall in its sweep.

    Negative when a wall cuts into the box on that side; ``inf`` when the
    side's sweep meets no wall.
    """
    walls = np.asarray(wall_segments, np.float64).reshape(-1, 2, 2)
    if len(walls) == 0:
        return np.full(4, np.inf)
    angles = yaw + np.arange(4) * (np.pi / 2)
    normal = np.stack([np.cos(angles), np.sin(angles)], axis=1)  # (4, 2) outward
    tangent = np.stack([-normal[:, 1], normal[:, 0]], axis=1)
    half_depth = np.abs(np.array([size[0], size[1], size[0], size[1]], np.float64)) / 2
    half_width = np.abs(np.array([size[1], size[0], size[1], size[0]], np.float64)) / 2
    relative = walls - np.asarray(center_xy, np.float64)  # (S, 2, 2)
    ahead = np.einsum('sep,kp->kse', relative, normal)  # (4, S, 2) along the normal
    across = np.einsum('sep,kp->kse', relative, tangent)  # (4, S, 2) along the side
    lo, hi = _clip_to_band(across, half_width[:, None])
    a_lo = ahead[..., 0] + lo * (ahead[..., 1] - ahead[..., 0])
    a_hi = ahead[..., 0] + hi * (ahead[..., 1] - ahead[..., 0])
    reach = np.maximum(np.minimum(a_lo, a_hi), 0.0) - half_depth[:, None]
    direction = np.diff(walls, axis=1)[:, 0]
    length = np.linalg.norm(direction, axis=1)
    along = np.abs(direction @ normal.T).T / np.where(length > 0, length, 1.0)
    valid = (lo <= hi) & (np.maximum(a_lo, a_hi) >= 0.0) & (along < PARALLEL_COS) & (length > 0)
    return np.where(valid, reach, np.inf).min(axis=1)


def _clip_to_band(across: np.ndarray, half_width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Parameter interval [lo, hi] of each segment whose across-coordinate is within the band.

    ``across`` holds the two endpoints' coordinates (..., 2); the interval is
    empty (lo > hi) when the segment passes beside the side.
    """
    b0, b1 = across[..., 0], across[..., 1]
    delta = b1 - b0
    flat = np.abs(delta) < 1e-12
    safe = np.where(flat, 1.0, delta)
    t_minus = (-half_width - b0) / safe
    t_plus = (half_width - b0) / safe
    lo = np.where(flat, np.where(np.abs(b0) <= half_width, 0.0, 1.0), np.minimum(t_minus, t_plus))
    hi = np.where(flat, np.where(np.abs(b0) <= half_width, 1.0, 0.0), np.maximum(t_minus, t_plus))
    return np.maximum(lo, 0.0), np.minimum(hi, 1.0)
