"""The live state of a world: the sun, lights, doors, paint and object models the sensors see now.

A World starts from frozen :class:`~ravh_sim.world.settings.Resolved` settings and keeps what changes
later here. Everyone reads it (as read-only mappings); one place writes it:
:class:`ravh_sim.world.appearance.Appearance` (the Simulation records, once, where its robots really
start). The state is the world's current :class:`Resolved` value, replaced (never edited) on each
change, so :meth:`WorldState.settings` is the footprint's record of it at no cost. Each field of the
model has a revision that grows when the field changes, so readers cache instead of comparing: a
renderer asks :meth:`WorldState.changed_since` which fields moved since it last looked, and
``layout_revision`` grows only when a door or an object model changes (what maps and plans depend on).
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ravh_sim.world.settings import AgentSpec, Resolved

LAYOUT_FIELDS = ("doors", "models", "dressing")


class WorldState:
    """Sun angle, lights, doors, paint, models and agents of one world as they are now: the current
    frozen settings and a revision per field."""

    def __init__(self, initial: Resolved) -> None:
        self._now = initial
        self._revisions = dict.fromkeys(Resolved.model_fields, 0)

    def settings(self) -> Resolved:
        """The state as frozen settings: what a footprint records and a world is rebuilt from. A later
        change makes a new value; this one stays as it is."""
        return self._now

    @property
    def seed(self) -> int:
        """The seed of noise and odometry streams; never changes."""
        return self._now.seed

    @property
    def sun_angle(self) -> float:
        return self._now.sun_angle

    @property
    def lights(self) -> Mapping[str, bool]:
        return self._now.lights

    @property
    def doors(self) -> Mapping[str, bool]:
        """Door id -> open."""
        return self._now.doors

    @property
    def paint(self) -> Mapping[str, Mapping[str, str]]:
        return self._now.paint

    @property
    def models(self) -> Mapping[str, int]:
        return self._now.models

    @property
    def dressing(self) -> str:
        """none | tidy | lived-in (:mod:`ravh_sim.world.dressing`)."""
        return self._now.dressing

    @property
    def agents(self) -> tuple[AgentSpec, ...]:
        return self._now.agents

    def revisions(self) -> dict[str, int]:
        """Field name -> its revision now (a copy: keep it to ask :meth:`changed_since` later)."""
        return dict(self._revisions)

    def changed_since(self, seen: Mapping[str, int] | None) -> frozenset[str]:
        """The fields whose revision moved since ``seen`` (from :meth:`revisions`; None: every field)."""
        return frozenset(f for f, rev in self._revisions.items() if seen is None or seen[f] != rev)

    @property
    def revision(self) -> int:
        """Grows with every change."""
        return sum(self._revisions.values())

    @property
    def layout_revision(self) -> int:
        """Grows when a door opens or closes or an object model changes (the maps change)."""
        return sum(self._revisions[f] for f in LAYOUT_FIELDS)

    def write(self, **fields: Any) -> bool:
        """Record the given fields of the model (for Appearance and, for ``agents``, the Simulation only);
        a mapping is written over the current one (``paint={room: {surface: paint}}`` changes one
        surface). Returns whether anything changed. An item the world does not have is a KeyError (a
        caller's bug)."""
        now = self._now
        new = now.changed(**{f: _merged(getattr(now, f), value) for f, value in fields.items()})
        moved = [f for f in fields if getattr(new, f) != getattr(now, f)]
        for f in moved:
            self._revisions[f] += 1
        self._now = new
        return bool(moved)


def _merged(now: Any, change: Any) -> Any:
    """``change`` written over ``now``: item by item (and so on down) for mappings, whole otherwise."""
    if not isinstance(change, Mapping):
        return change
    for key in change:
        if key not in now:
            raise KeyError(f"unknown item {key!r}")
    return {**now, **{key: _merged(now[key], value) for key, value in change.items()}}
