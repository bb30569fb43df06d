"""Appearance-based localization: match a route's images against a map's, fused with odometry.

The map is a set of images with known poses (a grid raid); the route is a sequence of images with
odometry between them. The method is a discrete Bayes (histogram) filter whose states are the map
images' poses, kept simple so that the descriptor is what gets compared:

* **measurement**: a route image's cosine similarity s_i to each map image i gives the likelihood
  exp((s_i - max s) / :data:`TEMPERATURE`): the nearest map images in descriptor space get the weight;
* **motion**: the belief moves with the odometry step: the belief of image i goes to the images j
  near i's pose moved by the step, with a Gaussian kernel of :data:`SPREAD_M` m and
  :data:`SPREAD_DEG` degrees (the grid's spacing and heading steps), plus :data:`FLOOR` of
  uniform belief so a wrong lock can recover;
* **estimate**: the belief-weighted mean pose (circular mean for the heading) of the map images
  within :data:`ESTIMATE_RADIUS_M` m of the most believed one.

The odometry is synthetic: the true motion between consecutive route poses plus zero-mean Gaussian
noise of :data:`ODOMETRY_SIGMA` (metres on x and y, degrees on the heading) per step (paper §5.5).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ravh_sim.poses import relative

TEMPERATURE = 0.02
SPREAD_M = 0.25
SPREAD_DEG = 25.0
FLOOR = 1e-3
REACH = 3.0                           # kernel widths beyond which belief is not moved
MAX_STEP_M, MAX_TURN_DEG = 0.5, 45.0  # odometry steps up to these use the precomputed pairs
ESTIMATE_RADIUS_M = 0.75
ODOMETRY_SIGMA = (0.06, 1.0)          # m, deg


def noisy_odometry(poses: np.ndarray, rng: np.random.Generator,
                   sigma: tuple[float, float] = ODOMETRY_SIGMA) -> np.ndarray:
    """(T-1, 3) odometry steps (dx, dy, dyaw in the robot frame) between consecutive ``poses``
    (T, 3), each corrupted by zero-mean Gaussian noise ``sigma`` (m, deg)."""
    steps = np.array([relative(tuple(a), tuple(b)) for a, b in zip(poses[:-1], poses[1:])]).reshape(-1, 3)
    noise = rng.normal(0.0, 1.0, steps.shape) * [sigma[0], sigma[0], math.radians(sigma[1])]
    return steps + noise


@dataclass
class Localizer:
    """The map: (N, D) normalised descriptors and their (N, 3) poses."""
    descriptors: np.ndarray
    poses: np.ndarray

    def __post_init__(self) -> None:
        """The (from, to) pairs of map images a step of at most MAX_STEP_M / MAX_TURN_DEG can move
        belief between (beyond REACH kernel widths the kernel is negligible): the motion update
        then costs the pairs, not N squared."""
        x, y, yaw = self.poses.T
        near = np.hypot(x[:, None] - x[None], y[:, None] - y[None]) <= REACH * SPREAD_M + MAX_STEP_M
        near &= np.abs(_wrap(yaw[None] - yaw[:, None])) <= math.radians(REACH * SPREAD_DEG + MAX_TURN_DEG)
        self._from, self._to = np.nonzero(near)

    def localize(self, route_descriptors: np.ndarray, odometry: np.ndarray) -> np.ndarray:
        """(T, 3) pose estimates for the route (see the module for the method)."""
        similarity = route_descriptors @ self.descriptors.T
        belief = np.full(len(self.poses), 1.0 / len(self.poses))
        estimates = np.zeros((len(route_descriptors), 3))
        for t, sims in enumerate(similarity):
            if t > 0:
                belief = self._move(belief, odometry[t - 1])
            belief = belief * np.exp((sims - sims.max()) / TEMPERATURE)
            belief /= belief.sum()
            estimates[t] = self._estimate(belief)
        return estimates

    def _move(self, belief: np.ndarray, step: np.ndarray) -> np.ndarray:
        """The belief after an odometry step: each image's share spread over the images near its
        pose moved by the step."""
        x, y, yaw = self.poses.T
        c, s = np.cos(yaw), np.sin(yaw)
        moved = np.column_stack((x + c * step[0] - s * step[1], y + s * step[0] + c * step[1], yaw + step[2]))
        if math.hypot(step[0], step[1]) <= MAX_STEP_M and abs(_wrap(step[2])) <= math.radians(MAX_TURN_DEG):
            i, j = self._from, self._to
        else:                                                  # an unusually long step: every pair
            i, j = (a.ravel() for a in np.indices((len(x), len(x))))
        d2 = ((moved[i, 0] - x[j]) ** 2 + (moved[i, 1] - y[j]) ** 2) / SPREAD_M ** 2
        kernel = np.exp(-0.5 * (d2 + (_wrap(moved[i, 2] - yaw[j]) / math.radians(SPREAD_DEG)) ** 2))
        row = np.bincount(i, weights=kernel, minlength=len(x))
        out = np.bincount(j, weights=kernel * (belief / np.maximum(row, 1e-300))[i], minlength=len(x))
        return (1.0 - FLOOR) * out / out.sum() + FLOOR / len(out)

    def _estimate(self, belief: np.ndarray) -> tuple[float, float, float]:
        best = self.poses[int(np.argmax(belief))]
        near = np.hypot(self.poses[:, 0] - best[0], self.poses[:, 1] - best[1]) <= ESTIMATE_RADIUS_M
        w = belief[near] / belief[near].sum()
        x, y, yaw = self.poses[near].T
        return (float(w @ x), float(w @ y), math.atan2(float(w @ np.sin(yaw)), float(w @ np.cos(yaw))))


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def errors(estimates: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per step: position error (m) and absolute heading error (deg)."""
    position = np.hypot(estimates[:, 0] - truth[:, 0], estimates[:, 1] - truth[:, 1])
    rotation = np.degrees(np.abs(_wrap(estimates[:, 2] - truth[:, 2])))
    return position, rotation
