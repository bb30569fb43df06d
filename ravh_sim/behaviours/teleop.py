"""Manual driving: keys to velocity commands (the logic of the teleop node, testable without a terminal).

Like turtlebot3's teleop: each press steps the target speed, so holding nothing keeps the robot
moving at the chosen speed; ``s`` or space stops.
"""
from __future__ import annotations

from dataclasses import dataclass

LINEAR_STEP = 0.05        # m/s per press
ANGULAR_STEP = 0.1        # rad/s per press

HELP = """ravh teleop: drive the robot
   w            faster forward        x   faster backward
 a   d          turn left / right     s / space   stop
   c            capture now           q   quit
"""


@dataclass
class Teleop:
    max_linear: float
    max_angular: float
    v: float = 0.0
    w: float = 0.0

    def press(self, key: str) -> str | None:
        """Apply one key; returns 'capture' or 'quit' for those keys, else None."""
        if key == "w":
            self.v = min(self.max_linear, self.v + LINEAR_STEP)
        elif key == "x":
            self.v = max(-self.max_linear, self.v - LINEAR_STEP)
        elif key == "a":
            self.w = min(self.max_angular, self.w + ANGULAR_STEP)
        elif key == "d":
            self.w = max(-self.max_angular, self.w - ANGULAR_STEP)
        elif key in ("s", " "):
            self.v = self.w = 0.0
        elif key == "c":
            return "capture"
        elif key in ("q", "\x03"):
            self.v = self.w = 0.0
            return "quit"
        return None
