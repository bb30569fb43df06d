"""Which renderer backend a process uses, chosen once.

``gl``: ravh_sim's OpenGL renderer on a headless EGL context (moderngl; Mesa llvmpipe on a CPU, a
GPU where there is one). ``tiny``: pybullet's TinyRenderer, the slow fallback when no GL context can
be made (and the benchmark baseline). ``auto`` picks ``gl`` when it starts, else ``tiny`` with a
one-line warning. One EGL context serves the whole process (a second one, or pybullet's EGL plugin
beside it, has crashed Mesa here).
"""
from __future__ import annotations

import sys
from functools import lru_cache
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import moderngl

BACKENDS = ("auto", "gl", "tiny")
QUALITIES = ("realistic", "fast")


def resolve_backend(requested: str) -> str:
    """'gl' or 'tiny' for a requested backend name (ValueError for an unknown one)."""
    if requested not in BACKENDS:
        raise ValueError(f"renderer must be one of {BACKENDS}, got {requested!r}")
    if requested == "tiny":
        return "tiny"
    if gl_context() is None:
        if requested == "gl":
            raise RuntimeError("the gl renderer needs an EGL OpenGL 4.3 context, which could not be made")
        print("ravh_sim: OpenGL (EGL) unavailable, falling back to TinyRenderer (slower)", file=sys.stderr)
        return "tiny"
    return "gl"


@lru_cache(maxsize=1)
def gl_context() -> moderngl.Context | None:
    """The process's moderngl context (EGL, headless), or None when none can be made."""
    try:
        import moderngl
        # the ignore: moderngl's stub types every **settings value as a dict, but backend is a str
        ctx = moderngl.create_context(standalone=True, backend="egl", require=430)  # type: ignore[arg-type]
    except Exception:                      # no libEGL, no driver, GL too old: all mean "no GL"
        return None
    return ctx
