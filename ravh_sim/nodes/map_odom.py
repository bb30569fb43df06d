"""Who puts the map -> odom edge on /tf: the sim (its ground truth) or a SLAM or localisation node.

Two publishers of one edge make tf2 jump between them, so ``map_tf`` says who owns it: ``on`` the sim,
``off`` someone else, ``auto`` (default) the sim only while no other node (slam_toolbox, AMCL) publishes
that edge; it takes the edge back MAP_TF_RESUME_S after the other stops. The ground truth stays on
``map_to_odom`` and ``ground_truth/pose`` either way.
"""
from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Iterable

from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_sim.runtime import Agent

MAP_TF_RESUME_S = 2.0                   # wall s without another map -> odom publisher before the sim takes over


class MapOdomOwnership:
    """Whether the sim publishes each agent's map -> odom on /tf now, from what it hears on /tf."""

    def __init__(self, mode: str, agents: Iterable[Agent], info: Callable[[str], None]) -> None:
        self.mode = mode                                            # one of sim_params.MAP_TF_MODES
        self._info = info
        self._own: deque[tuple] = deque(maxlen=256)                 # what the sim put on /tf lately
        self._foreign: dict[str, float] = {}                        # odom frame -> wall time last heard
        self._publishing = {agent.name: mode != "off" for agent in agents}

    @property
    def listens(self) -> bool:
        """Whether the sim must hear /tf to decide (``auto``)."""
        return self.mode == "auto"

    def heard(self, msg: TFMessage) -> None:
        """Note map -> odom edges on /tf that the sim did not publish (a SLAM or localisation node)."""
        for tf in msg.transforms:
            if tf.header.frame_id.lstrip("/") == n.MAP_FRAME and _tf_key(tf) not in self._own:
                self._foreign[tf.child_frame_id.lstrip("/")] = time.monotonic()

    def published(self, tf: TransformStamped) -> None:
        """The sim put ``tf`` on /tf (hearing it back is not another publisher)."""
        self._own.append(_tf_key(tf))

    def owns(self, agent: Agent) -> bool:
        """Whether the sim publishes ``agent``'s map -> odom on /tf now; logs each hand-over once."""
        if self.mode != "auto":
            return self.mode == "on"
        odom = n.agent_name(n.ODOM_FRAME, agent.name, agent.first)
        seen = self._foreign.get(odom)
        owns = seen is None or time.monotonic() - seen > MAP_TF_RESUME_S
        if owns != self._publishing[agent.name]:
            self._publishing[agent.name] = owns
            self._info(
                f"map_tf auto: no other node has published {n.MAP_FRAME} -> {odom} for {MAP_TF_RESUME_S:g} s; "
                "the sim publishes its ground truth on /tf again" if owns else
                f"map_tf auto: another node publishes {n.MAP_FRAME} -> {odom}; the sim stops publishing "
                f"its ground truth on /tf (still on {n.agent_name(n.MAP_TO_ODOM, agent.name, agent.first)})")
        return owns


def _tf_key(tf: TransformStamped) -> tuple:
    """What tells one transform message from another (stamp, child and values)."""
    t, r = tf.transform.translation, tf.transform.rotation
    return (tf.child_frame_id, tf.header.stamp.sec, tf.header.stamp.nanosec, t.x, t.y, t.z, r.x, r.y, r.z, r.w)
