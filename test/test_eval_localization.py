"""The localization filter and the synthetic odometry on hand-made maps and routes."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ravh_sim.eval.localization import Localizer, errors, noisy_odometry
from ravh_sim.poses import compose


def _map(seed: int = 0):
    """Grid nodes every 0.5 m over 3 x 2 m, 10 headings each, a random unit descriptor per pose."""
    xs, ys = np.meshgrid(np.arange(0, 3.01, 0.5), np.arange(0, 2.01, 0.5))
    poses = np.array([(x, y, wrap) for x, y in zip(xs.ravel(), ys.ravel())
                      for wrap in (2 * math.pi * k / 10 - math.pi for k in range(10))])
    d = np.random.default_rng(seed).normal(size=(len(poses), 64))
    return poses, d / np.linalg.norm(d, axis=1, keepdims=True)


def test_odometry_steps_rebuild_the_path_and_noise_has_the_asked_sigma():
    poses = np.array([(0.0, 0.0, 0.0), (0.5, 0.0, 0.3), (0.9, 0.2, 1.0), (0.9, 0.7, 2.0)])
    steps = noisy_odometry(poses, np.random.default_rng(0), (0.0, 0.0))
    pose = tuple(poses[0])
    for step, truth in zip(steps, poses[1:]):
        pose = compose(pose, tuple(step))
        assert pose == pytest.approx(tuple(truth))
    still = np.zeros((20001, 3))
    noise = noisy_odometry(still, np.random.default_rng(1))
    assert noise[:, :2].std() == pytest.approx(0.06, rel=0.03)
    assert math.degrees(noise[:, 2].std()) == pytest.approx(1.0, rel=0.03)
    assert abs(noise.mean(axis=0)).max() < 0.002


def test_route_equal_to_a_map_trajectory_localizes_exactly():
    poses, descriptors = _map()
    route = np.arange(30, 90)                                  # a run of map images, in map order
    estimates = Localizer(descriptors, poses).localize(descriptors[route],
                                                       noisy_odometry(poses[route], np.random.default_rng(2)))
    position, rotation = errors(estimates, poses[route])
    assert position.max() < 1e-6 and rotation.max() < 1e-4


def test_odometry_carries_the_route_through_uninformative_images():
    poses, descriptors = _map()
    route = np.arange(30, 90)
    blind = descriptors[route].copy()
    blind[10:14] = 0.0                                         # images that match nothing (a wall, sky)
    estimates = Localizer(descriptors, poses).localize(blind, noisy_odometry(poses[route], np.random.default_rng(3)))
    position, rotation = errors(estimates, poses[route])
    assert position[10:14].max() < 0.3 and rotation[10:14].max() < 20
    assert position[25:].max() < 1e-6


def test_errors_wrap_headings():
    position, rotation = errors(np.array([[0.0, 0.0, math.pi - 0.01]]), np.array([[3.0, 4.0, -math.pi + 0.01]]))
    assert position[0] == pytest.approx(5.0) and rotation[0] == pytest.approx(math.degrees(0.02))


def test_motion_update_on_near_pairs_equals_the_full_one():
    poses, descriptors = _map()
    sparse = Localizer(descriptors, poses)
    dense = Localizer(descriptors, poses)
    dense._from, dense._to = (a.ravel() for a in np.indices((len(poses), len(poses))))
    belief = np.random.default_rng(4).random(len(poses))
    belief /= belief.sum()
    step = np.array([0.3, -0.1, 0.4])
    assert np.allclose(sparse._move(belief, step), dense._move(belief, step), rtol=1e-3, atol=0)   # 3 sigma cut
    assert len(sparse._from) < len(dense._from) / 2
