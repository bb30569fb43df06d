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

from ravh_sim.robot.robot import relative

TEMPERATURE = 0.02
SPREAD_M = 0.25
SPREAD_DEG = 25.0
FLOOR = 1e-3
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
        x, y, yaw = self.poses.T
        c, s = np.cos(yaw), np.sin(yaw)
        moved = np.column_stack((x + c * step[0] - s * step[1], y + s * step[0] + c * step[1], yaw + step[2]))
        d2 = ((moved[:, None, 0] - x[None]) ** 2 + (moved[:, None, 1] - y[None]) ** 2) / SPREAD_M ** 2
        turn = (moved[:, None, 2] - yaw[None] + np.pi) % (2 * np.pi) - np.pi
        kernel = np.exp(-0.5 * (d2 + (turn / math.radians(SPREAD_DEG)) ** 2))
        kernel /= kernel.sum(axis=1, keepdims=True)
        out = belief @ kernel
        return (1.0 - FLOOR) * out / out.sum() + FLOOR / len(out)

    def _estimate(self, belief: np.ndarray) -> tuple[float, float, float]:
        best = self.poses[int(np.argmax(belief))]
        near = np.hypot(self.poses[:, 0] - best[0], self.poses[:, 1] - best[1]) <= ESTIMATE_RADIUS_M
        w = belief[near] / belief[near].sum()
        x, y, yaw = self.poses[near].T
        return (float(w @ x), float(w @ y), math.atan2(float(w @ np.sin(yaw)), float(w @ np.cos(yaw))))


def errors(estimates: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per step: position error (m) and absolute heading error (deg)."""
    position = np.hypot(estimates[:, 0] - truth[:, 0], estimates[:, 1] - truth[:, 1])
    rotation = np.degrees(np.abs((estimates[:, 2] - truth[:, 2] + np.pi) % (2 * np.pi) - np.pi))
    return position, rotation
