"""The obstacle map: what a ROS map_server would load for this house (published as /map).

It is the uninflated map of :func:`ravh_sim.nav.freespace.obstacles`, from the same obstacle source
the robot's free space is built from, cut at the laser's height: walls, closed doors and the
footprints of everything from the floor up to the laser plane are OCCUPIED (100), known floor FREE
(0), outside the house UNKNOWN (-1). Laser endpoints land on its occupied cells, so AMCL's likelihood
field and Nav2's costmaps (which inflate it themselves) see the house as a real map of it; objects
lower than the laser plane are kept because the robot would bump into them.

The robot's own planner and behaviours use the inflated free space instead (``Navigation.map``,
topic ``/ravh/free_space``).
"""
from __future__ import annotations

from collections.abc import Mapping

from ravh_sim.nav.freespace import obstacles
from ravh_sim.nav.grid import Grid
from ravh_sim.world.house import House

LASER_PLANE_MARGIN = 0.02
"""m above the laser plane still counted, so a shape whose top is exactly at laser height is in."""


def obstacle_map(house: House, door_open: Mapping[str, bool], models: Mapping[str, int] | None,
                 laser_height: float, resolution: float) -> Grid:
    """Known floor FREE, obstacles up to ``laser_height`` (+ a margin) OCCUPIED, outside UNKNOWN."""
    return obstacles(house, door_open, models, height=laser_height + LASER_PLANE_MARGIN, resolution=resolution)
