"""The facts the sim publishes once, latched (TRANSIENT_LOCAL), so a node that starts later still gets
them: /map and the free space, the footprint (the world as the sensors see it), the instance labels and
every sensor mount on /tf_static. The maps and the footprint are published again when they change."""
from __future__ import annotations

import json
from typing import Any

from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_sim.nodes import convert
from ravh_sim.nodes.sim_topics import SimTopics


class LatchedTopics:
    """Publishes the latched facts, and each again when it is no longer true."""

    def __init__(self, topics: SimTopics) -> None:
        self.topics, self.runtime = topics, topics.runtime
        self._published_map = -1

    def publish_all(self) -> None:
        footprint = self.publish_footprint()
        labels = {str(row["id"]): {"name": row["name"], "kind": row["kind"], "type": row["type"],
                                   "tags": row["tags"], "room": row["room"], "mask_color": row["mask_color"]}
                  for row in footprint["instances"]}
        self.topics.labels.publish(String(data=json.dumps(labels)))
        self.publish_map()
        self._publish_static()

    @property
    def map_stale(self) -> bool:
        """Whether a door or a model changed since /map was published."""
        return self.runtime.map_version != self._published_map

    def publish_map(self) -> None:
        """/map (the obstacle map) and /ravh/free_space (the robot's inflated free space)."""
        rt = self.runtime
        self._published_map = rt.map_version
        t = self.topics.now()
        for publisher, grid in ((self.topics.map, rt.navigation.obstacle_map()),
                                (self.topics.free_space, rt.navigation.map())):
            publisher.publish(convert.occupancy_grid(grid, convert.header(t, n.MAP_FRAME), t))

    def publish_footprint(self) -> dict[str, Any]:
        """The latched footprint: republished after every appearance change so it stays true."""
        footprint = self.runtime.footprint()
        self.topics.footprint.publish(String(data=json.dumps(footprint)))
        return footprint

    def _publish_static(self) -> None:
        """Every agent's sensor mounts in one latched /tf_static message: a latched topic keeps only its
        last message, so one message per agent would leave late joiners with the last agent's only."""
        topics = self.topics
        t = topics.now()
        transforms = []
        for agent in self.runtime.agents:
            for parent, child, xyz, quat in self.runtime.static_transforms(agent):
                tf = convert.transform(convert.header(t, topics.frame(agent, parent)), topics.frame(agent, child),
                                       xyz, quat)
                topics.agents[agent.name]["static"][child].publish(tf)
                transforms.append(tf)
        topics.tf_static.publish(TFMessage(transforms=transforms))
