"""How many appearance changes the sim node makes under a burst, so that every request is answered and
/clock keeps its rate.

A change costs its own work and more at the next readings (a light-map redo of ~0.1-0.7 s at the next
camera frame, a new /map): the node measures that and lets changes take at most CHANGE_SHARE of its wall
time (CHANGE_BURST_S at once), and of requests that wait together it makes at most CHANGES_PER_BATCH.
The rest get a "busy" reply at once, which the client sends again.
"""
from __future__ import annotations

import threading
import time
from collections.abc import Iterable

CHANGE_SHARE = 0.15
CHANGE_BURST_S = 1.0
CHANGES_PER_BATCH = 1


class WorkBudget:
    """Wall time some work may take from a loop: ``burst`` seconds at once, refilled at ``share`` seconds
    per second (a token bucket counted in seconds)."""

    def __init__(self, burst: float, share: float) -> None:
        self.burst, self.share = burst, share
        self.level, self._at = burst, time.monotonic()
        self._lock = threading.Lock()               # spent from the render thread too

    def _refill(self) -> None:
        now = time.monotonic()
        self.level, self._at = min(self.burst, self.level + self.share * (now - self._at)), now

    def spend(self, seconds: float) -> None:
        with self._lock:
            self._refill()
            self.level -= seconds

    def wait_s(self) -> float:
        """How long until the work may run again (0: now)."""
        with self._lock:
            self._refill()
            return 0.0 if self.level > 0 else -self.level / self.share


class AppearanceBudget:
    """Whether an appearance change may be made now, and what changes have cost so far."""

    def __init__(self) -> None:
        self._in_batch = 0
        self._work = WorkBudget(CHANGE_BURST_S, CHANGE_SHARE)
        self._charged: set[tuple[str, str]] = set()      # (agent, port): next reading's time is a change's

    def new_batch(self) -> None:
        """The requests waiting from here on are one batch."""
        self._in_batch = 0

    def busy(self) -> str | None:
        """Why an appearance change must wait (None: it can be made now)."""
        if self._in_batch >= CHANGES_PER_BATCH:
            return "the sim is busy: requests came faster than it steps; send this one again in a moment"
        wait = self._work.wait_s()
        if wait > 0:
            return (f"the sim is busy with earlier appearance changes (they may take {CHANGE_SHARE:.0%} of its "
                    f"time); send this one again in {wait:.1f} s")
        return None

    def changed(self, readings: Iterable[tuple[str, str]], seconds: float) -> None:
        """A change was made in ``seconds``; the next of each of ``readings`` (agent, port) is charged to it."""
        self._in_batch += 1
        self._charged = set(readings)
        self._work.spend(seconds)

    def spend(self, seconds: float) -> None:
        """Work a change caused later (a new /map)."""
        self._work.spend(seconds)

    def note_reading(self, reading: tuple[str, str], seconds: float) -> None:
        """Charge the whole first reading of each sensor after an appearance change to the change (the
        renderer redoing its light maps). Only the excess is the change's, but under load every frame
        slows and the excess over a usual time measured then was too little: the charge errs high."""
        if reading in self._charged:             # (the camera's frames are noted on the render thread)
            self._charged.discard(reading)
            self._work.spend(seconds)
