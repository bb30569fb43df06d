"""Which renderer backend a process uses, chosen once.

``gl``: ravh_sim's OpenGL renderer on a headless EGL context (moderngl; Mesa llvmpipe on a CPU, a
GPU where there is one). ``tiny``: pybullet's TinyRenderer, the slow fallback when no GL context can
be made (and the benchmark baseline). ``auto`` picks ``gl`` when it starts, else ``tiny``, with a
warning (once, this module's ``logging`` logger) naming the exception that stopped OpenGL;
:func:`choose_backend` also returns it. One EGL context serves the whole process (a second one, or
pybullet's EGL plugin beside it, has crashed Mesa here).
"""
from __future__ import annotations

import ctypes
import logging
import threading
from collections.abc import Callable
from ctypes.util import find_library
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import moderngl

BACKENDS = ("auto", "gl", "tiny")
QUALITIES = ("realistic", "fast", "dataset")
"""``realistic``: the live stream's shading; ``fast``: one plain pass; ``dataset``: realistic shading of the
library's dataset level of detail (finer models and textures: captures that make datasets)."""


@dataclass(frozen=True)
class BackendChoice:
    """The backend a requested name resolves to, and why it is not the one asked for (``auto``
    falling back to ``tiny``: the exception that stopped OpenGL, ``"OSError: ..."``), else None."""
    backend: str                       # gl | tiny
    fallback_reason: str | None = None


def choose_backend(requested: str) -> BackendChoice:
    """The backend for a requested name, with the reason of a fallback (ValueError for an unknown name;
    RuntimeError, naming why, for ``gl`` when OpenGL cannot start). The first fallback of the process
    is logged as a warning naming the exception."""
    global _fallback_logged
    if requested not in BACKENDS:
        raise ValueError(f"renderer must be one of {BACKENDS}, got {requested!r}")
    if requested == "tiny":
        return BackendChoice("tiny")
    start = gl_start()
    if start.context is None:
        if requested == "gl":
            raise RuntimeError(f"the gl renderer needs an EGL OpenGL 4.3 context, which could not be made: "
                               f"{start.failure}")
        if not _fallback_logged:
            _fallback_logged = True
            log.warning("ravh_sim: OpenGL (EGL) could not start (%s); falling back to TinyRenderer (slower, "
                        "and its images differ)", start.failure)
        return BackendChoice("tiny", start.failure)
    return BackendChoice("gl")


def resolve_backend(requested: str) -> str:
    """'gl' or 'tiny' for a requested backend name (see :func:`choose_backend`, which also says why)."""
    return choose_backend(requested).backend


@dataclass(frozen=True)
class GLStart:
    """The outcome of starting the process's OpenGL context: the context, or why there is none."""
    context: moderngl.Context | None
    failure: str | None = None         # "ExceptionType: message" of what stopped it


def gl_start() -> GLStart:
    """Start the process's moderngl context (EGL, headless) once; later calls return the same outcome."""
    global _gl
    with _gl_lock:
        if _gl is None:
            try:
                _gl = GLStart(_create_context())
            except Exception as e:         # no libEGL, no driver, GL too old: all mean "no GL"
                _gl = GLStart(None, f"{type(e).__name__}: {e}")
        return _gl


def gl_context() -> moderngl.Context | None:
    """The process's moderngl context (EGL, headless), or None when none can be made (why:
    :func:`gl_start`)."""
    return gl_start().context


def _create_context() -> moderngl.Context:
    import moderngl
    # the ignore: moderngl's stub types every **settings value as a dict, but backend is a str
    return moderngl.create_context(standalone=True, backend="egl", require=430)  # type: ignore[arg-type]


log = logging.getLogger(__name__)
_gl: GLStart | None = None             # one EGL context serves the whole process (see the module's doc)
_gl_lock = threading.Lock()
_fallback_logged = False


GL_TRIANGLES = 0x0004


@dataclass(frozen=True)
class UnlockedGL:
    """The GL calls of a frame that wait for llvmpipe, made through ctypes, which lets go of the GIL
    during a foreign call (moderngl holds it): the sim's other threads run while a frame is drawn. A
    draw waits when llvmpipe's queue of binned scenes is full (a frame's later passes wait there for
    its earlier ones to be rasterised), a read-back when the frame is not finished (``finish`` first)."""
    finish: Callable[[], None]
    use_program: Callable[[int], None]
    bind_vertex_array: Callable[[int], None]
    draw_arrays: Callable[[int, int, int], None]

    def draw(self, vao: moderngl.VertexArray, first: int = 0, vertices: int = 3) -> None:
        """What ``vao.render(first=first, vertices=vertices)`` does for triangles, without the GIL."""
        self.use_program(vao.program.glo)
        self.bind_vertex_array(vao.glo)
        self.draw_arrays(GL_TRIANGLES, first, vertices)


@lru_cache(maxsize=1)
def unlocked_gl() -> UnlockedGL:
    """The GL calls of the process's context (current on the calling thread) that release the GIL."""
    egl = ctypes.CDLL(find_library("EGL") or "libEGL.so.1")     # the library moderngl's context is on
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]

    def function(name: str, *arguments: type) -> Any:
        address = egl.eglGetProcAddress(name.encode())
        if not address:
            raise RuntimeError(f"EGL has no {name}")
        return ctypes.CFUNCTYPE(None, *arguments)(address)

    return UnlockedGL(function("glFinish"), function("glUseProgram", ctypes.c_uint),
                      function("glBindVertexArray", ctypes.c_uint),
                      function("glDrawArrays", ctypes.c_uint, ctypes.c_int, ctypes.c_int))
