"""Poses and rotations without pybullet, checked against pybullet's own conversions."""
from __future__ import annotations

import math

import numpy as np
import pybullet as pb
import pytest

from ravh_sim.poses import (
    matrix_from_quaternion,
    pose_matrix,
    quaternion_from_matrix,
    quaternion_from_yaw,
    rotation_y,
    rotation_z,
)


@pytest.mark.parametrize("seed", range(20))
def test_matrix_from_quaternion_matches_pybullet_and_round_trips(seed):
    q = np.random.default_rng(seed).normal(size=4)
    q = tuple(float(v) for v in q / np.linalg.norm(q))
    matrix = matrix_from_quaternion(q)
    assert np.allclose(matrix, np.reshape(pb.getMatrixFromQuaternion(q), (3, 3)), atol=1e-12)
    assert np.allclose(matrix @ matrix.T, np.eye(3), atol=1e-12)
    back = quaternion_from_matrix(matrix)
    assert np.allclose(back, q, atol=1e-9) or np.allclose(back, [-v for v in q], atol=1e-9)


@pytest.mark.parametrize("yaw", [0.3, -2.0, 3.1])
def test_rotation_z_is_the_yaw_quaternion_and_pose_matrix_appends_the_position(yaw):
    assert np.allclose(rotation_z(yaw), matrix_from_quaternion(quaternion_from_yaw(yaw)), atol=1e-12)
    pose = pose_matrix((1.0, 2.0, 3.0), quaternion_from_yaw(yaw))
    assert np.allclose(pose[:, :3], rotation_z(yaw), atol=1e-12) and pose[:, 3].tolist() == [1.0, 2.0, 3.0]


def test_quarter_turns_are_exact_and_pitch_tips_x_down():
    assert rotation_z(math.pi / 2).tolist() == [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    assert (rotation_z(-math.pi) @ (1.0, 0.0, 0.0)).tolist() == [-1.0, 0.0, 0.0]
    assert np.allclose(rotation_y(0.5) @ (1.0, 0.0, 0.0), (math.cos(0.5), 0.0, -math.sin(0.5)))
