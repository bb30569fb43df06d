"""Core values <-> ROS messages: each kind converts to a message and back to the same message."""
from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from ravh_sim.nav.grid import Grid
from ravh_sim.nodes import convert
from ravh_sim.sensors.readings import CameraInfo, Scan

HDR = convert.header(12.25, "robot2/camera_optical_frame")
K = (548.6, 0.0, 320.0, 0.0, 568.4, 240.0, 0.0, 0.0, 1.0)
INFO = CameraInfo("robot2/camera_optical_frame", 640, 480, "plumb_bob", (0.1, -0.02, 0.0, 0.001, 0.0), K,
                  tuple(np.eye(3).ravel()), K[:3] + (0.0,) + K[3:6] + (0.0,) + K[6:] + (0.0,))


def _scan(n: int = 360) -> Scan:
    ranges = np.linspace(0.3, 8.0, n, dtype=np.float32)
    ranges[0], ranges[1] = np.inf, -np.inf
    inc = 2 * math.pi / n
    return Scan("laser_link", -math.pi, -math.pi + (n - 1) * inc, inc, 0.0, 0.1, 0.05, 30.0, ranges)


SENSOR_VALUES = {
    "rgb8": np.random.default_rng(0).integers(0, 255, (4, 5, 3), dtype=np.uint8),
    "32FC1": np.array([[0.5, np.nan, 3.0], [1.25, 2.0, np.inf]], np.float32),
    "16UC1": np.array([[0, 7, 65535], [12, 0, 300]], np.uint16),
    "jpeg": cv2.imencode(".jpg", np.random.default_rng(1).integers(0, 255, (48, 64, 3), dtype=np.uint8))[1].tobytes(),
    "camera_info": INFO,
    "laser_scan": _scan(),
}


def test_every_kind_has_a_value_here():
    assert set(SENSOR_VALUES) == set(convert.KINDS)


@pytest.mark.parametrize("kind", sorted(SENSOR_VALUES))
def test_sensor_kinds_round_trip(kind):
    conv = convert.KINDS[kind]
    msg = conv.to_message(SENSOR_VALUES[kind], HDR)
    assert isinstance(msg, conv.msg_type) and msg.header == HDR
    value = conv.from_message(msg)
    again = conv.to_message(value, HDR)
    assert again == msg
    if kind == "jpeg":                       # still a JPEG of the same picture
        assert value == SENSOR_VALUES[kind] and cv2.imdecode(np.frombuffer(value, np.uint8), 1).shape == (48, 64, 3)
    if isinstance(value, np.ndarray):
        assert value.dtype == SENSOR_VALUES[kind].dtype
        assert np.array_equal(value, SENSOR_VALUES[kind], equal_nan=True)


def test_images_keep_their_layout_and_stamp():
    m = convert.image(SENSOR_VALUES["rgb8"], "rgb8", HDR)
    assert (m.width, m.height, m.step, m.encoding) == (5, 4, 15, "rgb8")
    assert (m.header.stamp.sec, m.header.stamp.nanosec) == (12, 250_000_000)
    d = convert.image(SENSOR_VALUES["32FC1"], "32FC1", HDR)
    assert d.step == 12


def test_padded_image_rows_are_cut():
    m = convert.image(SENSOR_VALUES["16UC1"], "16UC1", HDR)
    m.step, m.data = 8, [b for row in np.asarray(m.data).reshape(2, 6) for b in (*row, 0, 0)]
    assert np.array_equal(convert.image_array(m), SENSOR_VALUES["16UC1"])


def test_camera_info_fields():
    msg = convert.camera_info(INFO, HDR)
    assert list(msg.k) == list(K) and msg.p[3] == 0.0 and msg.p[0] == 548.6
    assert msg.distortion_model == "plumb_bob" and list(msg.d) == list(INFO.D)
    assert convert.camera_info_of(msg) == INFO           # frame from the header


def test_laser_scan_counting_rule_and_values():
    msg = convert.laser_scan(_scan(), HDR)
    assert len(msg.ranges) == round((msg.angle_max - msg.angle_min) / msg.angle_increment) + 1 == 360
    assert math.isinf(msg.ranges[0]) and msg.ranges[1] == -math.inf and msg.time_increment == 0.0
    back = convert.scan_of(msg)
    assert back.ranges.dtype == np.float32 and np.array_equal(back.ranges, _scan().ranges)
    assert back.angle_min == pytest.approx(-math.pi) and back.range_max == 30.0


def test_occupancy_grid_round_trip():
    grid = Grid(np.array([[0, 100, -1], [-1, 0, 100]], np.int8), (1.5, -2.0), 0.05)
    msg = convert.occupancy_grid(grid, convert.header(3.0, "map"), 3.0)
    assert list(msg.data) == [0, 100, -1, -1, 0, 100] and (msg.info.width, msg.info.height) == (3, 2)
    back = convert.grid_of(msg)
    assert np.array_equal(back.data, grid.data) and back.origin == (1.5, -2.0) and back.resolution == 0.05
    assert convert.occupancy_grid(back, msg.header, 3.0) == msg


def test_poses_and_odometry_round_trip():
    pose = (1.25, -3.5, 2.0)
    msg = convert.pose_stamped(pose, convert.header(1.0, "map"))
    assert convert.pose_of(msg.pose) == pytest.approx(pose)
    assert convert.pose_stamped(convert.pose_of(msg.pose), msg.header) == msg
    odom = convert.odometry(pose, 0.2, -0.4, convert.header(1.0, "odom"), "base_link", (0.06, 0.01))
    (p, v, w) = convert.odometry_of(odom)
    assert p == pytest.approx(pose) and (v, w) == (0.2, -0.4)
    assert convert.odometry(p, v, w, odom.header, "base_link", (0.06, 0.01)) == odom


def test_transforms_round_trip():
    tf = convert.transform(convert.header(0.5, "base_link"), "laser_link", (0.0, 0.1, 0.25), (0.0, 0.0, 0.6, 0.8))
    parent, child, xyz, quat = convert.transform_of(tf)
    assert (parent, child, xyz, quat) == ("base_link", "laser_link", (0.0, 0.1, 0.25), (0.0, 0.0, 0.6, 0.8))
    assert convert.transform(tf.header, child, xyz, quat) == tf
    flat = convert.transform_2d(convert.header(0.5, "odom"), "base_link", (1.0, 2.0, -0.5))
    _, _, (x, y, z), (qx, qy, qz, qw) = convert.transform_of(flat)
    assert (x, y, z) == (1.0, 2.0, 0.0) and 2 * math.atan2(qz, qw) == pytest.approx(-0.5)


def test_stamps_round_trip():
    for t in (0.0, 12.25, 1e5 + 0.001):
        assert convert.seconds(convert.stamp(t)) == pytest.approx(t, abs=1e-9)
