"""The appearance-change language: one JSON object says what to change; the reply says what changed.

Example::

    {"sun_angle": "night", "lights": {"ceiling": "on", "Lamp_0": "random"},
     "doors": {"Door_2": "closed"}, "paint": {"Bedroom_1": {"walls": "brick"}},
     "models": {"Bed_0": 2, "all": "random"}, "seed": 7}

Keys are all optional; ``seed`` drives this request's random choices; ``randomise: SEED`` alone
re-draws lights, doors, paint and models as the settings' "random" does. Replies use the envelope of
:mod:`ravh_msgs_py.query`. Only the syntax lives here (no simulator), so clients validate offline.
"""
from __future__ import annotations

import json
import math
from typing import Any

from ravh_msgs_py.query import BAD_REQUEST, QueryError, decode

KEYS = ("sun_angle", "lights", "doors", "paint", "models", "seed", "randomise")
# The one vocabulary of appearance: requests, settings files, the CLI and the simulator use these names.
SUN_PRESETS = {"day": 100.0, "sunset": 180.0, "night": 200.0}      # sun angle in degrees of each word
SUN_WORDS = (*SUN_PRESETS, "random")
SWITCH = ("on", "off", "random")
DOOR = ("open", "closed", "random")
LIGHT_GROUPS = ("all", "ceiling", "lamps")   # lamps: every light that is not a ceiling light
SURFACES = ("walls", "floor")
SEED_MAX = 2**32 - 1       # the one seed range: settings files, command-line flags and requests


def request(**changes: Any) -> str:
    return json.dumps(changes)


def parse(text: str | bytes | dict) -> dict[str, Any]:
    """Check the syntax of an appearance request (names are checked against the house later)."""
    data = decode(text)
    if not isinstance(data, dict) or not data:
        raise QueryError(BAD_REQUEST, 'expected a non-empty JSON object like {"sun_angle": "night"}',
                         list(KEYS))
    for key in data:
        if key not in KEYS:
            raise QueryError(BAD_REQUEST, f"unknown key {key!r}", list(KEYS))
    if "sun_angle" in data:
        _sun(data["sun_angle"])
    for key, allowed in (("lights", SWITCH), ("doors", DOOR)):
        for item, value in _mapping(data, key).items():
            if value not in allowed and not isinstance(value, bool):
                raise QueryError(BAD_REQUEST, f"{key}.{item}: expected one of {', '.join(allowed)}, "
                                              f"got {value!r}")
    for room, surfaces in _mapping(data, "paint").items():
        if not isinstance(surfaces, dict) or not surfaces or set(surfaces) - set(SURFACES):
            raise QueryError(BAD_REQUEST, f"paint.{room}: expected {{walls: PAINT, floor: PAINT}}")
        for surface, paint in surfaces.items():
            if not isinstance(paint, str):
                raise QueryError(BAD_REQUEST, f"paint.{room}.{surface}: expected a paint name")
    for obj, value in _mapping(data, "models").items():
        ok = value in ("random", "default") or _is_int(value) and value >= 0 or (
            isinstance(value, dict) and set(value) == {"inherit"} and isinstance(value["inherit"], str))
        if not ok:
            raise QueryError(BAD_REQUEST, f"models.{obj}: expected default, random, an index >= 0 or "
                                          f"{{inherit: OBJECT_ID}}, got {value!r}")
    for key in ("seed", "randomise"):
        if key in data and not (_is_int(data[key]) and 0 <= data[key] <= SEED_MAX):
            raise QueryError(BAD_REQUEST, f"{key}: expected an integer in 0..{SEED_MAX}")
    return data


def _sun(value: Any) -> None:
    if value in SUN_WORDS:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or not 0 <= value <= 360:
        raise QueryError(BAD_REQUEST, f"sun_angle: expected degrees in [0, 360] or one of "
                                      f"{', '.join(SUN_WORDS)}, got {value!r}")


def _mapping(data: dict, key: str) -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise QueryError(BAD_REQUEST, f"{key}: expected a JSON object of name -> value")
    return value


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)
