"""Each robot's state at the odometry rate: odometry, the true pose, odom -> base_link and map -> odom
(on their own topics, and on /tf as far as the sim owns the edge, see ravh_sim.nodes.map_odom), and the
room it stands in when that changes."""
from __future__ import annotations

from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from ravh_msgs_py import names as n
from ravh_sim.nodes import convert
from ravh_sim.nodes.map_odom import MapOdomOwnership
from ravh_sim.nodes.sim_topics import SimTopics
from ravh_sim.runtime import Agent


class RobotState:
    """Publishes an agent's state when its odometry falls due, and every pose while lockstep waits."""

    def __init__(self, topics: SimTopics, map_odom: MapOdomOwnership) -> None:
        self.topics, self.runtime, self.map_odom = topics, topics.runtime, map_odom

    def publish(self, agent: Agent) -> None:
        rt, topics = self.runtime, self.topics
        pubs = topics.agents[agent.name]
        t = topics.now()
        odom_pose, true_pose = agent.robot.odometry, agent.robot.pose
        v, w = agent.robot.velocity
        odom_hdr = convert.header(t, topics.frame(agent, n.ODOM_FRAME))
        base = topics.frame(agent, n.BASE_FRAME)
        pubs["odom"].publish(convert.odometry(odom_pose, v, w, odom_hdr, base,
                                              (agent.profile.odom_linear_sigma, agent.profile.odom_angular_sigma)))
        pubs["gt_pose"].publish(convert.pose_stamped(true_pose, convert.header(t, n.MAP_FRAME)))
        odom_tf = convert.transform_2d(odom_hdr, base, odom_pose)
        map_odom = convert.transform_2d(convert.header(t, n.MAP_FRAME), odom_hdr.frame_id,
                                        rt.map_to_odom(agent))
        pubs["odom_tf"].publish(odom_tf)
        pubs["map_odom"].publish(map_odom)
        tf = [odom_tf]
        if self.map_odom.owns(agent):
            tf.append(map_odom)
            self.map_odom.published(map_odom)
        topics.tf.publish(TFMessage(transforms=tf))
        room = rt.room_of(agent)
        if room != pubs["last_room"]:
            pubs["last_room"] = room
            pubs["room"].publish(String(data=room or ""))

    def arrived(self) -> None:
        """Lockstep: at the granted time, the pose the behaviour acts on (repeated while waiting, with
        /clock, so late subscribers get it and nobody takes the pause for a dead sim)."""
        rt = self.runtime
        self.topics.clock.publish(convert.clock(rt.time))
        for agent in rt.agents:
            self.topics.agents[agent.name]["gt_pose"].publish(
                convert.pose_stamped(agent.robot.pose, convert.header(rt.time, n.MAP_FRAME)))
