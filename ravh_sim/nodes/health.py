"""The sim node's health on ``/diagnostics``: how fast sim time runs, what the camera published, dropped and
failed, how long frames take to render and how many captures wait.

``diagnostic_msgs/DiagnosticArray`` on ``/diagnostics`` is what every ROS monitoring tool reads
(``rqt_robot_monitor``, ``diagnostic_aggregator``, ``ros2 topic echo``). A frame that cannot be rendered is
one dropped frame, not a dead node: :meth:`SimHealth.frame_failed` counts it and says once per cause why,
so a fault that repeats every frame does not flood the log, and the count and the last cause stay on
``/diagnostics`` for as long as the node runs.
"""
from __future__ import annotations

import re
import threading
import time
from collections import deque
from collections.abc import Callable

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from ravh_sim.nodes import convert

NAME = "ravh_sim: sim"
HARDWARE_ID = "ravh_sim"
RTF_WINDOW_S = 5.0              # wall seconds over which the real-time factor is measured
RENDER_WINDOW = 20              # frames over which render time is averaged
SLOW_RTF_SHARE = 0.8            # below this share of the asked real-time factor: WARN


class SimHealth:
    """Counters of the node's frames and captures; written from the executor and the render thread."""

    def __init__(self, rtf: float, warn: Callable[[str], None]) -> None:
        self.rtf = rtf
        self._warn = warn
        self._lock = threading.Lock()
        self.published = 0                 # camera frames published (streamed and captured)
        self.skipped = 0                   # due while the last one rendered (frame_policy drop)
        self.failed = 0                    # the renderer raised: dropped, the node goes on
        self.last_failure = ""
        self._causes: set[str] = set()     # failure causes already logged
        self._render_s: deque[float] = deque(maxlen=RENDER_WINDOW)
        self._clock: deque[tuple[float, float]] = deque()      # (wall, sim) samples for the RTF

    def frame_rendered(self, seconds: float) -> None:
        with self._lock:
            self.published += 1
            self._render_s.append(seconds)

    def frame_skipped(self) -> None:
        with self._lock:
            self.skipped += 1

    def frame_failed(self, what: str, error: BaseException) -> None:
        """A frame the renderer refused or failed: counted; its cause logged the first time it is seen."""
        cause = f"{type(error).__name__}: {error}"
        kind = re.sub(r"\d+", "#", cause)           # the same fault with other counts is one cause
        with self._lock:
            self.failed += 1
            self.last_failure = f"{what}: {cause}"
            new = kind not in self._causes
            self._causes.add(kind)
        if new:
            self._warn(f"dropped {what}: {cause} (counted on /diagnostics; logged once per cause)")

    def sim_time(self, sim_s: float) -> None:
        """Note the sim time now (called once per tick) for the measured real-time factor."""
        now = time.monotonic()
        self._clock.append((now, sim_s))
        while len(self._clock) > 2 and now - self._clock[1][0] > RTF_WINDOW_S:
            self._clock.popleft()

    def measured_rtf(self) -> float:
        if len(self._clock) < 2:
            return 0.0
        (w0, s0), (w1, s1) = self._clock[0], self._clock[-1]
        return (s1 - s0) / (w1 - w0) if w1 > w0 else 0.0

    def status(self, captures_waiting: int) -> DiagnosticStatus:
        """The node's health as one DiagnosticStatus: WARN while frames fail or sim time lags."""
        with self._lock:
            render_ms = 1000 * sum(self._render_s) / len(self._render_s) if self._render_s else 0.0
            published, skipped, failed, last = self.published, self.skipped, self.failed, self.last_failure
        rtf = self.measured_rtf()
        problems = []
        if failed:
            problems.append(f"{failed} frames failed")
        if self.rtf > 0 and len(self._clock) >= 2 and rtf < SLOW_RTF_SHARE * self.rtf:
            problems.append(f"real-time factor {rtf:.2f} of {self.rtf:g}")
        values = {"real_time_factor": f"{rtf:.3f}", "real_time_factor_asked": f"{self.rtf:g}",
                  "frames_published": str(published), "frames_dropped": str(skipped + failed),
                  "frames_skipped_busy": str(skipped), "frames_failed": str(failed),
                  "last_failure": last, "render_ms": f"{render_ms:.1f}", "capture_queue": str(captures_waiting)}
        return DiagnosticStatus(
            level=DiagnosticStatus.WARN if problems else DiagnosticStatus.OK, name=NAME,
            message="; ".join(problems) or "ok", hardware_id=HARDWARE_ID,
            values=[KeyValue(key=k, value=v) for k, v in values.items()])

    def array(self, stamp: float, captures_waiting: int) -> DiagnosticArray:
        return DiagnosticArray(header=convert.header(stamp, ""), status=[self.status(captures_waiting)])
