"""``ros2 run ravh_sim grid``: lattice nodes over the free area, a 360 degree turn with N captures at each."""
from __future__ import annotations

from typing import Any

from ravh_sim.behaviours.grid import GridSweep
from ravh_sim.behaviours.waypoints import NODE_RULES, PAPER_AGENT_RADIUS, grid_nodes, paper_grid_nodes
from ravh_sim.nav.grid import Grid
from ravh_sim.nodes.behaviour_node import BehaviourNode, common_args
from ravh_sim.nodes.common import run_node
from ravh_sim.robot.profile import RobotProfile


def make_node(argv: list[str]) -> BehaviourNode:
    p = common_args("grid", "Grid behaviour: nodes every SPACING m, N captures in a full turn at each.")
    p.add_argument("--spacing", type=float, default=0.5, help="metres between lattice nodes")
    p.add_argument("--captures", type=int, default=10, help="captures per node (one every 360/N degrees)")
    p.add_argument("--max-nodes", type=int, default=0, help="stop after this many nodes (0: all)")
    p.add_argument("--nodes", choices=NODE_RULES, default="paper",
                   help="paper: the original's lattice rule (the paper's node counts); cover: nodes on the "
                        "robot's own free space")
    args = p.parse_args(argv)

    def make(follower, layout, grid, start, footprint) -> Any:
        if args.nodes == "paper":
            nodes = paper_grid_nodes(layout, walkable_of(footprint, follower.profile), grid, start, args.spacing)
        else:
            nodes = grid_nodes(layout, grid, start, args.spacing)
        return GridSweep(follower, nodes[:args.max_nodes] if args.max_nodes > 0 else nodes, args.captures)

    return BehaviourNode("grid", make, args.agent, args.profile, args.log, args.wait_recorder, args.lockstep)


def walkable_of(footprint: dict[str, Any], profile: RobotProfile) -> Grid:
    """The paper's walkable area (free space for its 0.1 m agent) of the sim's house and settings, from
    its footprint: the sim publishes only the robot's own free space."""
    from ravh_sim.nav.navigation import Navigation
    from ravh_sim.world.house import load_house
    from ravh_sim.world.settings import Resolved
    from ravh_sim.world.state import WorldState
    house = load_house(int(footprint["house"]))
    state = WorldState(Resolved.model_validate(footprint["settings"]))
    return Navigation(house, state, profile).walkable(PAPER_AGENT_RADIUS)


def main(argv: list[str] | None = None) -> int:
    return run_node(make_node, argv)
