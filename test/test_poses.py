"""Poses and rotations without pybullet, checked against pybullet's own conversions."""
from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest

from ravh_sim.poses import matrix_from_quaternion, quaternion_from_matrix


@pytest.mark.parametrize("seed", range(20))
def test_matrix_from_quaternion_matches_pybullet_and_round_trips(seed):
    q = np.random.default_rng(seed).normal(size=4)
    q = tuple(float(v) for v in q / np.linalg.norm(q))
    matrix = matrix_from_quaternion(q)
    assert np.allclose(matrix, np.reshape(pb.getMatrixFromQuaternion(q), (3, 3)), atol=1e-12)
    assert np.allclose(matrix @ matrix.T, np.eye(3), atol=1e-12)
    back = quaternion_from_matrix(matrix)
    assert np.allclose(back, q, atol=1e-9) or np.allclose(back, [-v for v in q], atol=1e-9)
