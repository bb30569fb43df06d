"""``ros2 run ravh_sim teleop``: drive the robot from the keyboard in a terminal (the Manual behaviour)."""
from __future__ import annotations

import argparse
import select
import sys
import termios
import tty

from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.task import Future
from std_srvs.srv import Trigger

from ravh_msgs_py import names as n
from ravh_sim.behaviours.teleop import HELP, Teleop
from ravh_sim.errors import UserError
from ravh_sim.nodes.behaviour_node import which_agent
from ravh_sim.nodes.common import COMMAND_QOS, run_node
from ravh_sim.robot.profile import load_profile

PUBLISH_HZ = 10.0


class TeleopNode(Node):
    def __init__(self, agent: str | None, profile: str | None) -> None:
        """``agent``: None drives the sim's first agent; ``profile``: None takes the agent's from the sim."""
        super().__init__("teleop")
        if not sys.stdin.isatty():
            raise UserError("teleop reads keys from a terminal; run it in an interactive shell")
        agent, first, agent_profile = which_agent(self, agent)
        p = load_profile(profile or agent_profile)
        self.teleop = Teleop(p.max_linear_speed, p.max_angular_speed)
        self.pub = self.create_publisher(Twist, n.agent_name(n.CMD_VEL, agent, first), COMMAND_QOS)
        self.capture = self.create_client(Trigger, n.agent_name(n.CAPTURE_SERVICE, agent, first))
        self.finished = Future()
        self._saved = termios.tcgetattr(sys.stdin)
        tty.setcbreak(sys.stdin.fileno())
        print(HELP, flush=True)
        self.create_timer(1.0 / PUBLISH_HZ, self._tick)

    def _tick(self) -> None:
        while select.select([sys.stdin], [], [], 0)[0]:
            action = self.teleop.press(sys.stdin.read(1))
            if action == "capture" and self.capture.service_is_ready():
                self.capture.call_async(Trigger.Request())
            elif action == "quit":
                self.finished.set_result(True)
        msg = Twist()
        msg.linear.x, msg.angular.z = self.teleop.v, self.teleop.w
        self.pub.publish(msg)
        print(f"\rv {self.teleop.v:+.2f} m/s   w {self.teleop.w:+.2f} rad/s ", end="", flush=True)

    def close(self) -> None:
        termios.tcsetattr(sys.stdin, termios.TCSADRAIN, self._saved)
        self.pub.publish(Twist())
        print()


def main(argv: list[str] | None = None) -> int:
    def make(args: list[str]) -> TeleopNode:
        p = argparse.ArgumentParser(prog="teleop", description="Drive a robot with the keyboard.")
        p.add_argument("--agent", default=None, help="agent to drive (default: the sim's first)")
        p.add_argument("--profile", default=None, help="its robot profile (default: its profile in the sim)")
        a = p.parse_args(args)
        return TeleopNode(a.agent, a.profile)
    return run_node(make, argv)
