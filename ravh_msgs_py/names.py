"""Every ROS name of ravh_sim in one place: topics, services, frames and their message types.

The sim node, the behaviours, the recorder, the tests and users' code import these instead of
spelling strings, so a rename happens here once. With several agents, robot topics and frames are
prefixed by the agent name (``robot2/scan``, ``robot2/base_link``); the first agent uses the plain
names so single-robot users see the conventional ``/scan`` and ``base_link``.

Per agent (``robot2`` here; the first agent drops the prefix): frames ``robot2/odom``,
``robot2/base_link``, ``robot2/laser_link``, ``robot2/camera_link``, ``robot2/camera_optical_frame``
under the one shared ``map``; topics ``robot2/scan``, ``robot2/odom``, ``robot2/cmd_vel``,
``robot2/camera/...`` and service ``robot2/capture``. /clock, /tf, /tf_static, /map and the /ravh/
services are shared.

The ``map`` frame is the house model's x, y; its z=0 is the floor the robots drive on (the house
model's main floor level, which the model itself puts at z=-0.03: ground-truth JSON such as
/ravh/ground_truth and query answers keep the model's z, so subtract the floor's ``floor_z`` to
place them in ``map``). base_link lies on the floor (z=0), sensor frames above it at their mount
heights.
"""
from __future__ import annotations

from typing import Any

# ---------------------------------------------------------------- defaults
DEFAULT_AGENT = "robot"                            # the agent of the default settings (config/default.yaml)
DEFAULT_PROFILE = "giraff"                         # the robot profile an agent gets unless told (config/robots/)

# ---------------------------------------------------------------- frames (REP 105 / REP 103)
MAP_FRAME = "map"
ODOM_FRAME = "odom"
BASE_FRAME = "base_link"
LASER_FRAME = "laser_link"
CAMERA_FRAME = "camera_link"                       # x forward, z up (REP 103 body convention)
CAMERA_OPTICAL_FRAME = "camera_optical_frame"      # z forward, x right, y down (REP 103 optical)

# ---------------------------------------------------------------- topics: (name, message type)
CLOCK = "/clock"                                   # rosgraph_msgs/Clock, sim time
SCAN = "scan"                                      # sensor_msgs/LaserScan
COLOR_IMAGE = "camera/color/image_raw"             # sensor_msgs/Image rgb8
COLOR_INFO = "camera/color/camera_info"            # sensor_msgs/CameraInfo
COLOR_COMPRESSED = "camera/color/image_raw/compressed"  # sensor_msgs/CompressedImage jpeg
DEPTH_IMAGE = "camera/depth/image_raw"             # sensor_msgs/Image 32FC1 metres (REP 118)
DEPTH_INFO = "camera/depth/camera_info"            # sensor_msgs/CameraInfo
INSTANCE_IMAGE = "camera/instance/image_raw"       # sensor_msgs/Image 16UC1 instance ids
INSTANCE_LABELS = "camera/instance/labels"         # std_msgs/String JSON, latched
ODOM = "odom"                                      # nav_msgs/Odometry odom -> base_link (noisy)
GROUND_TRUTH_POSE = "ground_truth/pose"            # geometry_msgs/PoseStamped in map
ODOM_TRANSFORM = "odom/transform"                  # geometry_msgs/TransformStamped odom -> base_link
MAP_TO_ODOM = "map_to_odom"                        # geometry_msgs/TransformStamped map -> odom
ROOM = "ravh/room"                                 # std_msgs/String: the room the robot is in
CMD_VEL = "cmd_vel"                                # geometry_msgs/Twist (or TwistStamped by parameter)
CAPTURE_EVENT = "ravh/capture"                     # std_msgs/String JSON: a capture was published
CAPTURE_RECORDED = "ravh/capture_recorded"         # std_msgs/String JSON: a recorder stored a capture
STEP = "ravh/step"                                  # geometry_msgs/TwistStamped: lockstep command + time granted
MAP = "/map"                                       # nav_msgs/OccupancyGrid, latched: obstacle map at laser height
FREE_SPACE_MAP = "/ravh/free_space"                # nav_msgs/OccupancyGrid, latched: FREE where the robot's centre fits
GROUND_TRUTH = "/ravh/ground_truth"                # std_msgs/String JSON footprint, latched
TF = "/tf"                                         # tf2_msgs/TFMessage: odom -> base_link, map -> odom (see map_tf)
TF_STATIC = "/tf_static"                           # tf2_msgs/TFMessage, latched: every agent's sensor mounts
TF_STATIC_TOPIC = "tf_static/{child}"              # geometry_msgs/TransformStamped, latched: one mount each
DIAGNOSTICS = "/diagnostics"                       # diagnostic_msgs/DiagnosticArray: the sim's health, 1 Hz

# ---------------------------------------------------------------- services
# JSON services use diagnostic_msgs/srv/AddDiagnostics, the one standard service shaped
# "string in -> bool + string out": request.load_namespace carries the JSON request,
# response.success says ok and response.message carries the JSON reply.
QUERY_SERVICE = "/ravh/query"                      # ground-truth query language (ravh_msgs_py.query)
APPEARANCE_SERVICE = "/ravh/appearance"            # appearance changes (ravh_msgs_py.appearance)
GET_MAP_SERVICE = "/ravh/get_map"                  # nav_msgs/srv/GetMap: the obstacle map (/map)
GET_FREE_SPACE_SERVICE = "/ravh/get_free_space"    # nav_msgs/srv/GetMap: the inflated free space
GET_PLAN_SERVICE = "/ravh/get_plan"                # nav_msgs/srv/GetPlan
CAPTURE_SERVICE = "capture"                        # std_srvs/srv/Trigger: one synchronised capture now
RESET_SERVICE = "/ravh/reset"                      # std_srvs/srv/Trigger: agents back to their start

JSON_SERVICE_TYPE = "diagnostic_msgs/srv/AddDiagnostics"


def agent_name(base: str, agent: str, first: bool) -> str:
    """A robot topic, service or frame name for ``agent``: plain for the first agent, prefixed after."""
    if first or base.startswith("/"):
        return base
    return f"{agent}/{base}"


def footprint_agents(footprint: dict[str, Any]) -> list[str]:
    """The agents' names in the sim's order, from the footprint on /ravh/ground_truth: the first of them
    uses the plain names, whatever it is called."""
    return [str(a["name"]) for a in footprint.get("settings", {}).get("agents", [])]
