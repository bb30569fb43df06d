"""The appearance model: one typed model of the sun, lights, doors, paint and object models.

:class:`Looks` declares every appearance field with its type and bounds, once. It is at the same time
the record a footprint keeps and a world is rebuilt from, the live state of a running world (which
keeps a revision per field, so renderers ask which fields changed), and by its fields the vocabulary
of settings files and of appearance requests. A *global knob* is a field annotated with a
:class:`Knob` (``sun_angle``): one number for the whole house, whose range, preset words and random
draw its Knob declares; settings files set it under ``lights:``, requests by its name. The other fields
map the house's ids to one choice each.

An appearance request is one JSON object saying what to change; the reply says what changed::

    {"sun_angle": "night", "lights": {"ceiling": "on", "Lamp_0": "random"},
     "doors": {"Door_2": "closed"}, "paint": {"Bedroom_1": {"walls": "brick"}},
     "models": {"Bed_0": 2, "all": "random"}, "dressing": "tidy", "seed": 7}

Keys are all optional; ``seed`` drives this request's random choices; ``randomise: SEED`` alone
re-draws lights, doors, paint and models as the settings' "random" does. Replies use the envelope of
:mod:`ravh_msgs_py.query`. Only the syntax lives here (no simulator), so clients validate offline.
"""
from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from random import Random
from types import MappingProxyType
from typing import Annotated, Any, Literal, Self, TypeVar

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, GetCoreSchemaHandler, WrapSerializer
from pydantic_core import CoreSchema, core_schema

from ravh_msgs_py.query import BAD_REQUEST, QueryError, decode

# The one vocabulary of appearance: requests, settings files, the CLI and the simulator use these names.
SUN_PRESETS = {"day": 100.0, "sunset": 180.0, "night": 200.0}      # sun angle in degrees of each word
SWITCH = ("on", "off", "random")
DOOR = ("open", "closed", "random")
LIGHT_GROUPS = ("all", "ceiling", "lamps")   # lamps: every light that is not a ceiling light
SURFACES = ("walls", "floor")
DRESSING = ("none", "tidy", "lived-in")   # what a house holds besides the paper's objects (ravh_sim.world.dressing)
SEED_MAX = 2**32 - 1       # the one seed range: settings files, command-line flags and requests

Seed = Annotated[int, Field(strict=True, ge=0, le=SEED_MAX)]
V = TypeVar("V")
# id -> choice, read-only (a value handed to a World or written into a footprint never drifts)
Items = Annotated[Mapping[str, V], AfterValidator(MappingProxyType), WrapSerializer(lambda v, dump: dump(dict(v)))]


@dataclass(frozen=True)
class Knob:
    """A global appearance number: its unit and range, the words a settings file or a request may
    write for it, and how "random" draws it. Annotating a :class:`Looks` field with one makes it a knob
    of settings files, requests, the live state and the footprint; the field's default, if it has one,
    is what a settings file or a record that does not name the knob gets."""
    unit: str
    low: float
    high: float
    presets: Mapping[str, float] = field(default_factory=dict)
    random: tuple[float, float] | None = None    # "random" draws uniformly from this range...
    stream: str = ""                              # ...with the random stream of this name

    @property
    def words(self) -> tuple[str, ...]:
        return (*self.presets, *(("random",) if self.random else ()))

    @property
    def expected(self) -> str:
        words = f" or one of {', '.join(self.words)}" if self.words else ""
        return f"expected {self.unit} in [{self.low:g}, {self.high:g}]{words}"

    def check(self, choice: Any) -> Any:
        """``choice`` if it is a number in range or one of the words; otherwise ValueError."""
        if isinstance(choice, str) and choice in self.words:
            return choice
        if isinstance(choice, bool) or not isinstance(choice, (int, float)) or not math.isfinite(choice) \
                or not self.low <= choice <= self.high:
            raise ValueError(self.expected)
        return choice

    def value(self, choice: float | str, stream: Callable[[str], Random]) -> float:
        """The number a checked ``choice`` stands for; ``stream(name)`` gives a seeded random stream."""
        if choice == "random" and self.random is not None:
            return stream(self.stream).uniform(*self.random)
        return float(self.presets[choice] if isinstance(choice, str) else choice)

    def __get_pydantic_core_schema__(self, source: Any, handler: GetCoreSchemaHandler) -> CoreSchema:
        return core_schema.float_schema(ge=self.low, le=self.high, allow_inf_nan=False)


SUN = Knob("degrees", 0.0, 360.0, SUN_PRESETS, random=(0.0, 240.0), stream="sun/angle")


class Looks(BaseModel):
    """One explicit choice for every appearance item of a house."""
    model_config = ConfigDict(frozen=True, extra="forbid")

    sun_angle: Annotated[float, SUN]       # 0 sunrise, 90 noon, 180 sunset, >180 night
    lights: Items[bool]                    # light id -> on
    doors: Items[bool]                     # door id -> open
    paint: Items[Items[str]]               # room id -> {"walls": paint, "floor": paint}
    models: Items[Annotated[int, Field(ge=0)]]   # object id -> model variant
    # every light's colour temperature; at the default, the colours the house files give the lights
    light_temperature: Annotated[float, Knob("kelvin", 1000.0, 10000.0)] = 2700.0
    # every lamp's dimmer, a share of its power; at the default, the power the house files give it
    lamp_dimmer: Annotated[float, Knob("share of full power", 0.1, 1.0)] = 1.0
    # the things people put in a home (plates, books, pillows, rugs, curtains...), placed from the seed;
    # at the default, none: a record from before dressing is the bare house it was
    dressing: Literal["none", "tidy", "lived-in"] = "none"

    def changed(self, **fields: Any) -> Self:
        """A copy with ``fields`` replaced, validated like the original (a ValueError if one is bad)."""
        return type(self).model_validate({**dict(self), **fields})


KNOBS: dict[str, Knob] = {name: knob for name, info in Looks.model_fields.items()
                          for knob in info.metadata if isinstance(knob, Knob)}
KEYS = (*KNOBS, "lights", "doors", "paint", "models", "dressing", "seed", "randomise")


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
    for name, knob in KNOBS.items():
        if name in data:
            try:
                knob.check(data[name])
            except ValueError as e:
                raise QueryError(BAD_REQUEST, f"{name}: {e}, got {data[name]!r}") from None
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
    if "dressing" in data and data["dressing"] not in DRESSING:
        raise QueryError(BAD_REQUEST, f"dressing: expected one of {', '.join(DRESSING)}, got {data['dressing']!r}")
    for key in ("seed", "randomise"):
        if key in data and not (_is_int(data[key]) and 0 <= data[key] <= SEED_MAX):
            raise QueryError(BAD_REQUEST, f"{key}: expected an integer in 0..{SEED_MAX}")
    return data


def _mapping(data: dict, key: str) -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise QueryError(BAD_REQUEST, f"{key}: expected a JSON object of name -> value")
    return value


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)
