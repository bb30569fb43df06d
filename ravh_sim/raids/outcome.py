"""How a raid ended: raid.json's ``status`` is one of these sentences with its details filled in.

Both engines (the ROS raid and the direct one) state their end with :meth:`Outcome.status`, and
whoever reads a raid.json back (the build skipping finished raids, ``ravh raid``'s exit status) asks
:meth:`Outcome.of` rather than matching the words, so the sentences can change in one place.
"""
from __future__ import annotations

import re
from enum import Enum
from typing import Any

LOSS_SEPARATOR = "; "        # an interrupted raid that lost captures says both: "interrupted (Ctrl-C); lost ..."


class Outcome(Enum):
    DONE = "done"                                                      # the behaviour finished, nothing lost
    STOPPED = "stopped at {captures} captures"                         # the capture limit it was given
    TIMED_OUT = "timed out after {limit}"                              # "600 s", or "3600 sim s" (direct)
    PROCESS_STOPPED = "the {name} stopped with exit status {code} (see logs/{name}.log)"
    PROCESS_FAILED = "{name} exited with {code} (see logs/{name}.log)"  # after the behaviour ended
    LOST = "lost {lost} of {requested} captures (see logs/)"            # the recorder missed captures
    INTERRUPTED = "interrupted (Ctrl-C)"

    def status(self, **details: Any) -> str:
        """The sentence raid.json stores for this outcome."""
        return self.value.format(**details)

    @property
    def complete(self) -> bool:
        """The raid ran to its end or to the limit it was given: its dataset is whole."""
        return self in (Outcome.DONE, Outcome.STOPPED)

    @classmethod
    def of(cls, status: str) -> Outcome:
        """The outcome a stored status states (an interrupted raid's losses follow its own sentence)."""
        first = status.split(LOSS_SEPARATOR)[0]
        for outcome in cls:
            if re.fullmatch(re.sub(r"\\\{\w+\\\}", ".+", re.escape(outcome.value)), first):
                return outcome
        raise ValueError(f"not a raid status: {status!r}")
