"""Stops a robot whose velocity commands stop arriving, as a real base does: a teleop or a behaviour that
dies must not leave its robot driving on for ever. Counted in sim time, so a paused or slow sim does not
stop a robot that is still commanded."""
from __future__ import annotations

from collections.abc import Iterable

from ravh_sim.runtime import Agent

CMD_TIMEOUT_S = 0.5                     # stop a robot whose commands stop arriving (sim seconds)


class CommandWatchdog:
    """The sim time of each agent's last command, and the stop once it is older than CMD_TIMEOUT_S."""

    def __init__(self) -> None:
        self._last: dict[str, float] = {}

    def commanded(self, agent: Agent, sim_time: float) -> None:
        self._last[agent.name] = sim_time

    def check(self, agents: Iterable[Agent], sim_time: float) -> None:
        """Stop every agent whose last command is older than CMD_TIMEOUT_S (once: it stays stopped)."""
        for agent in agents:
            last = self._last.get(agent.name)
            if last is not None and sim_time - last > CMD_TIMEOUT_S:
                agent.robot.set_command(0.0, 0.0)
                del self._last[agent.name]
