"""Core values to ROS messages: the only place that knows both numpy arrays and message fields.

Kept free of node state so each conversion is a small pure function, unit-tested without a ROS graph.
Large arrays are copied with ``array.array.frombytes`` (0.1 ms for an rgb8 frame vs ~1 ms through a
Python list, measured here).
"""
from __future__ import annotations

import array
import math
from collections.abc import Sequence

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Pose, PoseStamped, Quaternion, TransformStamped
from nav_msgs.msg import OccupancyGrid, Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, LaserScan
from std_msgs.msg import Header

from ravh_sim.nav.grid import Grid
from ravh_sim.poses import Pose2D, quaternion_from_yaw


def stamp(seconds: float) -> Time:
    sec = int(math.floor(seconds))
    return Time(sec=sec, nanosec=int(round((seconds - sec) * 1e9)) % 1_000_000_000)


def header(seconds: float, frame_id: str) -> Header:
    return Header(stamp=stamp(seconds), frame_id=frame_id)


def clock(seconds: float) -> Clock:
    return Clock(clock=stamp(seconds))


def _bytes(a: np.ndarray) -> array.array:
    out = array.array("B")
    out.frombytes(np.ascontiguousarray(a).view(np.uint8).reshape(-1).data)
    return out


def image(a: np.ndarray, encoding: str, hdr: Header) -> Image:
    """An Image from an (H, W[, C]) array; ``encoding`` e.g. rgb8, 32FC1, 16UC1."""
    a = np.ascontiguousarray(a)
    height, width = a.shape[:2]
    msg = Image(header=hdr, height=height, width=width, encoding=encoding,
                is_bigendian=0, step=int(a.strides[0]))
    msg.data = _bytes(a)
    return msg


def compressed(jpeg: bytes, hdr: Header) -> CompressedImage:
    msg = CompressedImage(header=hdr, format="rgb8; jpeg compressed bgr8")
    msg.data = array.array("B", jpeg)
    return msg


def camera_info(k: np.ndarray, width: int, height: int, hdr: Header,
                d: Sequence[float] = (0.0, 0.0, 0.0, 0.0, 0.0)) -> CameraInfo:
    """CameraInfo for a pinhole camera (plumb_bob distortion ``d``; P = [K | 0] for a mono camera)."""
    k = np.asarray(k, dtype=float)
    p = np.zeros((3, 4))
    p[:, :3] = k
    return CameraInfo(header=hdr, width=width, height=height, distortion_model="plumb_bob",
                      d=[float(x) for x in d], k=k.reshape(-1).tolist(),
                      r=np.eye(3).reshape(-1).tolist(), p=p.reshape(-1).tolist())


def laser_scan(ranges: np.ndarray, angle_min: float, angle_increment: float, range_min: float,
               range_max: float, scan_time: float, hdr: Header) -> LaserScan:
    n = len(ranges)
    msg = LaserScan(header=hdr, angle_min=float(angle_min),
                    angle_max=float(angle_min + (n - 1) * angle_increment),
                    angle_increment=float(angle_increment), time_increment=0.0,
                    scan_time=float(scan_time), range_min=float(range_min), range_max=float(range_max))
    msg.ranges = array.array("f", np.asarray(ranges, dtype=np.float32).tobytes())
    return msg


def occupancy_grid(grid: Grid, hdr: Header, map_load_time: float) -> OccupancyGrid:
    msg = OccupancyGrid(header=hdr)
    msg.info.map_load_time = stamp(map_load_time)
    msg.info.resolution = float(grid.resolution)
    msg.info.height, msg.info.width = grid.shape
    msg.info.origin.position.x, msg.info.origin.position.y = map(float, grid.origin)
    msg.info.origin.orientation.w = 1.0
    msg.data = array.array("b", np.ascontiguousarray(grid.data, dtype=np.int8).tobytes())
    return msg


def yaw_quaternion(yaw: float) -> Quaternion:
    x, y, z, w = quaternion_from_yaw(yaw)
    return Quaternion(x=x, y=y, z=z, w=w)


def pose_2d(p: Pose2D, z: float = 0.0) -> Pose:
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = float(p[0]), float(p[1]), float(z)
    pose.orientation = yaw_quaternion(p[2])
    return pose


def pose_stamped(p: Pose2D, hdr: Header, z: float = 0.0) -> PoseStamped:
    return PoseStamped(header=hdr, pose=pose_2d(p, z))


def transform(parent_hdr: Header, child: str, xyz: Sequence[float], quat_xyzw: Sequence[float]) -> TransformStamped:
    t = TransformStamped(header=parent_hdr, child_frame_id=child)
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = map(float, xyz)
    q = t.transform.rotation
    q.x, q.y, q.z, q.w = map(float, quat_xyzw)
    return t


def transform_2d(parent_hdr: Header, child: str, p: Pose2D) -> TransformStamped:
    return transform(parent_hdr, child, (p[0], p[1], 0.0), quaternion_from_yaw(p[2]))


def odometry(p: Pose2D, v: float, w: float, hdr: Header, child: str,
             pose_sigma: tuple[float, float] = (0.0, 0.0)) -> Odometry:
    """Odometry in ``hdr.frame_id`` (odom) with twist in ``child`` (base_link); the covariance
    diagonal carries the configured noise so consumers can weight it."""
    msg = Odometry(header=hdr, child_frame_id=child)
    msg.pose.pose = pose_2d(p)
    cov = [0.0] * 36
    cov[0] = cov[7] = pose_sigma[0] ** 2
    cov[35] = pose_sigma[1] ** 2
    msg.pose.covariance = cov
    msg.twist.twist.linear.x = float(v)
    msg.twist.twist.angular.z = float(w)
    return msg
