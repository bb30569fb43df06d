"""A 2D occupancy grid over the house frame, the one map type every module exchanges.

Values follow nav_msgs/OccupancyGrid: 0 free, 100 occupied, -1 unknown (outside the house).
Row ``r``, column ``c`` covers x in [ox + c*res, ox + (c+1)*res) and y in [oy + r*res, ...): row 0 is
the lowest y, as in a ROS map (the picture is flipped only when drawn or written to PGM).
"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ravh_sim.world.geometry import points_in_polygon

FREE, OCCUPIED, UNKNOWN = 0, 100, -1


@dataclass
class Grid:
    data: np.ndarray               # (rows, cols) int8
    origin: tuple[float, float]    # (x, y) of the lower-left corner of cell (0, 0)
    resolution: float              # metres per cell

    @property
    def shape(self) -> tuple[int, int]:
        return self.data.shape

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """(row, col) of the cell containing (x, y); may lie outside the grid."""
        return (int(np.floor((y - self.origin[1]) / self.resolution)),
                int(np.floor((x - self.origin[0]) / self.resolution)))

    def center_of(self, row: int, col: int) -> tuple[float, float]:
        return (self.origin[0] + (col + 0.5) * self.resolution,
                self.origin[1] + (row + 0.5) * self.resolution)

    def inside(self, row: int, col: int) -> bool:
        return 0 <= row < self.data.shape[0] and 0 <= col < self.data.shape[1]

    def is_free(self, x: float, y: float) -> bool:
        r, c = self.cell_of(x, y)
        return self.inside(r, c) and self.data[r, c] == FREE

    def cell_centres(self) -> tuple[np.ndarray, np.ndarray]:
        """(xs, ys): the house-frame centre of every cell, each of the grid's shape."""
        indices = np.indices(self.data.shape)
        rows, cols = indices[0], indices[1]
        return (self.origin[0] + (cols + 0.5) * self.resolution,
                self.origin[1] + (rows + 0.5) * self.resolution)

    def polygons_mask(self, polygons) -> np.ndarray:
        """Cells whose centres lie inside any of ``polygons`` (a room's floor outlines)."""
        xs, ys = self.cell_centres()
        inside = np.zeros(self.data.shape, bool)
        for poly in polygons:
            inside |= points_in_polygon(xs, ys, poly)
        return inside


def distance_to_obstacle(grid: Grid) -> np.ndarray:
    """Metres (float32, grid shape) from each cell centre to the nearest non-FREE cell centre;
    0 on non-FREE cells. On an inflated map this is the clearance beyond the robot radius."""
    return distance_cells(grid.data) * np.float32(grid.resolution)


def distance_cells(data: np.ndarray) -> np.ndarray:
    """Cells from each cell centre to the nearest non-FREE cell centre (0 on non-FREE cells)."""
    free = (data == FREE).astype(np.uint8)
    return cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)


def reachable(grid: Grid, start: tuple[float, float], snap: float = np.inf) -> np.ndarray:
    """FREE cells connected to the free cell nearest ``start`` (within ``snap`` metres; all False if
    none). 4-connected, as the planner moves: its diagonal steps need both orthogonal cells free."""
    free = (grid.data == FREE).astype(np.uint8)
    rows, cols = np.nonzero(free)
    r, c = grid.cell_of(*start)
    if rows.size == 0:
        return np.zeros(grid.shape, bool)
    d2 = (rows - r) ** 2 + (cols - c) ** 2
    k = int(np.argmin(d2))
    if np.sqrt(d2[k]) * grid.resolution > snap + grid.resolution:
        return np.zeros(grid.shape, bool)
    _, labels = cv2.connectedComponents(free, connectivity=4)
    return labels == labels[rows[k], cols[k]]
