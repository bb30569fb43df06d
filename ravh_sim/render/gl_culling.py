"""Frustum culling for the GL renderer: a CPU rasteriser pays for every triangle it is given, so only
the bodies whose boxes meet the view are drawn."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DrawRuns:
    """The vertex buffer as runs of one body's triangles of one pattern (the buffer is sorted by
    pattern, then body), each with its box in the house frame: what frustum culling draws or skips."""
    pattern: np.ndarray               # (R,) pattern drawn with
    first: np.ndarray                 # (R,) first vertex
    count: np.ndarray                 # (R,) vertices
    corners: np.ndarray               # (R, 8, 4) homogeneous corners of each run's box

    @staticmethod
    def of(vertices: np.ndarray, triangle_pattern: np.ndarray, drawn_as: int | None) -> DrawRuns:
        """Runs of a pattern-sorted buffer; ``drawn_as`` replaces every pattern (fast quality)."""
        instance = vertices[::3, 10].astype(np.int64)
        key = triangle_pattern.astype(np.int64) * (int(instance.max()) + 1) + instance
        starts = np.concatenate([[0], np.flatnonzero(np.diff(key)) + 1])
        ends = np.concatenate([starts[1:], [len(key)]])
        positions = vertices[:, :3].astype(np.float64)
        lo = np.minimum.reduceat(positions, 3 * starts)
        hi = np.maximum.reduceat(positions, 3 * starts)
        pick = np.array([[(i >> axis) & 1 for axis in range(3)] for i in range(8)], bool)
        corners = np.where(pick[None], hi[:, None, :], lo[:, None, :])
        corners = np.concatenate([corners, np.ones((*corners.shape[:2], 1))], axis=2)
        pattern = triangle_pattern[starts] if drawn_as is None else np.full(len(starts), drawn_as)
        return DrawRuns(pattern, 3 * starts, 3 * (ends - starts), corners)

    def visible(self, view_proj: np.ndarray) -> np.ndarray:
        """Runs whose box is not wholly outside one plane of the view frustum."""
        clip = self.corners @ view_proj.T                                     # (R, 8, 4)
        w = clip[..., 3]
        outside = [(clip[..., axis] > w).all(axis=1) | (clip[..., axis] < -w).all(axis=1) for axis in range(3)]
        return ~(outside[0] | outside[1] | outside[2])

    def spans(self, chosen: np.ndarray) -> list[tuple[int, int]]:
        """(first vertex, count) of the chosen runs, neighbours in the buffer merged into one draw."""
        index = np.flatnonzero(chosen)
        if not len(index):
            return []
        first, count = self.first[index], self.count[index]
        breaks = np.flatnonzero(first[1:] != first[:-1] + count[:-1]) + 1
        heads = np.concatenate([[0], breaks])
        tails = np.concatenate([breaks, [len(index)]]) - 1
        return [(int(first[h]), int(first[t] + count[t] - first[h])) for h, t in zip(heads, tails)]
