"""The obstacle map: what a ROS map_server would load for this house (published as /map).

It is the house cut at the laser's height, as a SLAM would build it from the sim's own scans: what
the laser can hit there is OCCUPIED (100), the known floor FREE (0), outside the house UNKNOWN (-1).
What the laser can hit is the geometry the pybullet world collides with (:mod:`ravh_sim.world.scene`):
wall pieces, closed door leaves and their jambs, the convex hulls of procedural furniture parts
(legs, slats, pedestals) and the triangles of furniture-library models, each cut by the horizontal
plane at the laser's height above its room's floor (:meth:`ravh_sim.world.solids.Placed.section`).
The cut segments are drawn as lines one cell wide, so a laser endpoint lands on an occupied cell or
next to one, and the laser sees between legs where the map does too; AMCL's likelihood field and
Nav2's costmaps (which inflate it themselves) then agree with the sensor they localise with.

Cells enclosed by one object's cut (inside a cabinet's outline, a leg, a closed sofa base) are
OCCUPIED too, as map_server maps draw walls solid: the laser never reaches them and no robot stands
there (a SLAM map would leave them UNKNOWN; an outline open on one side, like a shelf's front, is not
closed and stays as cut). Objects entirely below the laser plane (a low stool, a rug) and parts above
it (a table top) are not in this map, because the laser does not see them. Dressing objects that
collide (:mod:`ravh_sim.world.dressing`: floor plants, curtains...) are cut like furniture.

The robot's own planner and behaviours use the inflated free space instead (``Navigation.map``,
topic ``/ravh/free_space``, :mod:`ravh_sim.nav.freespace`): the boxes of everything the robot's body
would bump into, from the floor to its height, so it still keeps off low furniture that /map leaves out.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import cv2
import numpy as np

from ravh_sim.nav.freespace import SCALE, SHIFT, fill_box, map_start, pixels, wall_box
from ravh_sim.nav.grid import OCCUPIED, Grid
from ravh_sim.world.dressing import Dressed
from ravh_sim.world.house import House
from ravh_sim.world.solids import object_parts
from ravh_sim.world.structure import solid_walls

UNSEEN_TYPES = frozenset({"Station"})
"""Object types the laser cannot hit (the world's ``NON_SOLID_TYPES``: the robot starts on its station)."""


def obstacle_map(house: House, door_open: Mapping[str, bool], models: Mapping[str, int] | None,
                 laser_height: float, resolution: float, margin: float = 0.5,
                 dressed: Sequence[Dressed] = ()) -> Grid:
    """Known floor FREE, what the laser at ``laser_height`` above the floor hits OCCUPIED, outside
    UNKNOWN; doors, models and dressing as :func:`ravh_sim.nav.freespace.obstacles` takes them, on the
    same grid."""
    open_state, models, grid = map_start(house, door_open, models, resolution, margin, laser_height=laser_height)
    hit = np.zeros(grid.shape, np.uint8)
    floor_z = {room.id: room.floor_z for room in house.rooms}
    for wall in (w for room in house.rooms for w in solid_walls(house, room.id)):
        if wall.z0 <= floor_z[wall.room] + laser_height <= wall.z1:
            fill_box(hit, wall_box(wall), grid)
    for obj in house.objects:
        if obj.type in UNSEEN_TYPES or open_state.get(obj.id, False):      # an open door's leaf is away
            continue
        placed = object_parts(house, obj, models.get(obj.id))
        _draw_section(hit, placed.section(floor_z[obj.room] + laser_height), grid)
    for item in dressed:
        if item.slot.collides:
            _draw_section(hit, item.placed().section(floor_z[item.slot.room] + laser_height), grid)
    grid.data[hit > 0] = OCCUPIED
    return grid


def _draw_section(mask: np.ndarray, segments: np.ndarray, grid: Grid) -> None:
    """Set to 1 the cells of ``mask`` that one object's cut ``segments`` ((n, 2, 2) metres) cross, drawn
    as lines one cell wide, and the cells they enclose (a 4-connected flood from outside the object
    does not reach them)."""
    if not len(segments):
        return
    at = (segments.reshape(-1, 2) - np.asarray(grid.origin)) / grid.resolution - 0.5   # cell centres on integers
    c0, r0 = (math.floor(v) - 1 for v in at.min(axis=0))
    c1, r1 = (math.ceil(v) + 2 for v in at.max(axis=0))
    local = np.zeros((r1 - r0, c1 - c0), np.uint8)                      # an empty cell all round the cut
    ends = pixels(segments.reshape(-1, 2), grid) - np.array([c0, r0], np.int32) * SCALE
    cv2.polylines(local, list(ends.reshape(-1, 2, 2)), False, 1, lineType=cv2.LINE_8, shift=SHIFT)
    outside = np.zeros((local.shape[0] + 2, local.shape[1] + 2), np.uint8)
    cv2.floodFill(local.copy(), outside, (0, 0), 1, flags=4 | cv2.FLOODFILL_MASK_ONLY | (1 << 8))
    solid = outside[1:-1, 1:-1] == 0
    rows, cols = mask.shape
    rs, cs = slice(max(r0, 0), min(r1, rows)), slice(max(c0, 0), min(c1, cols))
    mask[rs, cs] |= solid[rs.start - r0:rs.stop - r0, cs.start - c0:cs.stop - c0].astype(np.uint8)
