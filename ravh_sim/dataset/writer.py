"""DatasetWriter: puts captures, the footprint and the map on disk in the dataset layout (no ROS).

Kept free of rclpy so the format is unit-tested with plain arrays and the recorder node stays a thin
adapter. Crash safety comes from the order of writes: a capture's files are each written atomically
(:func:`~ravh_sim.dataset.layout.atomic_write`), and only then is its line appended to
captures.jsonl and fsynced. A process killed at any point leaves at most orphan files, which readers
ignore because no line names them.
"""
from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from ravh_msgs_py.capture import CaptureEvent
from ravh_sim.dataset import layout
from ravh_sim.errors import UserError
from ravh_sim.files import named
from ravh_sim.nav.grid import Grid
from ravh_sim.nav.mapio import write_map
from ravh_sim.sensors.suite import SENSORS
from ravh_sim.world.footprint import dump_footprint


class DatasetWriter:
    """Writes one dataset folder; refuses a folder that already holds one (no silent mixing)."""

    def __init__(self, directory: str | Path) -> None:
        self.dir = Path(directory)
        try:
            self.dir.mkdir(parents=True, exist_ok=True)
            if (self.dir / layout.DATASET_JSON).exists():
                raise UserError(f"{self.dir} already holds a dataset; record into a new folder")
            try:
                self._rows = open(self.dir / layout.CAPTURES_JSONL, "xb", buffering=0)
            except FileExistsError:
                raise UserError(f"{self.dir} already holds {layout.CAPTURES_JSONL}; record into a new folder") from None
            for kind in layout.capture_files(0):
                (self.dir / kind).mkdir(exist_ok=True)
        except OSError as e:
            raise UserError(f"{e.filename or self.dir}: cannot write the dataset: {e.strerror}") from None
        self.count = 0
        self._room_types: dict[str, str] = {}
        self._agent_facts: dict[str, dict[str, Any]] = {}    # side file (camera.json) -> agent -> entry

    # ------------------------------------------------------------------ once (or on change)
    def write_footprint(self, footprint: dict[str, Any]) -> None:
        """footprint.json and settings.json; called again when the world changes, the latest wins."""
        layout.atomic_write(self.dir / layout.FOOTPRINT_JSON, dump_footprint(footprint).encode())
        layout.atomic_write(self.dir / layout.SETTINGS_JSON,
                            (json.dumps(footprint["settings"], indent=1, sort_keys=True) + "\n").encode())
        self._room_types = {row["room"]: row["room_type"] for row in footprint["instances"]}

    def write_meta(self, house: int, agents: Sequence[str], raid: dict[str, Any] | None = None,
                   bag: bool = False) -> None:
        """dataset.json: what was recorded, when, and the caller's description of the raid."""
        meta = {"format": layout.FORMAT, "house": int(house), "agents": list(agents),
                "created": datetime.now(UTC).isoformat(timespec="seconds"),
                "raid": dict(raid or {}), "bag": layout.BAG_DIR if bag else None}
        layout.atomic_write(self.dir / layout.DATASET_JSON, (json.dumps(meta, indent=1) + "\n").encode())

    def write_map(self, grid: Grid) -> None:
        """map/map.pgm + map.yaml, each replaced atomically (the PGM first: the YAML names it)."""
        folder = self.dir / layout.MAP_DIR
        folder.mkdir(exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=layout.TMP_PREFIX, dir=folder))
        try:
            pgm, yaml_path = write_map(grid, staging, layout.MAP_NAME)
            for path in (pgm, yaml_path):
                with open(path, "rb") as f:
                    os.fsync(f.fileno())
                os.replace(path, folder / path.name)
        finally:
            shutil.rmtree(staging, ignore_errors=True)

    # ------------------------------------------------------------------ per capture
    def write_capture(self, event: CaptureEvent, values: Mapping[str, Any]) -> int:
        """Store one capture and return its index.

        ``values``: every sensor's dataset values by topic key (ravh_sim.sensors.suite), as
        :meth:`SimRuntime.sample` reads them and the recorder decodes them from the topics; each
        sensor port turns its own into files and fields.
        """
        index = self.count
        files = layout.capture_files(index)
        room = event.room
        row: dict[str, Any] = {"index": index, "stamp": float(event.stamp), "agent": event.agent,
                               "pose": [float(v) for v in event.pose], "odom": [float(v) for v in event.odom],
                               "room": room, "room_type": self._room_types.get(room) if room else None,
                               "files": files}
        stored = [port.encode(values) for port in SENSORS]
        contents = {kind: data for part in stored for kind, data in part.files.items()}
        if contents.keys() != files.keys():
            raise ValueError(f"the sensors stored files {sorted(contents)}, they declare {sorted(files)}")
        for kind, path in files.items():
            layout.atomic_write(self.dir / path, contents[kind])
        for part in stored:
            row.update(part.row)
            for name, fact in part.agent_facts.items():
                facts = self._agent_facts.setdefault(name, {})
                if facts.get(event.agent) != fact:
                    facts[event.agent] = fact
                    layout.atomic_write(self.dir / name, (json.dumps(facts, indent=1) + "\n").encode())
        self._append_row((json.dumps(row) + "\n").encode())
        self.count += 1
        return index

    def _append_row(self, line: bytes) -> None:
        """Append one line to captures.jsonl and fsync it; a write that fails part-way (a full disk)
        is cut off again, so the file never holds a torn line that a later line would follow."""
        start = self._rows.tell()
        try:
            done = 0
            while done < len(line):
                done += self._rows.write(line[done:])
            os.fsync(self._rows.fileno())
        except OSError as e:
            os.ftruncate(self._rows.fileno(), start)
            self._rows.seek(start)
            raise named(e, self.dir / layout.CAPTURES_JSONL) from None

    def close(self) -> None:
        self._rows.close()

    def __enter__(self) -> DatasetWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
