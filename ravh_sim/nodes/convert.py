"""Core values <-> ROS messages, both ways: the only place that knows both numpy arrays and message fields.

Every node and test converts here: the sim node builds messages from the runtime's values, the
recorder and the behaviours turn messages back into arrays, grids and poses. Sensor topics are
converted by message kind (:data:`KINDS`, named by each port's topics in ravh_sim.sensors). Kept
free of node state so each conversion is a small pure function, unit-tested without a ROS graph.
Large arrays are copied with ``array.array.frombytes`` (0.1 ms for an rgb8 frame vs ~1 ms through a
Python list, measured here).
"""
from __future__ import annotations

import array
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Pose, PoseStamped, Quaternion, TransformStamped
from nav_msgs.msg import OccupancyGrid, Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, LaserScan
from std_msgs.msg import Header

from ravh_sim.nav.grid import Grid
from ravh_sim.poses import Pose2D, quaternion_from_yaw, yaw_from_quaternion
from ravh_sim.sensors import readings


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


def camera_info(info: readings.CameraInfo, hdr: Header) -> CameraInfo:
    """CameraInfo of a pinhole camera (frame from ``hdr``: the one the images are stamped in)."""
    return CameraInfo(header=hdr, width=info.width, height=info.height, distortion_model=info.distortion_model,
                      d=[float(x) for x in info.D], k=[float(x) for x in info.K],
                      r=[float(x) for x in info.R], p=[float(x) for x in info.P])


def laser_scan(scan: readings.Scan, hdr: Header) -> LaserScan:
    """The rays are cast at one instant: time_increment 0."""
    msg = LaserScan(header=hdr, angle_min=float(scan.angle_min), angle_max=float(scan.angle_max),
                    angle_increment=float(scan.angle_increment), time_increment=0.0,
                    scan_time=float(scan.scan_time), range_min=float(scan.range_min),
                    range_max=float(scan.range_max))
    msg.ranges = array.array("f", np.asarray(scan.ranges, dtype=np.float32).tobytes())
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


# ---------------------------------------------------------------------------- messages -> values

def seconds(t: Time) -> float:
    return t.sec + t.nanosec * 1e-9


def image_array(msg: Image) -> np.ndarray:
    """The pixels of an rgb8, 32FC1 or 16UC1 Image (row padding removed)."""
    dtype, channels = {"rgb8": (np.uint8, 3), "32FC1": (np.float32, 1), "16UC1": (np.uint16, 1)}[msg.encoding]
    row_bytes = msg.width * channels * np.dtype(dtype).itemsize
    rows = np.frombuffer(msg.data, np.uint8).reshape(msg.height, msg.step)[:, :row_bytes]
    a = np.ascontiguousarray(rows).view(dtype).reshape(msg.height, msg.width, channels)
    return a[:, :, 0] if channels == 1 else a


def jpeg_bytes(msg: CompressedImage) -> bytes:
    return bytes(msg.data)


def camera_info_of(msg: CameraInfo) -> readings.CameraInfo:
    return readings.CameraInfo(msg.header.frame_id, msg.width, msg.height, msg.distortion_model,
                               tuple(float(v) for v in msg.d), tuple(float(v) for v in msg.k),
                               tuple(float(v) for v in msg.r), tuple(float(v) for v in msg.p))


def scan_of(msg: LaserScan) -> readings.Scan:
    return readings.Scan(msg.header.frame_id, msg.angle_min, msg.angle_max, msg.angle_increment, msg.time_increment,
                         msg.scan_time, msg.range_min, msg.range_max, np.asarray(msg.ranges, np.float32))


def grid_of(msg: OccupancyGrid) -> Grid:
    data = np.array(msg.data, np.int8).reshape(msg.info.height, msg.info.width)
    return Grid(data, (msg.info.origin.position.x, msg.info.origin.position.y), msg.info.resolution)


def pose_of(pose: Pose) -> Pose2D:
    """(x, y, yaw) of a Pose on the floor (the yaw of its quaternion)."""
    return (pose.position.x, pose.position.y, yaw_from_quaternion(pose.orientation.z, pose.orientation.w))


def odometry_of(msg: Odometry) -> tuple[Pose2D, float, float]:
    """(pose in odom, v, w) of an Odometry."""
    return pose_of(msg.pose.pose), msg.twist.twist.linear.x, msg.twist.twist.angular.z


def transform_of(msg: TransformStamped) -> tuple[str, str, tuple[float, ...], tuple[float, ...]]:
    """(parent, child, xyz, quaternion xyzw) of a transform."""
    t, q = msg.transform.translation, msg.transform.rotation
    return msg.header.frame_id, msg.child_frame_id, (t.x, t.y, t.z), (q.x, q.y, q.z, q.w)


# ---------------------------------------------------------------------------- sensor message kinds

@dataclass(frozen=True)
class Kind:
    """A sensor topic's message type and its conversions (``Topic.kind`` in ravh_sim.sensors.ports)."""
    msg_type: type
    to_message: Callable[[Any, Header], Any]
    from_message: Callable[[Any], Any]


KINDS: dict[str, Kind] = {
    "rgb8": Kind(Image, lambda a, hdr: image(a, "rgb8", hdr), image_array),
    "32FC1": Kind(Image, lambda a, hdr: image(a, "32FC1", hdr), image_array),
    "16UC1": Kind(Image, lambda a, hdr: image(a, "16UC1", hdr), image_array),
    "jpeg": Kind(CompressedImage, compressed, jpeg_bytes),
    "camera_info": Kind(CameraInfo, camera_info, camera_info_of),
    "laser_scan": Kind(LaserScan, laser_scan, scan_of),
}
