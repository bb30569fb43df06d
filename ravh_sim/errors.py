"""User-facing errors: a mistake in a file, a flag or a request, reported in one clear line.

Everything a user can get wrong raises :class:`UserError` (or a subclass); the CLI and the nodes
print its message instead of a traceback. Code bugs stay ordinary exceptions.
"""
from __future__ import annotations

from pathlib import Path


class UserError(Exception):
    """A problem the user can fix: bad file, unknown name, invalid value."""


class FileFieldError(UserError):
    """A malformed field in a data file; the message names the file and the field path."""

    def __init__(self, path: str | Path, field: str, problem: str) -> None:
        self.path, self.field, self.problem = str(path), field, problem
        super().__init__(f"{path}: {field}: {problem}")


class UnknownNameError(UserError):
    """A name (house, room, object, tag...) that does not exist; the message lists what does."""

    def __init__(self, kind: str, name: object, valid: list) -> None:
        self.kind, self.name, self.valid = kind, name, list(valid)
        shown = ", ".join(str(v) for v in self.valid[:60])
        more = f" (+{len(self.valid) - 60} more)" if len(self.valid) > 60 else ""
        super().__init__(f"unknown {kind} {name!r}; valid: {shown}{more}")
