"""The example parameter files for standard ROS 2 tools (config/) name the sim's frames and topics."""
from __future__ import annotations

import yaml
from conftest import ROOT

from ravh_msgs_py import names as n


def node_params(path: str) -> dict[str, dict]:
    """node name -> ros__parameters, following nested namespaces (global_costmap: global_costmap: ...)."""
    found: dict[str, dict] = {}

    def walk(prefix: str, tree: dict) -> None:
        for key, value in tree.items():
            if key == "ros__parameters":
                found[prefix] = value
            elif isinstance(value, dict):
                walk(f"{prefix}/{key}" if prefix else key, value)
    walk("", yaml.safe_load((ROOT / path).read_text()))
    return found


def test_every_node_runs_on_sim_time():
    for path in ("config/slam_toolbox.yaml", "config/nav2.yaml"):
        for node, params in node_params(path).items():
            assert params.get("use_sim_time") is True, f"{path}: {node}"


def test_slam_toolbox_uses_the_sims_frames_and_scan():
    params = node_params("config/slam_toolbox.yaml")["slam_toolbox"]
    assert (params["map_frame"], params["odom_frame"], params["base_frame"]) == (n.MAP_FRAME, n.ODOM_FRAME,
                                                                                 n.BASE_FRAME)
    assert params["scan_topic"] == "/" + n.SCAN


def test_nav2_uses_the_sims_frames_and_topics():
    nodes = node_params("config/nav2.yaml")
    amcl = nodes["amcl"]
    assert (amcl["global_frame_id"], amcl["odom_frame_id"], amcl["base_frame_id"]) == (n.MAP_FRAME, n.ODOM_FRAME,
                                                                                       n.BASE_FRAME)
    assert amcl["scan_topic"] == n.SCAN and "/" + amcl["map_topic"] == n.MAP
    for costmap, frame in (("global_costmap/global_costmap", n.MAP_FRAME),
                           ("local_costmap/local_costmap", n.ODOM_FRAME)):
        params = nodes[costmap]
        assert params["global_frame"] == frame and params["robot_base_frame"] == n.BASE_FRAME
        for layer in params["plugins"]:
            if "observation_sources" in params[layer]:
                assert params[layer]["scan"]["topic"] == "/" + n.SCAN
    assert nodes["global_costmap/global_costmap"]["static_layer"]["map_topic"] == n.MAP
    assert nodes["collision_monitor"]["cmd_vel_out_topic"] == n.CMD_VEL
    assert nodes["bt_navigator"]["odom_topic"] == "/" + n.ODOM
