"""How far the sim node lets sim time run: the node is the clock of the ROS graph.

Sim time follows wall time times the real-time factor (0 = as fast as possible). With ``--lockstep`` it
advances only as far as a behaviour grants on ``ravh/step``, so a run depends on sim time alone and
repeats exactly with the same seed. Plain Python: the node asks, once per tick, up to which physics step
it may go.
"""
from __future__ import annotations

import time
from collections.abc import Callable

MAX_STEP_S = 0.1                        # sim time advanced per tick at most (keeps services responsive)
HEARTBEAT_S = 0.5                       # lockstep: wall period of /clock and pose while waiting


class Pacing:
    """The physics step a tick may run to, as the real-time factor and the lockstep grants allow."""

    def __init__(self, rtf: float, lockstep: bool, physics_hz: float, steps: int, sim_time: float) -> None:
        self.rtf, self.lockstep = rtf, lockstep
        self.allowed = steps                        # lockstep: the step granted
        self._heartbeat = 0.0                       # lockstep: wall time of the last beat while waiting
        self._max_steps = round(MAX_STEP_S * physics_hz)
        self._wall0, self._sim0 = time.monotonic(), sim_time

    def _asked(self) -> float:
        """The sim time that wall time asks for now (real-time factor > 0)."""
        return self._sim0 + self.rtf * (time.monotonic() - self._wall0)

    def last_step(self, steps: int, step_at: Callable[[float], int]) -> int:
        """The step to run to from ``steps`` (``step_at``: the first step at or after a sim time)."""
        last = steps + self._max_steps
        if self.rtf > 0:
            last = min(last, step_at(self._asked()))
        if self.lockstep:
            last = min(last, self.allowed)
        return last

    def grant(self, step: int) -> None:
        """Lockstep: sim time may run up to ``step`` (no effect without lockstep)."""
        self.allowed = max(self.allowed, step)

    def behaviour_grants(self, step: int) -> None:
        """Lockstep: a behaviour's grant, whose arrival is announced at once (no heartbeat to wait for)."""
        self.grant(step)
        self._heartbeat = 0.0

    def beat_due(self, steps: int) -> bool:
        """Lockstep: whether to announce, again, that sim time stands at the granted step (True notes it)."""
        if not (self.lockstep and steps >= self.allowed and time.monotonic() - self._heartbeat > HEARTBEAT_S):
            return False
        self._heartbeat = time.monotonic()
        return True

    def settle(self, sim_time: float) -> None:
        """After a tick: a sim that fell behind wall time does not try to catch up."""
        if self.rtf > 0 and sim_time + MAX_STEP_S < self._asked():
            self._wall0, self._sim0 = time.monotonic(), sim_time
