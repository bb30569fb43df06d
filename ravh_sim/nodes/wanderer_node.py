"""``ros2 run ravh_sim wanderer``: visit every room through its ceiling lights, capturing while moving."""
from __future__ import annotations

from typing import Any

from ravh_sim.behaviours.wanderer import Wanderer
from ravh_sim.behaviours.waypoints import ORDERS, light_waypoints
from ravh_sim.nodes.behaviour_node import BehaviourNode, common_args
from ravh_sim.nodes.common import run_node


def make_node(argv: list[str]) -> BehaviourNode:
    p = common_args("wanderer", "Wanderer behaviour: room to room under the ceiling lights.")
    p.add_argument("--order", choices=ORDERS, default="cyclic",
                   help="cyclic: round after round; once: one round then stop; random: shuffled rounds")
    p.add_argument("--capture-period", type=float, default=0.5, help="seconds between captures while moving")
    p.add_argument("--seed", type=int, default=0, help="seed of the random order")
    args = p.parse_args(argv)

    def make(follower, layout, grid, start, _footprint) -> Any:
        return Wanderer(follower, light_waypoints(layout, grid, start), args.order, args.capture_period,
                        args.seed)

    return BehaviourNode("wanderer", make, args.agent, args.profile, args.log, args.wait_recorder, args.lockstep)


def main(argv: list[str] | None = None) -> int:
    return run_node(make_node, argv)
