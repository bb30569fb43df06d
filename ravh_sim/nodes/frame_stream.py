"""Sensor readings that fall due, streamed at each port's rate to whoever subscribes.

A sensor topic nobody subscribes to costs nothing: a reading is taken only for the topics that have
subscribers (no render, no JPEG for nobody). Camera frames are rendered and converted on the render
thread, stamped with the sim time of their pose. ``frame_policy`` says what happens when a frame falls
due while the last one still renders: ``drop`` (default) skips it, keeping the real-time factor, as a
real camera drops frames and as Nav2 and slam_toolbox expect of a clock that follows the wall clock
(logged once); ``wait`` keeps every frame by holding sim time until the last frame is out (the camera's
rate in sim time, a slower sim). A frame the renderer refuses (non-finite radiance) or fails is one
dropped frame, logged once per cause and counted on ``/diagnostics`` (ravh_sim.nodes.health).
"""
from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

from ravh_sim.nodes.appearance_budget import AppearanceBudget
from ravh_sim.nodes.health import SimHealth
from ravh_sim.nodes.render_thread import RenderThread
from ravh_sim.nodes.sim_topics import SimTopics
from ravh_sim.runtime import Agent
from ravh_sim.sensors.ports import SensorPort, Topic

CAMERA = "camera"                       # the port rendered on the render thread (the others are cheap)


class FramePolicy:
    """One camera frame of an agent renders at a time; ``policy`` says what becomes of the next one due
    meanwhile (``drop``: skipped; ``wait``: it waits for the last, and so does sim time)."""

    def __init__(self, policy: str) -> None:
        self.policy = policy                        # one of sim_params.FRAME_POLICIES
        self._frames: dict[str, Future] = {}        # agent -> its frame being rendered

    def may_start(self, agent: str) -> bool:
        """Whether ``agent``'s next frame may be rendered (under ``wait``, once the last is out)."""
        busy = self._frames.get(agent)
        if busy is None or busy.done():
            return True
        if self.policy == "drop":
            return False
        busy.result()
        return True

    def started(self, agent: str, frame: Future) -> None:
        self._frames[agent] = frame


class FrameStream:
    """Takes and publishes the readings that fall due; renders camera frames, streamed and captured."""

    def __init__(self, topics: SimTopics, render_thread: RenderThread, policy: FramePolicy, health: SimHealth,
                 budget: AppearanceBudget, rtf: float, warn: Callable[[str], None]) -> None:
        self.topics, self.runtime, self.render_thread = topics, topics.runtime, render_thread
        self.policy, self.health, self.budget = policy, health, budget
        self._rtf, self._warn = rtf, warn
        self._dropping = False

    def stream(self, agent: Agent, port: SensorPort) -> None:
        """A reading of ``port`` that fell due: published on the topics that have subscribers (none:
        not taken); a camera frame goes to the render thread, as the frame policy says when it is busy."""
        rt = self.runtime
        topics = self.topics.subscribed(agent, port)
        if not topics:
            rt.skip(agent, port.name)
            return
        if port.name != CAMERA:
            start = time.monotonic()
            self.topics.publish_sensor(agent, port, rt.read(agent, port.name), self.topics.now(), topics)
            self.budget.note_reading((agent.name, port.name), time.monotonic() - start)
            return
        if not self.policy.may_start(agent.name):
            rt.skip(agent, port.name)
            self.health.frame_skipped()
            if not self._dropping:
                self._dropping = True
                self._warn(
                    f"the camera cannot keep {agent.rates[port.name]:g} Hz at real-time factor {self._rtf:g}: "
                    "frames that fall due while one renders are dropped (frame_policy:=wait keeps every "
                    "frame by slowing the sim)")
            return
        self.policy.started(agent.name, self.render_thread.submit(
            self._stream_frame, agent, port, rt.frame_later(agent), self.topics.now(), topics))

    def _stream_frame(self, agent: Agent, port: SensorPort, frame: Callable[[], Any], stamp: float,
                      topics: tuple[Topic, ...]) -> None:
        """On the render thread: a streamed frame; one that fails is dropped (counted, its cause logged
        once) and the stream goes on with the next."""
        try:
            self._render(agent, port, frame, stamp, topics)
        except Exception:  # never die from a frame: _render counted it
            pass

    def render_later(self, agent: Agent, port: SensorPort, frame: Callable[[], Any], stamp: float,
                     topics: tuple[Topic, ...]) -> Future:
        """``frame`` rendered and published on the render thread, after the frames already queued; the
        future raises what the frame failed with."""
        return self.render_thread.submit(self._render, agent, port, frame, stamp, topics)

    def _render(self, agent: Agent, port: SensorPort, frame: Callable[[], Any], stamp: float,
                topics: tuple[Topic, ...]) -> None:
        """On the render thread: render ``frame`` and publish it on ``topics``, stamped ``stamp`` (when it
        was asked for: the sim time of its pose). A frame that fails is counted on /diagnostics and raised."""
        start = time.monotonic()
        try:
            data = frame()
        except Exception as e:
            self.health.frame_failed(f"{agent.name}'s {port.name} frame at t={stamp:.3f} s", e)
            raise
        self.topics.publish_sensor(agent, port, data, stamp, topics)
        seconds = time.monotonic() - start
        self.health.frame_rendered(seconds)
        self.budget.note_reading((agent.name, port.name), seconds)
