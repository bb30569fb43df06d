"""What changed in a scene since a renderer last looked, in the terms a renderer redraws by.

The world state keeps a revision per field (:class:`ravh_sim.world.state.WorldState`); which fields
move which part of the scene is decided here, once, for every renderer: doors, models and paint move
surfaces (everything is redone), the sun angle the sunlight, a switch the lamps it names, and every
other global knob (``KNOBS``: the colour temperature...) the light of every lamp.
"""
from __future__ import annotations

from dataclasses import dataclass

from ravh_msgs_py.appearance import KNOBS
from ravh_sim.world.state import WorldState

GEOMETRY_FIELDS = frozenset({"doors", "models", "paint", "dressing"})
SUN_FIELDS = frozenset({"sun_angle"})
EVERY_LAMP_FIELDS = frozenset(KNOBS) - SUN_FIELDS


@dataclass(frozen=True)
class SceneChange:
    """What moved since the last look; ``geometry`` implies every other part."""
    geometry: bool                        # surfaces: meshes, poses or materials
    sun: bool                             # the sun's direction and colour
    lamps: bool                           # which lamps shine, or their light
    every_lamp: bool                      # every lamp's light (not only those switched)

    @property
    def lighting(self) -> bool:
        return self.geometry or self.sun or self.lamps


class ChangeWatch:
    """One reader's view of a world state's revisions: each :meth:`poll` reports what changed since
    the previous one (the first reports everything)."""

    def __init__(self, state: WorldState) -> None:
        self.state = state
        self._seen: dict[str, int] | None = None

    def poll(self) -> SceneChange:
        changed = self.state.changed_since(self._seen)
        self._seen = self.state.revisions()
        geometry = bool(changed & GEOMETRY_FIELDS)
        every_lamp = bool(changed & EVERY_LAMP_FIELDS)
        return SceneChange(geometry, geometry or bool(changed & SUN_FIELDS),
                           every_lamp or "lights" in changed, every_lamp)
