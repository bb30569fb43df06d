"""The ground-truth query language: JSON in, JSON out, defined once for the CLI, Python and ROS.

A request is a JSON object ``{"query": NAME, ...arguments}``; a reply is ``{"ok": true, "result": ...}``
or ``{"ok": false, "error": {"code": ..., "message": ..., "valid": [...]}}``. :data:`QUERIES` lists every
query with its arguments; :func:`parse_request` checks a request against it so that the engine only
ever sees well-formed requests, and a bad one gets a structured error instead of an exception.
This module is plain Python with no dependency on the simulator, so clients can import it alone.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

# error codes
BAD_JSON = "bad_json"
BAD_REQUEST = "bad_request"
UNKNOWN_QUERY = "unknown_query"
UNKNOWN_ID = "unknown_id"
INTERNAL = "internal"
BUSY = "busy"              # the sim refused the request to keep its rate (a burst): send it again later

# Requests are small; anything longer is refused before decoding, and no reply quotes more than a few
# hundred characters of what it was sent (a 10 MB request must not come back or stay in memory).
MAX_REQUEST_CHARS = 65_536
MAX_MESSAGE_CHARS = 300
MAX_COORDINATE = 1e6     # m: numbers in queries are positions; beyond this they are slips, not places


@dataclass(frozen=True)
class Arg:
    name: str
    kind: type | tuple[type, ...]
    required: bool = True
    help: str = ""


@dataclass(frozen=True)
class QuerySpec:
    name: str
    help: str
    args: tuple[Arg, ...] = field(default_factory=tuple)


_NUM = (int, float)
QUERIES: dict[str, QuerySpec] = {q.name: q for q in (
    QuerySpec("help", "list the queries and their arguments"),
    QuerySpec("rooms", "rooms, optionally of one type", (Arg("type", str, False, "room type"),)),
    QuerySpec("room", "one room: type, area, floor outline, doors, objects", (Arg("id", str),)),
    QuerySpec("objects_in_room", "objects in a room, optionally with a tag",
              (Arg("room", str), Arg("tag", str, False))),
    QuerySpec("objects_with_tag", "objects carrying a tag", (Arg("tag", str),)),
    QuerySpec("object", "one object's pose, box, room, model and mask colour", (Arg("id", str),)),
    QuerySpec("room_at", "the room containing a point (null outside)",
              (Arg("x", _NUM), Arg("y", _NUM))),
    QuerySpec("door", "the rooms a door joins and its state", (Arg("id", str),)),
    QuerySpec("connectivity", "room graph: rooms joined by doors (open_only: only open doors)",
              (Arg("open_only", bool, False),)),
    QuerySpec("counts", "numbers of objects and rooms by category, in the house or one room",
              (Arg("room", str, False),)),
    QuerySpec("tags", "every object tag in the house with its count"),
)}


class QueryError(Exception):
    """A request that cannot be answered; carries the structured error reply."""

    def __init__(self, code: str, message: str, valid: list | None = None) -> None:
        super().__init__(message)
        self.code, self.message, self.valid = code, message, list(valid or [])

    def reply(self) -> dict[str, Any]:
        return error_reply(self.code, self.message, self.valid)


def ok_reply(result: Any) -> dict[str, Any]:
    return {"ok": True, "result": result}


def error_reply(code: str, message: str, valid: list | None = None) -> dict[str, Any]:
    err: dict[str, Any] = {"code": code, "message": shorten(message, MAX_MESSAGE_CHARS)}
    if valid:
        err["valid"] = list(valid)
    return {"ok": False, "error": err}


def shorten(text: str, limit: int) -> str:
    return text if len(text) <= limit else text[:limit - 20] + f"... ({len(text)} chars)"


def request(query: str, **args: Any) -> str:
    """Encode a request (what a client sends)."""
    return json.dumps({"query": query, **args})


def decode(text: str | bytes | dict) -> Any:
    """A request as decoded JSON (a dict passes through); bad JSON raises :class:`QueryError`."""
    if isinstance(text, dict):
        return text
    if isinstance(text, (str, bytes)) and len(text) > MAX_REQUEST_CHARS:
        raise QueryError(BAD_REQUEST, f"request of {len(text)} characters is over the limit of {MAX_REQUEST_CHARS}")
    try:
        return json.loads(text)
    except (ValueError, TypeError) as e:
        raise QueryError(BAD_JSON, f"request is not valid JSON: {e}") from None
    except RecursionError:
        raise QueryError(BAD_JSON, "request is nested too deeply") from None


def parse_request(text: str | bytes | dict) -> tuple[str, dict[str, Any]]:
    """Validate a request; returns (query name, arguments) or raises :class:`QueryError`."""
    data = decode(text)
    if not isinstance(data, dict):
        raise QueryError(BAD_REQUEST, 'request must be a JSON object like {"query": "rooms"}')
    name = data.get("query")
    if not isinstance(name, str) or name not in QUERIES:
        raise QueryError(UNKNOWN_QUERY, f"unknown query {name!r}", sorted(QUERIES))
    spec = QUERIES[name]
    args = {k: v for k, v in data.items() if k != "query"}
    allowed = {a.name for a in spec.args}
    for key in args:
        if key not in allowed:
            raise QueryError(BAD_REQUEST, f"query {name!r} takes no argument {key!r}", sorted(allowed))
    for arg in spec.args:
        if arg.name not in args:
            if arg.required:
                raise QueryError(BAD_REQUEST, f"query {name!r} needs argument {arg.name!r}")
            continue
        value = args[arg.name]
        if isinstance(value, bool) and arg.kind is not bool or not isinstance(value, arg.kind):
            raise QueryError(BAD_REQUEST, f"argument {arg.name!r} of {name!r} has the wrong type "
                                          f"({type(value).__name__})")
        if isinstance(value, (int, float)) and not isinstance(value, bool) and not (
                -MAX_COORDINATE <= value <= MAX_COORDINATE):                  # False for NaN too
            raise QueryError(BAD_REQUEST, f"argument {arg.name!r} must be finite and within "
                                          f"+-{MAX_COORDINATE:g}")
    return name, args


def describe() -> list[dict[str, Any]]:
    """The query catalogue, as the ``help`` query returns it."""
    return [{"query": q.name, "help": q.help,
             "args": [{"name": a.name, "required": a.required} for a in q.args]} for q in QUERIES.values()]
