"""Appearance managers: sun, lights, paint, object models and doors, changed at run time.

Every change goes through :class:`Appearance` and lands in ``world.settings`` (the resolved settings),
so the footprint always describes what the sensors see. Paint, models and doors change pybullet
bodies (through the World, no rebuild); the sun and the lights are read by the camera at capture time
(pybullet renders one directional light, the rest is the camera's lighting pass), so switching them
costs nothing. Random choices go through :func:`settings.resolve`, so "random" here picks exactly what
the same seed picks in a settings file.

The sun model (:func:`sun_light`) is here too: one angle gives the light direction, the colour and
level of daylight indoors and the sky colour seen beyond the house and through the windows.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from ravh_sim.errors import UnknownNameError, UserError
from ravh_sim.world import paints
from ravh_sim.world.furniture import variant_count
from ravh_sim.world.house import LIGHT_KINDS, Light
from ravh_sim.world.scene import World
from ravh_sim.world.settings import SUN_PRESETS, Resolved, load_settings, resolve

RGB = tuple[float, float, float]

LIGHT_GROUPS = ("all", *LIGHT_KINDS)
SWITCH_STATES = ("on", "off", "random")
SURFACES = ("walls", "floor")

# Daylight indoors (multiplies pybullet's render) and sky colours, from night to noon.
NIGHT_LEVEL = 0.12
NIGHT_COLOUR: RGB = (0.45, 0.55, 1.0)
HORIZON_COLOUR: RGB = (1.0, 0.62, 0.36)
HORIZON_LEVEL = 0.6
NOON_COLOUR: RGB = (1.0, 1.0, 1.0)
SKY_NOON: RGB = (125, 178, 235)
SKY_HORIZON: RGB = (240, 150, 95)
SKY_NIGHT: RGB = (10, 14, 32)
TWILIGHT_DEG = 15.0                       # how long after sunset (and before sunrise) light fades out
SUN_SOUTH_TILT = 0.35                     # the sun's arc leans to -y so noon light is not vertical
MOON_DIRECTION: RGB = (-0.3, 0.4, 0.87)


@dataclass(frozen=True)
class SunLight:
    """What one sun angle means for the camera."""
    angle: float                          # degrees: 0 sunrise, 90 noon, 180 sunset, >180 night
    direction: RGB                        # unit vector towards the sun (the moon at night), house frame
    gain: RGB                             # daylight colour x level, multiplies the rendered image
    sky: tuple[int, int, int]             # 8-bit RGB of the sky


def sun_light(angle: float) -> SunLight:
    """The sun at ``angle`` degrees: rises in +x (east), culminates over -y (south), sets in -x."""
    a = angle % 360.0
    rad = math.radians(a)
    if a <= 180.0:
        height = math.sqrt(max(math.sin(rad), 0.0))          # 0 at the horizon, 1 at noon
        daylight = 1.0
        direction = _unit((math.cos(rad), -SUN_SOUTH_TILT * math.sin(rad), math.sin(rad)))
    else:
        height = 0.0
        below = min(a - 180.0, 360.0 - a)                      # degrees below the horizon
        daylight = max(0.0, 1.0 - below / TWILIGHT_DEG)
        direction = _unit(MOON_DIRECTION)
    day_colour = _lerp(HORIZON_COLOUR, NOON_COLOUR, height)
    day_level = HORIZON_LEVEL + (1.0 - HORIZON_LEVEL) * height
    night = tuple(NIGHT_LEVEL * c for c in NIGHT_COLOUR)
    gain = _lerp(night, tuple(day_level * c for c in day_colour), daylight)
    sky = _lerp(SKY_NIGHT, _lerp(SKY_HORIZON, SKY_NOON, height), daylight)
    return SunLight(a, direction, gain, tuple(int(round(c)) for c in sky))


class Appearance:
    """Run-time changes to how a house looks; every change is recorded in ``world.settings``."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.house = world.house

    # ------------------------------------------------------------------ sun and lights
    @property
    def sun(self) -> SunLight:
        return sun_light(self.world.settings.sun_angle)

    def set_sun(self, angle: float | str) -> None:
        """Sun angle in degrees [0, 360] or a preset name (day, sunset, night)."""
        if isinstance(angle, str):
            if angle not in SUN_PRESETS:
                raise UnknownNameError("sun preset", angle, list(SUN_PRESETS))
            angle = SUN_PRESETS[angle]
        if not (isinstance(angle, (int, float)) and math.isfinite(angle) and 0.0 <= angle <= 360.0):
            raise UserError(f"sun angle must be degrees in [0, 360], got {angle!r}")
        self.world.settings.sun_angle = float(angle)

    def set_light(self, light_id: str, on: bool) -> None:
        if light_id not in self.house.light_by_id:
            raise UnknownNameError("light", light_id, list(self.house.light_by_id))
        self.world.settings.lights[light_id] = bool(on)

    def set_lights(self, which: str = "all", state: str = "on", seed: int | None = None) -> None:
        """Switch every light of a kind (ceiling, lamp, wall) or all of them on, off or at random."""
        if which not in LIGHT_GROUPS:
            raise UnknownNameError("light group", which, list(LIGHT_GROUPS))
        if state not in SWITCH_STATES:
            raise UnknownNameError("light state", state, list(SWITCH_STATES))
        chosen = [lt.id for lt in self.house.lights if which in ("all", lt.kind)]
        states = self._resolve({"lights": {"set": {lid: state for lid in chosen}}}, seed).lights
        for lid in chosen:
            self.set_light(lid, states[lid])

    def lights_on(self) -> list[Light]:
        return [lt for lt in self.house.lights if self.world.settings.lights.get(lt.id, False)]

    # ------------------------------------------------------------------ bodies
    def set_paint(self, room_id: str, surface: str, paint: str) -> None:
        self.house.room(room_id)
        if surface not in SURFACES:
            raise UnknownNameError("surface", surface, list(SURFACES))
        if not paints.is_paint(paint):
            raise UnknownNameError("paint", paint, paints.all_paints() + ["#rrggbb"])
        self.world.set_paint(room_id, surface, paint)

    def set_object_model(self, object_id: str, model: int | str | dict[str, str],
                         seed: int | None = None) -> int:
        """Swap an object's model: an index, 'random' (seeded) or {'inherit': OTHER_ID}; returns it."""
        obj = self.house.object(object_id)
        if isinstance(model, bool) or not isinstance(model, (int, str, dict)):
            raise UserError(f"model must be an index, 'random' or {{'inherit': ID}}, got {model!r}")
        if isinstance(model, dict):
            if set(model) != {"inherit"}:
                raise UserError(f"model must be {{'inherit': OBJECT_ID}}, got {model!r}")
            index = self.world.settings.models[self.house.object(model["inherit"]).id]
        elif model == "random":
            index = self._resolve({"models": {"set": {object_id: "random"}}}, seed).models[object_id]
        elif isinstance(model, int):
            index = model
        else:
            raise UserError(f"model must be an index, 'random' or {{'inherit': ID}}, got {model!r}")
        count = variant_count(obj.type)
        if not 0 <= index < count:
            raise UserError(f"{object_id}: model index must be in 0..{count - 1}, got {index}")
        if index != self.world.settings.models[object_id]:
            self.world.set_object_model(object_id, index)
        return index

    def set_door(self, door_id: str, is_open: bool) -> None:
        if door_id not in self.house.door_by_id:
            raise UnknownNameError("door", door_id, list(self.house.door_by_id))
        self.world.set_door_open(door_id, bool(is_open))

    # ------------------------------------------------------------------ whole settings
    def apply(self, target: Resolved) -> None:
        """Bring the world to ``target`` (sun, lights, doors, paint, models), changing only what differs."""
        current = self.world.settings
        self.set_sun(target.sun_angle)
        for lid, on in target.lights.items():
            self.set_light(lid, on)
        for did, is_open in target.doors.items():
            if current.doors[did] != is_open:
                self.set_door(did, is_open)
        for room_id, surfaces in target.paint.items():
            for surface, paint in surfaces.items():
                if current.paint[room_id][surface] != paint:
                    self.set_paint(room_id, surface, paint)
        for oid, model in target.models.items():
            if current.models[oid] != model:
                self.set_object_model(oid, model)

    def randomise(self, seed: int) -> Resolved:
        """Random sun, lights, doors, paint and models (what a settings file of 'random' gives for
        ``seed``); returns the new settings. The noise seed and the agents stay as they were."""
        target = self._resolve({"lights": {"sun_angle": "random", "ceiling": "random", "lamps": "random"},
                                "doors": {"all": "random"},
                                "paint": {"walls": "random", "floors": "random"},
                                "models": {"all": "random"}}, seed)
        self.apply(target)
        return self.world.settings

    def _resolve(self, overrides: dict[str, dict[str, Any]], seed: int | None) -> Resolved:
        """Resolve the default settings with ``overrides`` for this house (random picks by seed)."""
        cfg = _default_settings()
        for section, values in overrides.items():
            cfg[section] = {**cfg[section], **values}
        return resolve(cfg, self.house, self.world.settings.seed if seed is None else seed, "appearance")


@lru_cache(maxsize=1)
def _cached_defaults() -> dict[str, Any]:
    return load_settings()


def _default_settings() -> dict[str, Any]:
    return copy.deepcopy(_cached_defaults())


def _lerp(a, b, t: float) -> RGB:
    return tuple(x + (y - x) * t for x, y in zip(a, b))


def _unit(v) -> RGB:
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)
