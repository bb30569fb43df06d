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
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from ravh_sim.dataset import layout
from ravh_sim.errors import UserError
from ravh_sim.nav.grid import Grid
from ravh_sim.nav.mapio import write_map
from ravh_sim.sensors import imaging
from ravh_sim.world.footprint import dump_footprint

Pose2D = Sequence[float]


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
            for folder, _ in layout.CAPTURE_FILES.values():
                (self.dir / folder).mkdir(exist_ok=True)
        except OSError as e:
            raise UserError(f"{e.filename or self.dir}: cannot write the dataset: {e.strerror}") from None
        self.count = 0
        self._room_types: dict[str, str] = {}
        self._cameras: dict[str, dict[str, Any]] = {}

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
    def write_capture(self, stamp: float, agent: str, pose: Pose2D, odom: Pose2D, room: str | None,
                      rgb: np.ndarray, depth: np.ndarray, instance: np.ndarray, scan_ranges: np.ndarray,
                      scan_meta: dict[str, float], camera: dict[str, Any] | None = None) -> int:
        """Store one capture and return its index.

        rgb: (H, W, 3) uint8 RGB; depth: (H, W) float metres, NaN/inf = none; instance: (H, W)
        instance ids; scan_meta: angle_min, angle_increment, range_min, range_max (LaserScan
        fields); camera: the agent's intrinsics (width, height, K, D, ...), stored in camera.json.
        """
        h, w = rgb.shape[:2]
        if rgb.shape != (h, w, 3) or depth.shape != (h, w) or instance.shape != (h, w):
            raise ValueError(f"image shapes differ: rgb {rgb.shape}, depth {depth.shape}, "
                             f"instance {instance.shape}")
        if instance.size and (instance.min() < 0 or instance.max() > np.iinfo(np.uint16).max):
            raise ValueError("instance ids must fit in 16 bits")
        index = self.count
        files = layout.capture_files(index)
        payload = {
            "rgb": layout.encode_png(np.ascontiguousarray(rgb, np.uint8)),
            "depth": layout.encode_png(imaging.depth_to_png(depth)),
            "mask": layout.encode_png(instance.astype(np.uint16)),
            "scan": layout.encode_scan(scan_ranges, scan_meta["angle_min"], scan_meta["angle_increment"]),
        }
        for kind, data in payload.items():
            layout.atomic_write(self.dir / files[kind], data)
        if camera is not None and self._cameras.get(agent) != camera:
            self._cameras[agent] = camera
            layout.atomic_write(self.dir / layout.CAMERA_JSON,
                                (json.dumps(self._cameras, indent=1) + "\n").encode())
        row = {"index": index, "stamp": float(stamp), "agent": agent,
               "pose": [float(v) for v in pose], "odom": [float(v) for v in odom],
               "room": room, "room_type": self._room_types.get(room) if room else None,
               "files": files, "scan": {k: float(scan_meta[k]) for k in
                                        ("angle_min", "angle_increment", "range_min", "range_max")}}
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
        except OSError:
            os.ftruncate(self._rows.fileno(), start)
            self._rows.seek(start)
            raise

    def close(self) -> None:
        self._rows.close()

    def __enter__(self) -> DatasetWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
