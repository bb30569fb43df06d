"""Requested captures: every sensor of an agent at one stamp, on every topic, then the event on
``ravh/capture`` (pose, room) so recorders can store it as one dataset sample.

A capture is known by its stamp, and no two captures of an agent share one: a capture requested while
sim time still stands at the previous capture's stamp (a paused or lockstep sim, a loaded machine, two
requests back to back at ``--rtf 0``) waits for the next physics step (in lockstep the sim grants itself
that one step). So every message of a capture (image, depth, instances, camera_infos, scan, the event)
carries one stamp that names that capture alone, which is what rosbag2, message_filters' exact-time
synchroniser and our recorder match on; a ROS header has no sequence number to carry instead.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from concurrent.futures import Future

from rclpy.task import Future as RosFuture
from std_msgs.msg import String

from ravh_msgs_py.capture import CaptureEvent
from ravh_sim.nodes.frame_stream import CAMERA, FrameStream
from ravh_sim.nodes.sim_topics import SimTopics
from ravh_sim.runtime import Agent
from ravh_sim.sensors.suite import SENSORS


class Captures:
    """Takes captures in rclpy coroutine callbacks; counts those in flight (waiting for a stamp or a frame)."""

    def __init__(self, topics: SimTopics, frames: FrameStream, grant_step: Callable[[int], None]) -> None:
        self.topics, self.runtime, self.frames = topics, topics.runtime, frames
        self._grant_step = grant_step                 # lockstep: let sim time run to a step
        self.rendering = 0
        self.waiting = 0                              # for a step past the agent's last capture stamp
        self._stamps: dict[str, float] = {}           # agent -> its last capture's stamp
        self._step_waiters: list[RosFuture] = []      # done at the next physics step

    @property
    def in_flight(self) -> int:
        return self.rendering + self.waiting

    def stepped(self) -> None:
        """Physics stepped: the captures waiting for a new stamp go on."""
        waiters, self._step_waiters = self._step_waiters, []
        for step in waiters:
            step.set_result(None)

    async def capture(self, agent: Agent) -> CaptureEvent:
        """A capture of ``agent``. Everything is taken now (stamp, pose, the frame's number); the camera
        frame is rendered on the render thread, after the frames already queued, and the event waits for
        it, the tick not: physics and /clock go on meanwhile. At real-time factor 0 (as fast as possible)
        the tick does wait (see :attr:`rendering`): there is no rate to keep, and a sim racing on would
        push the capture's readings out of its readers' queues before they took them."""
        rt, stamp = self.runtime, await self.stamp(agent)
        event = rt.capture_event(agent)
        rendered = []
        self.rendering += 1
        try:
            for port in SENSORS:
                if port.name == CAMERA:
                    rendered.append(self.frames.render_later(agent, port, rt.frame_later(agent), stamp, port.topics))
                else:
                    self.topics.publish_sensor(agent, port, rt.read(agent, port.name), stamp, port.topics)
            for frame in rendered:
                await _awaitable(frame)
        finally:
            self.rendering -= 1
        self.topics.agents[agent.name]["capture"].publish(String(data=event.to_json()))
        return event

    async def stamp(self, agent: Agent) -> float:
        """Sim time now, once it is past ``agent``'s last capture stamp (waiting for the next physics step
        if need be; in lockstep the sim grants itself that step): every capture has a stamp of its own."""
        rt = self.runtime
        self.waiting += 1
        try:
            while rt.time <= self._stamps.get(agent.name, -math.inf):
                self._grant_step(rt.steps + 1)
                step = RosFuture()
                self._step_waiters.append(step)
                await step
        finally:
            self.waiting -= 1
        stamp = self._stamps[agent.name] = self.topics.now()
        return stamp


def _awaitable(future: Future) -> RosFuture:
    """A future of another thread as one an rclpy coroutine callback can await (the executor resumes
    the callback on its turns until the future is done); its result or exception."""
    awaited = RosFuture()

    def hand_over(done: Future) -> None:
        error = done.exception()
        if error is None:
            awaited.set_result(done.result())
        else:
            awaited.set_exception(error)
    future.add_done_callback(hand_over)
    return awaited
