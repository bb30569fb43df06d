"""The sim node's sensor streams in this process: lazy sensors and frames rendered off the control loop.

The camera's renderer is replaced by a stand-in that counts its renders and is as slow as a test says
(in sim time, so nothing here is timed), the node runs on the real runtime and publishes over DDS.
"""
from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import pytest
import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph import start_rclpy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Image, LaserScan
from std_srvs.srv import Trigger

from ravh_msgs_py import names as n
from ravh_msgs_py.capture import CaptureEvent
from ravh_sim.nodes import convert
from ravh_sim.render.gl_develop import RenderError
from ravh_sim.render.views import RenderedViews
from ravh_sim.sensors import imaging

# deep enough that the test, spinning the node in its own thread, loses nothing
KEEP_ALL = QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE)
PERIOD = 0.1                       # the camera's and the laser's period (giraff profile, 10 Hz)


class StandInRenderer:
    """Flat views after ``slow()`` says the render may end; records the sim time each render began and ended."""

    def __init__(self, node, width: int, height: int) -> None:
        self.node, self.shape = node, (height, width)
        self.began: list[float] = []
        self.ended: list[float] = []
        self.slow: Callable[[float], bool] = lambda began: True
        self.fail: Callable[[], bool] = lambda: False      # True: this render raises (a refused frame)

    def render(self, position, rotation, exposure=None, radiance=False, development=None) -> RenderedViews:
        began = self.node.runtime.time
        self.began.append(began)
        give_up = time.monotonic() + 60.0
        while not self.slow(began) and time.monotonic() < give_up:
            time.sleep(0.002)
        self.ended.append(self.node.runtime.time)
        if self.fail():
            raise RenderError("3 pixels of non-finite radiance (instances [7]): the stand-in's bad frame")
        h, w = self.shape
        return RenderedViews(np.full((h, w, 3), 128, np.uint8), np.full((h, w), 2.0, np.float32),
                             np.ones((h, w), np.uint16), np.zeros((h, w), bool))

    def release(self) -> None:
        pass


class Session:
    """A sim node (house 20, real time) with a stand-in renderer, and a test node beside it."""

    def __init__(self, policy: str, **parameters) -> None:
        from ravh_sim.nodes.sim_node import SimNode
        start_rclpy()
        self.sim = SimNode({"house": 20, "seed": 0, "renderer": "tiny", "frame_policy": policy, **parameters})
        self.agent = self.sim.runtime.agents[0]
        camera = self.agent.sensors["camera"]
        camera.renderer = self.renderer = StandInRenderer(self.sim, camera.width, camera.height)
        laser = self.agent.sensors["scan"]
        self.scans_cast = 0
        cast = laser.scan

        def counted(*args, **kwargs):
            self.scans_cast += 1
            return cast(*args, **kwargs)
        laser.scan = counted
        self.node = rclpy.create_node(f"streams_{time.monotonic_ns()}")
        self.executor = SingleThreadedExecutor()
        for node in (self.sim, self.node):
            self.executor.add_node(node)
        self.got: dict[str, list] = {}

    def listen(self, kind, topic: str) -> list:
        self.got[topic] = []
        self.node.create_subscription(kind, topic, self.got[topic].append, KEEP_ALL)
        return self.got[topic]

    def spin_until(self, condition: Callable[[], bool], timeout: float = 120.0) -> None:
        end = time.monotonic() + timeout
        while not condition():
            assert time.monotonic() < end, "timed out"
            self.executor.spin_once(timeout_sec=0.01)

    def capture(self) -> Trigger.Response:
        return self.captures(1)[0]

    def captures(self, count: int) -> list[Trigger.Response]:
        """``count`` capture requests sent at once, before the node has taken any; their replies."""
        client = self.node.create_client(Trigger, n.CAPTURE_SERVICE)
        assert client.wait_for_service(timeout_sec=30)
        futures = [client.call_async(Trigger.Request()) for _ in range(count)]
        self.spin_until(lambda: all(f.done() for f in futures))
        return [f.result() for f in futures]

    def close(self) -> None:
        self.renderer.slow = lambda began: True     # a frame still rendering would wait for sim time that
        self.executor.shutdown()                    # no longer passes once the executor stops (60 s)
        self.sim.close()
        self.sim.destroy_node()
        self.node.destroy_node()


def stamps(msgs: list) -> np.ndarray:
    return np.array([convert.seconds(m.clock if isinstance(m, Clock) else m.header.stamp) for m in msgs])


@pytest.fixture(scope="class")
def session():
    s = Session("drop")
    yield s
    s.close()


class TestDroppingFrames:
    def test_nobody_subscribed_renders_and_scans_nothing_but_captures(self, session, monkeypatch):
        jpegs = []
        encode = imaging.encode_jpeg
        monkeypatch.setattr(imaging, "encode_jpeg", lambda *a: jpegs.append(1) or encode(*a))
        session.spin_until(lambda: session.sim.runtime.time >= 2.0)
        camera = session.agent.sensors["camera"]
        assert session.renderer.began == [] and session.scans_cast == 0 and jpegs == []
        assert camera.count >= 2.0 / PERIOD        # every due frame used up its number
        reply = session.capture()
        assert reply.success
        assert len(session.renderer.began) == 1 and session.scans_cast == 1 and len(jpegs) == 1

    def test_a_subscriber_that_joins_gets_frames_of_its_kind_only(self, session, monkeypatch):
        jpegs = []
        encode = imaging.encode_jpeg
        monkeypatch.setattr(imaging, "encode_jpeg", lambda *a: jpegs.append(1) or encode(*a))
        rendered = len(session.renderer.began)
        images = session.listen(Image, n.COLOR_IMAGE)
        session.spin_until(lambda: len(images) >= 3)
        assert len(session.renderer.began) >= rendered + 3
        assert jpegs == [] and session.scans_cast == 1      # no subscriber on compressed images, on scans
        assert images[-1].header.frame_id == n.CAMERA_OPTICAL_FRAME

    def test_clock_and_scans_keep_their_rate_while_a_frame_renders(self, session):
        # a renderer so slow that the sim runs a whole second while it renders one frame
        session.renderer.slow = lambda began: session.sim.runtime.time >= began + 1.0
        clock, scans = session.listen(Clock, n.CLOCK), session.listen(LaserScan, n.SCAN)
        images = session.listen(Image, n.COLOR_IMAGE)
        session.spin_until(lambda: len(images) >= 3)
        frames = stamps(images)
        assert np.all(np.diff(frames) >= 1.0 - 1e-6)        # frames that fell due while one rendered: dropped
        window = (frames[0], frames[-1])
        scan_t, clock_t = stamps(scans), stamps(clock)
        scan_t = scan_t[(scan_t >= window[0]) & (scan_t <= window[1])]
        clock_t = clock_t[(clock_t >= window[0]) & (clock_t <= window[1])]
        assert len(scan_t) >= (window[1] - window[0]) / PERIOD - 1
        assert np.allclose(np.diff(scan_t), PERIOD, atol=1e-3)          # every scan, none late
        assert np.diff(clock_t).max() < 2 / session.sim.params.clock_rate       # on physics steps: no gap

    def test_a_capture_waits_for_its_frame_while_the_clock_goes_on(self, session):
        # the renderer ends a frame only once the sim has run a second past its start: a capture
        # rendered on the control loop's tick would stall the clock and never end
        session.renderer.slow = lambda began: session.sim.runtime.time >= began + 1.0
        clock, images = session.listen(Clock, n.CLOCK), session.listen(Image, n.COLOR_IMAGE)
        rendered = len(session.renderer.ended)
        reply = session.capture()
        assert reply.success, reply.message
        event = CaptureEvent.from_json(reply.message)
        # its frame, stamped at its instant (to the nanosecond of a header stamp)
        session.spin_until(lambda: np.isclose(stamps(images), event.stamp, rtol=0, atol=1e-9).any())
        ended = np.array(session.renderer.ended[rendered:])
        began = np.array(session.renderer.began[rendered:rendered + len(ended)])
        assert len(ended) and np.all(ended >= began + 1.0)    # every render, the capture's too, saw the sim run on
        clock_t = stamps(clock)
        clock_t = clock_t[clock_t >= event.stamp]
        assert np.diff(clock_t).max() < 2 / session.sim.params.clock_rate   # on physics steps: no gap


class TestWaitingForFrames:
    def test_every_frame_is_kept_by_slowing_the_sim(self):
        s = Session("wait")
        try:
            # each render lasts while the sim could run three camera periods at real time
            ends: dict[float, float] = {}
            s.renderer.slow = lambda began: time.monotonic() >= ends.setdefault(began, time.monotonic() + 3 * PERIOD)
            images = s.listen(Image, n.COLOR_IMAGE)
            s.spin_until(lambda: len(images) >= 6)
            assert np.allclose(np.diff(stamps(images)[1:]), PERIOD, atol=1e-3)    # the first: the first step
        finally:
            s.close()


def diagnostics(msg: DiagnosticArray) -> tuple[int, dict[str, str]]:
    """The sim's status in a /diagnostics message: its level and its values."""
    (status,) = [s for s in msg.status if s.name == "ravh_sim: sim"]
    return status.level, {v.key: v.value for v in status.values}


class TestBadFrames:
    def test_a_frame_that_fails_is_dropped_counted_and_the_stream_goes_on(self, session):
        images, health = session.listen(Image, n.COLOR_IMAGE), session.listen(DiagnosticArray, n.DIAGNOSTICS)
        session.spin_until(lambda: len(images) >= 2)
        bad, published = len(session.renderer.began), len(images)   # the next render raises, later ones not
        session.renderer.fail = lambda: len(session.renderer.began) == bad + 1
        session.spin_until(lambda: len(images) >= published + 3)     # the stream goes on after it
        assert len(session.renderer.ended) >= bad + 1 and session.sim.health.failed == 1
        assert session.sim.health.published >= published + 3
        session.spin_until(lambda: health and diagnostics(health[-1])[1]["frames_failed"] == "1", 30)
        level, values = diagnostics(health[-1])
        assert level == DiagnosticStatus.WARN and "non-finite radiance" in values["last_failure"]
        assert int(values["frames_dropped"]) >= 1 and float(values["render_ms"]) >= 0
        session.renderer.fail = lambda: False

    def test_a_capture_whose_frame_fails_replies_with_the_reason(self, session):
        session.renderer.fail = lambda: True
        try:
            reply = session.capture()
        finally:
            session.renderer.fail = lambda: False
        assert not reply.success and "non-finite radiance" in reply.message
        reply = session.capture()                                  # the node is alive and captures again
        assert reply.success, reply.message


class TestCaptureIdentity:
    def test_captures_while_sim_time_stands_still_get_stamps_of_their_own(self):
        """Lockstep with nothing granted: sim time stands still. Four captures requested at once are four
        captures, each with its own stamp, each frame published at its stamp (they would share one)."""
        s = Session("drop", lockstep=True)
        try:
            images = s.listen(Image, n.COLOR_IMAGE)
            still = s.sim.runtime.time
            replies = s.captures(4)
            assert all(r.success for r in replies), [r.message for r in replies]
            events = [CaptureEvent.from_json(r.message) for r in replies]
            captured = sorted(e.stamp for e in events)
            assert len(set(captured)) == 4 and captured[0] >= still
            assert np.diff(captured).min() > 0
            s.spin_until(lambda: all(np.isclose(stamps(images), t, rtol=0, atol=1e-9).any() for t in captured))
            assert s.sim.runtime.time <= captured[-1] + 1e-9         # the sim took only the steps it needed
        finally:
            s.close()
