"""The light of a scene, computed once from the house and the world state for every renderer.

One model, in one place: the sun (:func:`sun_light`: one angle gives the light's direction, the
colour and level of daylight indoors and the sky's colour), the lamps (:func:`lamps_at`: the house's
switched-on lights at a colour temperature), the outdoors a window shows, each window as an area light
of its room, and each room's ambient (bounced sky light and the bounce of its own lamps).
:func:`scene_lights` gathers them for one world state; the renderers take a :class:`SceneLights` and
only draw it. A new light knob is one field of ``Looks`` (ravh_msgs_py.appearance) and one function
here that :func:`scene_lights` applies.

Light units are arbitrary but consistent (a camera's exposure adapts): the sun gives SUN_IRRADIANCE on
a surface facing it at noon, a lamp of intensity 1 gives LAMP_POWER / d^2, a window is an area light
of WINDOW_RADIANCE lighting its own room, and the outdoors seen through it is brighter than the room's
walls (OUTDOOR_DAY) but keeps its structure, as in an indoor photo with the window in it.
"""
from __future__ import annotations

import math
import zlib
from collections.abc import Iterable
from dataclasses import dataclass, replace

import numpy as np

from ravh_msgs_py.appearance import Looks
from ravh_sim.look.materials import srgb8_to_linear
from ravh_sim.world.geometry import polygon_centroid
from ravh_sim.world.house import House, Light, Room
from ravh_sim.world.state import WorldState

RGB = tuple[float, float, float]

# The sun: daylight indoors and sky colours, from night to noon.
NIGHT_LEVEL = 0.12
NIGHT_COLOUR: RGB = (0.45, 0.55, 1.0)
HORIZON_COLOUR: RGB = (1.0, 0.62, 0.36)
HORIZON_LEVEL = 0.6
NOON_COLOUR: RGB = (1.0, 1.0, 1.0)
SKY_NOON: RGB = (125, 178, 235)
SKY_HORIZON: RGB = (240, 150, 95)
SKY_NIGHT: RGB = (22, 28, 52)            # the horizon at night: a town's glow
SKY_NOON_HORIZON: RGB = (200, 220, 240)   # haze: the horizon is paler than the zenith
SKY_DUSK_ZENITH: RGB = (70, 95, 160)      # the sky overhead stays blue while the horizon glows
SKY_NIGHT_ZENITH: RGB = (6, 9, 24)
TWILIGHT_DEG = 15.0                       # how long after sunset (and before sunrise) light fades out
SUN_SOUTH_TILT = 0.35                     # the sun's arc leans to -y so noon light is not vertical
MOON_DIRECTION: RGB = (-0.3, 0.4, 0.87)
HOUSE_KELVIN: float = Looks.model_fields["light_temperature"].default   # of the house files' light colours

# What the light does in a house.
SUN_IRRADIANCE = 9.0                  # noon sun on a surface facing it
SKY_AMBIENT = 0.18                    # bounced sky light filling a room with generous windows, by day
WINDOW_RADIANCE = 5.0                 # mean radiance of the outdoors seen through a window, by day
OUTDOOR_DAY = 2.5                     # the outdoors' level by day against a room's bounce light
OUTDOOR_DUSK = 0.9                    # ... at sunset (the sky stays bright while rooms darken)
OUTDOOR_NIGHT = 0.25                  # ... and at night (moon and street light)
OUTDOOR_SUN = 1.6                     # sunlight on the outdoors' surfaces, against OUTDOOR_DAY
OUTDOOR_FILL = 1.0                    # the sky's light on them
SKY_FILL = 0.55                       # the sky's light by day, a share of OUTDOOR_FILL
LIT_WINDOW = 0.5                      # a neighbour's lit window at night
GROUND_BELOW_FLOOR = 0.4              # the garden lies this far below the ground floor
MIN_OPENNESS = 0.25                   # rooms without windows still get light through their doors
WINDOW_REACH = 6.0                    # window area x this / floor area = fully open room
LAMP_POWER = 1.0                      # irradiance of an intensity-1 lamp at 1 m
AMBIENT_TINT = 0.35                   # share of the daylight colour that survives bouncing indoors
LAMP_BOUNCE = 0.35                    # share of a lamp's power that comes back as room ambient (/m^2)
FIXTURE_GLOW = 6.0                    # radiance of a switched-on lamp shade or bulb
MOONLIGHT = 0.12                      # the moon and night sky, as a share of sun_light's night gain
NIGHT_FLOOR = 0.002                   # ambient that never goes away (moon, street lights)


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
    red, green, blue = (int(round(c)) for c in sky)
    return SunLight(a, direction, gain, (red, green, blue))


def lamps_at(lights: Iterable[Light], kelvin: float) -> list[Light]:
    """``lights`` at colour temperature ``kelvin``: each colour channel scales as a black body's does
    from HOUSE_KELVIN to ``kelvin``, so at HOUSE_KELVIN every colour stays exactly as the house gives it."""
    shift = tuple(a / b for a, b in zip(black_body(kelvin), black_body(HOUSE_KELVIN)))
    return [replace(lt, color=(lt.color[0] * shift[0], lt.color[1] * shift[1], lt.color[2] * shift[2]))
            for lt in lights]


def dimmed(lights: Iterable[Light], level: float) -> list[Light]:
    """``lights`` with their dimmers at ``level`` (a share of full power): what they shed and what
    comes back as room ambient scale with it, and so does their fixtures' glow above its floor."""
    return [replace(lt, intensity=lt.intensity * level) for lt in lights]


def black_body(kelvin: float) -> RGB:
    """Linear-ish RGB (0..1) of a black body at ``kelvin`` (Tanner Helland's fit, 1000 K to 40000 K)."""
    t = kelvin / 100.0
    red = 255.0 if t <= 66 else 329.698727446 * (t - 60) ** -0.1332047592
    green = 99.4708025861 * math.log(t) - 161.1195681661 if t <= 66 else 288.1221695283 * (t - 60) ** -0.0755148492
    blue = 255.0 if t >= 66 else 0.0 if t <= 19 else 138.5177312231 * math.log(t - 10) - 305.0447927307
    red, green, blue = (min(max(c, 0.0), 255.0) / 255.0 for c in (red, green, blue))
    return (red, green, blue)


def indoor_daylight(sun: SunLight) -> np.ndarray:
    """The daylight's (moonlight's) colour and level as it reaches a room: light that bounced off white
    ceilings and walls keeps only part of the daylight's colour (the direct sun keeps all of it: a
    sunset paints patches, not the whole room)."""
    gain = np.asarray(sun.gain) * (1.0 if sun.angle <= 180.0 else MOONLIGHT)
    return float(gain.mean()) * (1.0 - AMBIENT_TINT) + gain * AMBIENT_TINT


def room_ambient(house: House, room: Room, sun: SunLight, lamps: Iterable[Light]) -> np.ndarray:
    """Bounced sky light of the room (more where its windows are larger for its floor) plus the bounce
    of its own lamps: the fill that reaches every surface (the windows' direct light is their own)."""
    window_area = sum(w.width * w.height for w in house.windows if w.room == room.id)
    openness = max(MIN_OPENNESS, min(1.0, WINDOW_REACH * window_area / max(room.area, 1.0)))
    bounce = sum((np.asarray(lt.color) * lt.intensity for lt in lamps if lt.room == room.id), np.zeros(3))
    return SKY_AMBIENT * openness * indoor_daylight(sun) + LAMP_POWER * LAMP_BOUNCE * bounce / max(room.area, 4.0) \
        + NIGHT_FLOOR


def fixture_glow(lamp: Light) -> np.ndarray:
    """The radiance of a switched-on light's own shade or bulb."""
    return np.asarray(lamp.color) * FIXTURE_GLOW * max(lamp.intensity, 0.3)


@dataclass(frozen=True)
class Outdoors:
    """The sun and what a window shows, in radiance: a sky (zenith to horizon, the sun's glow, clouds lit
    by ``light``), and a neighbourhood (lawn, hedges, trees, the neighbours' houses on rings around
    ``site``) that the shader lights with ``light`` and ``fill``; ``seed`` picks this house's
    neighbourhood."""
    sun_direction: RGB
    sun_irradiance: RGB                   # on a surface facing the sun, indoors' units
    sun_radiance: RGB                     # of the sun's disc
    sky_zenith: RGB
    sky_horizon: RGB
    light: RGB                            # the sun (moon) on an outdoor surface facing it
    fill: RGB                             # the sky's light on an upward outdoor surface
    lit_windows: RGB                      # radiance of a neighbour's lit window (at night)
    site: tuple[float, float, float, float]   # the house's bounds: centre x, y, half width, half depth
    ground_z: float                       # the garden's level
    seed: float                           # 0..1, this house's neighbourhood


def outdoors(sun: SunLight, house: House | None = None) -> Outdoors:
    """The outdoors under ``sun`` around ``house``: bright by day (brighter than any wall in the room,
    but not so bright that a window is a white hole: an indoor photo shows the garden), warm at dusk,
    dark blue at night with a few of the neighbours' windows lit."""
    direction = np.asarray(sun.direction)
    elevation = math.degrees(math.asin(max(-1.0, min(1.0, direction[2]))))
    day = sun.angle <= 180.0
    sun_up = min(1.0, max(0.0, elevation / 2.0 + 0.5)) if day else MOONLIGHT
    irradiance = SUN_IRRADIANCE * np.asarray(sun.gain) * sun_up
    # How high the sun stands (0 at the horizon, 1 at noon) and how much daylight is left at dusk.
    height = math.sqrt(max(math.sin(math.radians(sun.angle)), 0.0)) if day else 0.0
    below = 0.0 if day else min(sun.angle - 180.0, 360.0 - sun.angle)
    daylight = 1.0 if day else max(0.0, 1.0 - below / TWILIGHT_DEG)
    zenith = _lerp(_lin(SKY_NIGHT_ZENITH), _lerp(_lin(SKY_DUSK_ZENITH), _lin(SKY_NOON), height), daylight)
    horizon = _lerp(_lin(SKY_NIGHT), _lerp(_lin(SKY_HORIZON), _lin(SKY_NOON_HORIZON), height), daylight)
    level = OUTDOOR_DAY * daylight * (OUTDOOR_DUSK + (1.0 - OUTDOOR_DUSK) * height) + OUTDOOR_NIGHT * (1.0 - daylight)
    gain = np.asarray(sun.gain) / max(float(np.max(sun.gain)), 1e-6)           # the daylight's colour
    gain = gain if day else 0.5 + 0.5 * gain                  # moonlight looks grey more than blue
    light = gain * OUTDOOR_SUN * level * (sun_up if day else MOONLIGHT)
    # What lights the garden besides the sun: mostly the sky overhead, its colour diluted by bounces;
    # as strong at dusk as the sky is bright (a dusky zenith's dark blue is not a dark sky).
    sky = np.asarray(_lerp(horizon, zenith, 0.85))
    strength = daylight * SKY_FILL + (1.0 - daylight) * float(sky.mean())
    fill = (0.4 + 0.6 * sky / float(sky.mean())) * strength * OUTDOOR_FILL * level
    lamps_lit = max(0.0, 1.0 - daylight * (0.8 + 0.3 * height))   # the neighbours switch on at dusk
    glow = np.asarray(black_body(2700.0)) * LIT_WINDOW * lamps_lit
    site, ground_z = _site(house)
    return Outdoors(_rgb(direction), _rgb(irradiance), _rgb(irradiance * 4.0),
                    _rgb(np.asarray(zenith) * level), _rgb(np.asarray(horizon) * level),
                    _rgb(light), _rgb(fill), _rgb(glow), site, ground_z, _house_seed(house))


def _lin(rgb: RGB) -> RGB:
    red, green, blue = (int(round(c)) for c in rgb)
    return srgb8_to_linear((red, green, blue))


def _site(house: House | None) -> tuple[tuple[float, float, float, float], float]:
    """Where the house stands: its rooms' bounds (centre, half extents) and the garden's level."""
    if house is None or not house.rooms:
        return (0.0, 0.0, 6.0, 5.0), -GROUND_BELOW_FLOOR
    points = np.asarray([p for room in house.rooms for p in room.floor])
    low, high = points.min(axis=0), points.max(axis=0)
    centre, half = (low + high) / 2.0, (high - low) / 2.0
    floor = min(room.floor_z for room in house.rooms)
    return (float(centre[0]), float(centre[1]), float(half[0]), float(half[1])), floor - GROUND_BELOW_FLOOR


def _house_seed(house: House | None) -> float:
    """A number in [0, 1) fixed for a house (its number, or an imported home's name): the same house
    always looks out on the same neighbourhood, two houses on different ones."""
    if house is None:
        return 0.0
    return (zlib.crc32(f"{house.number}:{house.name}".encode()) % 10007) / 10007.0


@dataclass(frozen=True)
class WindowLight:
    """A window as an area light of its room."""
    window_id: str
    room: str
    centre: tuple[float, float, float]
    normal: tuple[float, float]           # into its room, on the floor plane
    area: float                           # m^2


def window_lights(house: House) -> list[WindowLight]:
    """Every window as an area light, in the order of the house's rooms (a room's windows together)."""
    room_order = [r.id for r in house.rooms]
    out = []
    for w in sorted(house.windows, key=lambda w: room_order.index(w.room)):
        room = house.room(w.room)
        at, normal = np.asarray(w.position[:2]), np.array([-math.sin(w.yaw), math.cos(w.yaw)])
        if room.contains(*(at + 0.3 * normal)) == room.contains(*(at - 0.3 * normal)):   # the outline misses it
            normal *= np.sign(normal @ (np.asarray(polygon_centroid(room.floor)) - at)) or 1.0
        elif not room.contains(*(at + 0.3 * normal)):
            normal = -normal
        out.append(WindowLight(w.id, w.room, w.position, (float(normal[0]), float(normal[1])), w.width * w.height))
    return out


@dataclass(frozen=True)
class SceneLights:
    """Every light of a scene at one world state: what a renderer draws, already decided."""
    sun: SunLight
    outdoors: Outdoors
    window_radiance: np.ndarray           # (3,) of a window's area light, by day
    lamps: tuple[Light, ...]              # the switched-on lights, at the state's colour temperature
    room_ambient: dict[str, np.ndarray]   # room id -> (3,) fill light

    @property
    def glow(self) -> dict[str, np.ndarray]:
        """Light id -> the radiance of its fixture, for every switched-on light."""
        return {lt.id: fixture_glow(lt) for lt in self.lamps}


def scene_lights(house: House, state: WorldState, lamps_on: bool = True) -> SceneLights:
    """The light of ``house`` at ``state``; ``lamps_on`` False leaves every lamp out (daylight only)."""
    sun = sun_light(state.sun_angle)
    on = [lt for lt in house.lights if state.lights.get(lt.id, False)] if lamps_on else []
    looks = state.settings()
    lamps = tuple(dimmed(lamps_at(on, looks.light_temperature), looks.lamp_dimmer))
    return SceneLights(sun, outdoors(sun, house), WINDOW_RADIANCE * indoor_daylight(sun), lamps,
                       {room.id: room_ambient(house, room, sun, lamps) for room in house.rooms})


def _rgb(values) -> RGB:
    red, green, blue = (float(v) for v in values)
    return (red, green, blue)


def _lerp(a, b, t: float) -> RGB:
    return tuple(x + (y - x) * t for x, y in zip(a, b))


def _unit(v) -> RGB:
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)
