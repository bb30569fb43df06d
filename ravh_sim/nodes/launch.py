"""The ROS executables of the package, by name: what ``ros2 run ravh_sim NAME`` and ``ravh NAME`` start."""
from __future__ import annotations

import importlib
import sys

NODES = {
    "sim": "ravh_sim.nodes.sim_node",
    "recorder": "ravh_sim.nodes.recorder_node",
    "wanderer": "ravh_sim.nodes.wanderer_node",
    "grid": "ravh_sim.nodes.grid_node",
    "teleop": "ravh_sim.nodes.teleop_node",
    "probe": "ravh_sim.nodes.probe_node",
}


def main(name: str, argv: list[str] | None = None) -> int:
    """Run node ``name`` with ``argv`` (default: this process's arguments after the program name)."""
    module = importlib.import_module(NODES[name])
    return module.main([name, *(sys.argv[1:] if argv is None else argv)])
