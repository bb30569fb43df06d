"""The direct engine: a raid in one process, with no DDS in the way.

The same :class:`~ravh_sim.runtime.SimRuntime`, behaviours (:mod:`ravh_sim.behaviours`) and
:class:`~ravh_sim.dataset.writer.DatasetWriter` as the ROS engine (``ravh raid``: sim, behaviour and
recorder processes), stepped in lockstep: the behaviour is updated every control period of sim
time, each capture it asks for is rendered and written at once, and physics steps as fast as the
machine allows. Nothing here depends on wall time or thread timing, so the same house, settings
and seed give byte-identical capture files and captures.jsonl (only dataset.json's ``created``
and raid.json's ``wall_s`` and ``cpu_s`` say when and how fast it ran).

The API other code calls::

    from ravh_sim.raids.direct import GridSpec, WandererSpec, PosesSpec, record
    summary = record("out/h20_noon", 20, GridSpec(max_nodes=5),
                     settings={"lights": {"sun_angle": 90, "ceiling": "off"}}, seed=3)

``settings`` is a settings file's content (keys as in config/default.yaml, only those it names
override the defaults); it is saved as ``raid_settings.yaml`` in the output folder, as the ROS
engine does, so the raid can be rerun either way.
"""
from __future__ import annotations

import json
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import yaml

from ravh_sim.behaviours.grid import GridSweep
from ravh_sim.behaviours.wanderer import Wanderer
from ravh_sim.behaviours.waypoints import (
    NODE_RULES,
    ORDERS,
    PAPER_AGENT_RADIUS,
    Layout,
    grid_nodes,
    light_waypoints,
    paper_grid_nodes,
)
from ravh_sim.dataset import layout
from ravh_sim.dataset.writer import DatasetWriter
from ravh_sim.errors import UserError
from ravh_sim.nav.follower import CONTROL_PERIOD, PathFollower
from ravh_sim.poses import Pose2D
from ravh_sim.raids.outcome import Outcome
from ravh_sim.runtime import Agent, SimRuntime

SETTINGS_FILE = "raid_settings.yaml"
MAX_SIM_S = 3600.0               # sim seconds after which a behaviour that never ends is stopped
WRITES_IN_FLIGHT = 4             # captures encoded and written behind the renderer at most


@dataclass(frozen=True)
class GridSpec:
    """The Grid behaviour: lattice nodes every ``spacing`` m, ``captures_per_node`` in a full turn.
    ``nodes``: "paper" (the original's rule, the paper's node counts) or "cover" (nodes on the robot's
    own free space); see :mod:`ravh_sim.behaviours.waypoints`."""
    spacing: float = 0.5
    captures_per_node: int = 10
    max_nodes: int = 0                      # visit only the first N nodes (0: all)
    nodes: str = "paper"
    name = "grid"


@dataclass(frozen=True)
class WandererSpec:
    """The Wanderer: room to room under the ceiling lights, a capture every ``capture_period`` s."""
    order: str = "once"                     # once | cyclic | random (cyclic never ends: set a limit)
    capture_period: float = 0.5
    seed: int = 0                           # seed of the random room order
    name = "wanderer"


@dataclass(frozen=True)
class PosesSpec:
    """Scripted poses: the robot is put at each (x, y, yaw) in turn and captures there, one
    control period of sim time apart (to replay a recorded trajectory, or sample chosen views)."""
    poses: tuple[Pose2D, ...]
    name = "poses"


BehaviourSpec = GridSpec | WandererSpec | PosesSpec
BEHAVIOURS: dict[str, type] = {"grid": GridSpec, "wanderer": WandererSpec}


def record(out: str | Path, house: int | str, behaviour: BehaviourSpec | str = "wanderer", *,
           settings: dict[str, Any] | None = None, seed: int | None = None, max_captures: int = 0,
           max_sim_s: float = MAX_SIM_S, raid: dict[str, Any] | None = None, renderer: str = "auto",
           progress: Callable[[int], None] | None = None) -> dict[str, Any]:
    """Record one raid of ``house`` into the new folder ``out``; return its summary (also written
    to ``out/raid.json``: the ROS engine's keys, and ``cpu_s``, the CPU seconds this process used).

    behaviour: a spec, or "grid" / "wanderer" for the paper's parameters. settings: settings-file
    overrides (None: config/default.yaml). seed: every random choice (None: the settings' seed).
    max_captures / max_sim_s: stop early (0 captures: no limit). raid: extra metadata stored in
    dataset.json's ``raid``. progress: called with the capture count after every capture.
    """
    spec = BEHAVIOURS[behaviour]() if isinstance(behaviour, str) and behaviour in BEHAVIOURS else behaviour
    if not isinstance(spec, (GridSpec, WandererSpec, PosesSpec)):
        raise UserError(f"unknown behaviour {behaviour!r}; valid: {', '.join(BEHAVIOURS)} or a spec")
    if isinstance(spec, WandererSpec) and spec.order not in ORDERS:
        raise UserError(f"wanderer order must be one of {', '.join(ORDERS)}, got {spec.order!r}")
    if isinstance(spec, GridSpec) and spec.nodes not in NODE_RULES:
        raise UserError(f"grid nodes must be one of {', '.join(NODE_RULES)}, got {spec.nodes!r}")
    out = Path(out)
    start, cpu_start = time.monotonic(), time.process_time()
    with DatasetWriter(out) as writer:         # refuses a folder with a dataset before writing anything
        settings_path = out / SETTINGS_FILE
        layout.atomic_write(settings_path, yaml.safe_dump(settings or {}, sort_keys=False).encode())
        runtime = SimRuntime(house, settings_path, seed, renderer=renderer)
        try:
            home = runtime.house
            imported = {"house_name": home.name, "attribution": home.attribution} if home.name else {}
            meta = {"house": home.number, **imported, "engine": "direct", "behaviour": _describe(spec),
                    "seed": runtime.world.state.seed, **(raid or {})}
            session = _Session(runtime, writer, progress)
            writer.write_meta(runtime.house.number, [session.agent.name], meta)
            writer.write_footprint(runtime.footprint())
            writer.write_map(runtime.navigation.obstacle_map())      # what the ROS recorder gets on /map
            try:
                status = session.run(spec, max_captures, max_sim_s)
            finally:
                session.finish_writes()
        finally:
            runtime.close()
    rows = session.rows
    summary = {**meta, "status": status, "captures": len(rows),
               "rooms_visited": sorted({r for r in rows if r}),
               "wall_s": round(time.monotonic() - start, 1), "cpu_s": round(time.process_time() - cpu_start, 1),
               "sim_s": round(session.sim_span, 1)}
    layout.atomic_write(out / layout.RAID_JSON, (json.dumps(summary, indent=1) + "\n").encode())
    return summary


def _describe(spec: BehaviourSpec) -> dict[str, Any]:
    """The spec as stored in dataset.json (scripted poses by count, not listed twice)."""
    if isinstance(spec, PosesSpec):
        return {"name": spec.name, "poses": len(spec.poses)}
    return {"name": spec.name, **asdict(spec)}


class _Session:
    """One agent's behaviour in lockstep with the runtime, writing every capture it asks for.

    PNG encoding and the fsynced writes run in one worker thread behind the renderer (OpenCV and
    file I/O release the GIL), in submission order, so the files are those of a serial run."""

    def __init__(self, runtime: SimRuntime, writer: DatasetWriter,
                 progress: Callable[[int], None] | None) -> None:
        self.runtime, self.writer, self.progress = runtime, writer, progress
        self.agent: Agent = runtime.agents[0]
        self.rows: list[str | None] = []          # the room of each capture
        self.first_stamp: float | None = None
        self.sim_span = 0.0
        self.steps = max(1, round(CONTROL_PERIOD / runtime.sim.dt))
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ravh_direct_write")
        self._writes: deque[Future] = deque()

    def run(self, spec: BehaviourSpec, max_captures: int, max_sim_s: float) -> str:
        if isinstance(spec, PosesSpec):
            for pose in spec.poses:
                self.agent.robot.set_command(0.0, 0.0)
                self.agent.robot.teleport(*pose)
                self.capture()
                self.runtime.step(self.steps)
            return Outcome.DONE.status()
        behaviour = self._behaviour(spec)
        dt = self.steps * self.runtime.sim.dt
        end = self.runtime.time + max_sim_s
        while not behaviour.done:
            if self.runtime.time >= end:
                return Outcome.TIMED_OUT.status(limit=f"{max_sim_s:.0f} sim s")
            for _ in behaviour.update(dt):
                self.capture()
                if max_captures and len(self.rows) >= max_captures:
                    return Outcome.STOPPED.status(captures=max_captures)
            self.runtime.step(self.steps)
        return Outcome.DONE.status()

    def _behaviour(self, spec: GridSpec | WandererSpec) -> GridSweep | Wanderer:
        rt, robot = self.runtime, self.agent.robot
        follower = PathFollower(robot, rt.navigation, self.agent.profile)
        layout, grid, start = Layout.of(rt.house), rt.navigation.map(), robot.pose[:2]
        if isinstance(spec, GridSpec):
            if spec.nodes == "paper":
                walkable = rt.navigation.walkable(PAPER_AGENT_RADIUS)
                nodes = paper_grid_nodes(layout, walkable, grid, start, spec.spacing)
            else:
                nodes = grid_nodes(layout, grid, start, spec.spacing)
            return GridSweep(follower, nodes[:spec.max_nodes] if spec.max_nodes > 0 else nodes,
                             spec.captures_per_node)
        return Wanderer(follower, light_waypoints(layout, grid, start), spec.order, spec.capture_period,
                        spec.seed)

    def capture(self) -> None:
        """Read every sensor at this sim time and write the sample (as the sim node's capture service
        publishes it and the recorder stores it)."""
        event, values = self.runtime.sample(self.agent)
        if len(self._writes) >= WRITES_IN_FLIGHT:
            self._writes.popleft().result()          # re-raises a failed write here
        self._writes.append(self._worker.submit(self.writer.write_capture, event, values))
        self.rows.append(event.room)
        if self.first_stamp is None:
            self.first_stamp = event.stamp
        self.sim_span = event.stamp - self.first_stamp
        if self.progress:
            self.progress(len(self.rows))

    def finish_writes(self) -> None:
        """Wait for every queued write; the first failure is raised (nothing is lost silently)."""
        self._worker.shutdown(wait=True)
        while self._writes:
            self._writes.popleft().result()
