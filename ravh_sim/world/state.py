"""The live state of a world: the sun, lights, doors, paint and object models the sensors see now.

A World starts from frozen :class:`~ravh_sim.world.settings.Resolved` settings and keeps what changes
later here. Everyone reads it (as read-only mappings); one place writes it:
:class:`ravh_sim.world.appearance.Appearance` (the Simulation records, once, where its robots really
start). The state is the world's current :class:`Resolved` value, replaced (never edited) on each
change, so :meth:`WorldState.settings` is the footprint's record of it at no cost, and two counters let
readers cache instead of comparing: ``revision`` grows with every change, ``layout_revision`` only
when a door or an object model changes (what maps and plans depend on).
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import TypeVar

from ravh_sim.world.settings import AgentSpec, Resolved

V = TypeVar("V")


class WorldState:
    """Sun angle, lights, doors, paint, models and agents of one world as they are now: the current
    frozen settings and two revision counters."""

    def __init__(self, initial: Resolved) -> None:
        self._now = initial
        self._revision = 0
        self._layout_revision = 0

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
    def agents(self) -> tuple[AgentSpec, ...]:
        return self._now.agents

    @property
    def revision(self) -> int:
        """Grows with every change."""
        return self._revision

    @property
    def layout_revision(self) -> int:
        """Grows when a door opens or closes or an object model changes (the maps change)."""
        return self._layout_revision

    def write(self, *, sun_angle: float | None = None, lights: Mapping[str, bool] | None = None,
              doors: Mapping[str, bool] | None = None, paint: Mapping[str, Mapping[str, str]] | None = None,
              models: Mapping[str, int] | None = None, agents: Sequence[AgentSpec] | None = None) -> bool:
        """Record the given items (for Appearance and, for ``agents``, the Simulation only); returns
        whether anything changed. An item the world does not have is a KeyError (a caller's bug)."""
        now = self._now
        _check_known(now.paint, paint or {})
        new = replace(now, sun_angle=now.sun_angle if sun_angle is None else sun_angle,
                      lights=_merged(now.lights, lights), doors=_merged(now.doors, doors),
                      paint={room: _merged(surfaces, (paint or {}).get(room)) for room, surfaces in now.paint.items()},
                      models=_merged(now.models, models), agents=now.agents if agents is None else tuple(agents))
        if new == now:
            return False
        if new.doors != now.doors or new.models != now.models:
            self._layout_revision += 1
        self._now = new
        self._revision += 1
        return True


def _merged(items: Mapping[str, V], changes: Mapping[str, V] | None) -> Mapping[str, V]:
    """``items`` with ``changes`` written over them."""
    if not changes:
        return items
    _check_known(items, changes)
    return {**items, **changes}


def _check_known(items: Mapping, changes: Mapping) -> None:
    for key in changes:
        if key not in items:
            raise KeyError(f"unknown item {key!r}")
