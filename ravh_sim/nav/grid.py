"""A 2D occupancy grid over the house frame, the one map type every module exchanges.

Values follow nav_msgs/OccupancyGrid: 0 free, 100 occupied, -1 unknown (outside the house).
Row ``r``, column ``c`` covers x in [ox + c*res, ox + (c+1)*res) and y in [oy + r*res, ...): row 0 is
the lowest y, as in a ROS map (the picture is flipped only when drawn or written to PGM).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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
