"""The one thread that touches the renderers.

The process's GL context is made, and stays current, on the thread that builds the runtime
(ravh_sim.render.backend), so the runtime is built there, and every camera frame and every change to
the world's appearance runs there too, in the order asked. Physics, /clock, odometry, /tf and scans
keep their rates meanwhile: the renderer waits for llvmpipe with the GIL released.
"""
from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any


class RenderThread:
    """A queue of work run one at a time on a thread of its own."""

    def __init__(self) -> None:
        self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ravh_render")

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future:
        """``fn(*args)`` queued after the work already there."""
        return self._executor.submit(fn, *args)

    def call(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """``fn(*args, **kwargs)`` run on the render thread (after the work queued before it); its result."""
        return self._executor.submit(fn, *args, **kwargs).result()

    def shutdown(self) -> None:
        self._executor.shutdown()
