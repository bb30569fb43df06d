"""One way to validate every data file (settings, robot profiles, houses): pydantic models.

Each file kind declares its fields, types and bounds as a pydantic model (strict: ``1.5`` is not an
integer, ``true`` is not a number, unknown keys are errors). :func:`validate` turns pydantic's report
into the project's one-line :class:`FileFieldError` naming the file and the field path of the first
problem; :func:`read_text` reads a file so that unreadable, oversized or non-UTF-8 files fail the same
way, and :func:`load_yaml` parses YAML without aliases, so what a file expands to is bounded by its size.
"""
from __future__ import annotations

import math
import types
from pathlib import Path
from typing import Annotated, Any, TypeVar

import yaml
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError
from pydantic_core import ErrorDetails

from ravh_sim.errors import FileFieldError, UserError

M = TypeVar("M", bound=BaseModel)
SHOWN_INPUT = 40          # characters of a bad value quoted in an error (never echo a huge input)
MAX_FILE_BYTES = 1 << 20  # a settings file or robot profile; the shipped ones are ~2 KB


class Strict(BaseModel):
    """Base of every file schema: no type coercion, no unknown keys, immutable."""
    model_config = ConfigDict(strict=True, extra="forbid", frozen=True)


def _finite(v: float) -> float:
    if not math.isfinite(v):
        raise ValueError(f"expected a finite number, got {v}")
    return v


FINITE = AfterValidator(_finite)     # in Annotated[float, Field(...), FINITE], what number() returns, spelled out
                                     # where a type checker must read the annotation


# bounds of a robot profile (config/robots/*.yaml), its body and its sensors' sections: anything a real
# mobile robot could have; beyond them a value is a slip (a 1e6 m radius, a 0.5 px camera)
Length = Annotated[float, Field(gt=0.0, le=10.0), FINITE]           # m, body and mounting
Rate = Annotated[float, Field(gt=0.0, le=1000.0), FINITE]           # Hz
Sigma = Annotated[float, Field(ge=0.0, le=10.0), FINITE]
Range = Annotated[float, Field(gt=0.0, le=1000.0), FINITE]          # m


def number(ge: float | None = None, le: float | None = None, gt: float | None = None,
           lt: float | None = None) -> Any:
    """A finite float field with bounds; strict floats take ints (YAML/JSON write 1 for 1.0), not bools."""
    return Annotated[float, Field(ge=ge, le=le, gt=gt, lt=lt), FINITE]


def vector(item: Any, n: int) -> Any:
    """A fixed-length tuple field that files write as a list (``tuple[item, ...n times]``, built at run time)."""
    return Annotated[types.GenericAlias(tuple, (item,) * n), Field(strict=False)]


def validate(model: type[M], data: Any, source: str | Path) -> M:
    """``model`` from ``data``, or a one-line FileFieldError naming ``source`` and the first bad field."""
    try:
        return model.model_validate(data)
    except ValidationError as e:
        first = e.errors(include_url=False)[0]
        raise FileFieldError(str(source), field_path(first["loc"]), _problem(first)) from None
    except RecursionError:
        raise FileFieldError(str(source), "(top level)", "nested too deeply") from None


def field_path(loc: tuple[int | str, ...]) -> str:
    """('agents', 0, 'start') -> 'agents[0].start'."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "(top level)"


def _problem(error: ErrorDetails) -> str:
    msg = error["msg"].removeprefix("Value error, ")
    if error["type"] == "missing":
        return "missing"
    if error["type"] == "extra_forbidden":
        return "unknown key"
    if error["type"] in ("model_type", "dict_type"):
        return f"expected a mapping, got {shown(error.get('input'))}"
    return f"{msg}, got {shown(error.get('input'))}"


def shown(value: Any) -> str:
    """A short quote of a value for an error message."""
    text = repr(value)
    return text if len(text) <= SHOWN_INPUT else text[:SHOWN_INPUT - 3] + "..."


def read_text(path: Path, what: str, max_bytes: int = MAX_FILE_BYTES) -> str:
    """The UTF-8 text of ``path``; unreadable, oversized or undecodable files raise a one-line UserError."""
    try:
        with open(path, "rb") as f:
            data = f.read(max_bytes + 1)               # never more: a pipe or /dev/zero has no size to stat
    except OSError as e:
        raise UserError(f"{path}: cannot read {what}: {e.strerror}") from None
    if len(data) > max_bytes:
        raise FileFieldError(str(path), "(file)", f"over the {max_bytes // 1024} KiB limit for a {what}")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise FileFieldError(str(path), f"byte {e.start}", f"not UTF-8 text ({what})") from None


class _NoAliasLoader(yaml.SafeLoader):
    """SafeLoader that refuses aliases (``*name``): a few KB of nested aliases (a "billion laughs")
    expand to gigabytes; without them a document has at most as many nodes as its file has bytes."""

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.AliasEvent):
            mark = self.peek_event().start_mark
            raise yaml.composer.ComposerError(None, None, "aliases (*name) are not allowed", mark)
        return super().compose_node(parent, index)


def load_yaml(text: str, path: str | Path) -> Any:
    """The YAML document ``text`` (from ``path``); aliases, bad syntax and deep nesting are one-line errors."""
    try:
        return yaml.load(text, Loader=_NoAliasLoader)     # a SafeLoader
    except RecursionError:
        raise FileFieldError(str(path), "(top level)", "nested too deeply") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f"line {mark.line + 1} column {mark.column + 1}" if mark else "(top level)"
        raise FileFieldError(str(path), where, f"invalid YAML: {getattr(e, 'problem', None) or e}") from None
