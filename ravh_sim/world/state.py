"""The live state of a world: the sun, lights, doors, paint and object models the sensors see now.

A World starts from frozen :class:`~ravh_sim.world.settings.Resolved` settings and keeps what changes
later here. Everyone reads it (as read-only mappings); one place writes it:
:class:`ravh_sim.world.appearance.Appearance` (the Simulation records, once, where its robots really
start). Two counters let readers cache instead of comparing: ``revision`` grows with every change,
``layout_revision`` only when a door or an object model changes (what maps and plans depend on).
:meth:`WorldState.settings` is the footprint's record of it.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType

from ravh_sim.world.settings import AgentSpec, Resolved


class WorldState:
    """Sun angle, lights, doors, paint, models and agents of one world as they are now."""

    def __init__(self, initial: Resolved) -> None:
        self._seed = initial.seed                 # noise and odometry streams; never changes
        self._sun_angle = initial.sun_angle
        self._lights = dict(initial.lights)
        self._doors = dict(initial.doors)
        self._paint = {room: dict(surfaces) for room, surfaces in initial.paint.items()}
        self._models = dict(initial.models)
        self._agents = tuple(initial.agents)
        self._revision = 0
        self._layout_revision = 0
        self.lights: Mapping[str, bool] = MappingProxyType(self._lights)
        self.doors: Mapping[str, bool] = MappingProxyType(self._doors)     # door id -> open
        self.paint: Mapping[str, Mapping[str, str]] = MappingProxyType(
            {room: MappingProxyType(surfaces) for room, surfaces in self._paint.items()})
        self.models: Mapping[str, int] = MappingProxyType(self._models)

    @property
    def seed(self) -> int:
        return self._seed

    @property
    def sun_angle(self) -> float:
        return self._sun_angle

    @property
    def agents(self) -> tuple[AgentSpec, ...]:
        return self._agents

    @property
    def revision(self) -> int:
        """Grows with every change."""
        return self._revision

    @property
    def layout_revision(self) -> int:
        """Grows when a door opens or closes or an object model changes (the maps change)."""
        return self._layout_revision

    def settings(self) -> Resolved:
        """The state as frozen settings: what a footprint records and a world is rebuilt from."""
        return Resolved(seed=self._seed, sun_angle=self._sun_angle, lights=self._lights, doors=self._doors,
                        paint=self._paint, models=self._models, agents=self._agents)

    def write(self, *, sun_angle: float | None = None, lights: Mapping[str, bool] | None = None,
              doors: Mapping[str, bool] | None = None, paint: Mapping[str, Mapping[str, str]] | None = None,
              models: Mapping[str, int] | None = None, agents: Sequence[AgentSpec] | None = None) -> bool:
        """Record the given items (for Appearance and, for ``agents``, the Simulation only); returns
        whether anything changed. An item the world does not have is a KeyError (a caller's bug)."""
        changed = False
        if sun_angle is not None and sun_angle != self._sun_angle:
            self._sun_angle = sun_angle
            changed = True
        changed |= _merge(self._lights, lights)
        layout = _merge(self._doors, doors) | _merge(self._models, models)
        for room, surfaces in (paint or {}).items():
            if room not in self._paint:
                raise KeyError(f"unknown room {room!r}")
            changed |= _merge(self._paint[room], surfaces)
        if agents is not None and tuple(agents) != self._agents:
            self._agents = tuple(agents)
            changed = True
        if changed or layout:
            self._revision += 1
        if layout:
            self._layout_revision += 1
        return changed or layout


def _merge(items: dict, changes: Mapping | None) -> bool:
    """Write ``changes`` into ``items``; whether any value differed."""
    changed = False
    for key, value in (changes or {}).items():
        if key not in items:
            raise KeyError(f"unknown item {key!r}")
        if items[key] != value:
            items[key] = value
            changed = True
    return changed
