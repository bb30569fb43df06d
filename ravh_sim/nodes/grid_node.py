"""``ros2 run ravh_sim grid``: lattice nodes over the free area, a 360 degree turn with N captures at each."""
from __future__ import annotations

from typing import Any

from ravh_sim.behaviours.grid import GridSweep
from ravh_sim.behaviours.waypoints import grid_nodes
from ravh_sim.nodes.behaviour_node import BehaviourNode, common_args
from ravh_sim.nodes.common import run_node


def make_node(argv: list[str]) -> BehaviourNode:
    p = common_args("grid", "Grid behaviour: nodes every SPACING m, N captures in a full turn at each.")
    p.add_argument("--spacing", type=float, default=0.5, help="metres between lattice nodes")
    p.add_argument("--captures", type=int, default=10, help="captures per node (one every 360/N degrees)")
    p.add_argument("--max-nodes", type=int, default=0, help="stop after this many nodes (0: all)")
    args = p.parse_args(argv)

    def make(follower, layout, grid, start) -> Any:
        nodes = grid_nodes(layout, grid, start, args.spacing)
        return GridSweep(follower, nodes[:args.max_nodes] if args.max_nodes > 0 else nodes, args.captures)

    return BehaviourNode("grid", make, args.agent, args.profile, args.log, args.wait_recorder, args.lockstep)


def main(argv: list[str] | None = None) -> int:
    return run_node(make_node, argv)
