"""Dataset: read a recorded dataset folder and answer the questions a raid is recorded for.

Which samples were taken in a room (or room type), which object types an image shows, how many
objects or rooms of a kind the house has, which rooms the robot visited. Counts come from the
footprint stored with the dataset, so they describe exactly the world that was recorded. Pixels are
read lazily, one sample at a time, and decoded by the sensor ports that stored them. A dataset cut
short (recorder killed) reads as the captures that were complete: a torn last line of
captures.jsonl (no newline: the writer died appending it) is left out with a warning, and so are
lines whose files are missing (this module's ``logging`` logger). A malformed line anywhere else is
no crash to tolerate but a damaged file: it is refused (:class:`~ravh_sim.errors.UserError` naming
the file and the line).
"""
from __future__ import annotations

import json
import logging
from collections import Counter
from collections.abc import Iterator
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from ravh_sim.dataset import layout
from ravh_sim.errors import FileFieldError, UserError
from ravh_sim.nav.grid import Grid
from ravh_sim.nav.mapio import read_map
from ravh_sim.sensors.camera import CAMERA_JSON
from ravh_sim.sensors.laser import StoredScan
from ravh_sim.sensors.ports import SensorPort
from ravh_sim.sensors.suite import SENSORS
from ravh_sim.world.house import House, load_house
from ravh_sim.world.settings import Resolved

log = logging.getLogger(__name__)
MIN_PIXELS = 50          # an instance with fewer pixels in an image does not count as visible there


# file kind -> the sensor port that stores it (and so decodes it)
PORT_OF_FILE: dict[str, SensorPort[Any, Any, Any]] = {kind: port for port in SENSORS for kind in port.files}


class Sample:
    """One capture: its metadata as attributes, its sensors' data decoded by their ports on first use."""

    def __init__(self, root: Path, row: dict[str, Any], palette: np.ndarray) -> None:
        self.index: int = row["index"]
        self.stamp: float = row["stamp"]
        self.agent: str = row["agent"]
        self.pose: tuple[float, float, float] = tuple(row["pose"])
        self.odom: tuple[float, float, float] = tuple(row["odom"])
        self.room: str | None = row["room"]
        self.room_type: str | None = row["room_type"]
        self.files: dict[str, Path] = {kind: root / rel for kind, rel in row["files"].items()}
        self._row = row
        self._palette = palette
        self._decoded: dict[str, Any] = {}

    def __repr__(self) -> str:
        return f"Sample({self.index}, t={self.stamp:.3f}, {self.agent}, room={self.room})"

    def read(self, kind: str) -> Any:
        """The data of this sample's file of ``kind`` (a sensor port's ``files``), as its port decodes it."""
        if kind not in self._decoded:
            self._decoded[kind] = PORT_OF_FILE[kind].decode(kind, self.files[kind], self._row)
        return self._decoded[kind]

    @property
    def rgb(self) -> np.ndarray:
        """(H, W, 3) uint8, RGB order."""
        return self.read("rgb")

    @property
    def depth(self) -> np.ndarray:
        """(H, W) float32 metres along the optical axis, NaN = no depth (1 mm steps)."""
        return self.read("depth")

    @property
    def instance(self) -> np.ndarray:
        """(H, W) uint16 instance ids (footprint ids), 0 = nothing."""
        return self.read("mask")

    @property
    def mask(self) -> np.ndarray:
        """(H, W, 3) uint8 RGB: each instance in its footprint mask colour (black = nothing)."""
        ids = self.instance
        return self._palette[np.minimum(ids, len(self._palette) - 1)]

    @property
    def scan(self) -> StoredScan:
        return self.read("scan")


class Dataset:
    """A dataset folder written by :class:`~ravh_sim.dataset.writer.DatasetWriter`."""

    def __init__(self, directory: str | Path) -> None:
        self.dir = Path(directory)
        self.meta: dict[str, Any] = _read_json(self.dir / layout.DATASET_JSON)
        if self.meta.get("format") != layout.FORMAT:
            raise FileFieldError(self.dir / layout.DATASET_JSON, "format", f"expected {layout.FORMAT!r}")
        self.footprint: dict[str, Any] = _read_json(self.dir / layout.FOOTPRINT_JSON)
        self.instances: dict[int, dict[str, Any]] = {int(r["id"]): r for r in self.footprint["instances"]}
        self._palette = _palette(self.instances)
        self._rows = _complete_rows(self.dir)

    # ------------------------------------------------------------------ the samples
    def __len__(self) -> int:
        return len(self._rows)

    def __getitem__(self, i: int) -> Sample:
        return Sample(self.dir, self._rows[i], self._palette)

    def __iter__(self) -> Iterator[Sample]:
        return (Sample(self.dir, row, self._palette) for row in self._rows)

    def filter(self, room: str | None = None, room_type: str | None = None,
               agent: str | None = None) -> list[Sample]:
        """The samples taken in ``room`` / a room of ``room_type`` / by ``agent`` (None: any)."""
        return [Sample(self.dir, r, self._palette) for r in self._rows
                if (room is None or r["room"] == room) and (room_type is None or r["room_type"] == room_type)
                and (agent is None or r["agent"] == agent)]

    def rooms_visited(self) -> list[str]:
        """The rooms the samples were taken in, in the order first visited."""
        return list(dict.fromkeys(r["room"] for r in self._rows if r["room"]))

    # ------------------------------------------------------------------ questions
    def objects_in(self, sample: Sample, min_pixels: int = MIN_PIXELS) -> Counter[str]:
        """Object type -> how many distinct objects of it cover at least ``min_pixels`` of the image."""
        pixels = np.bincount(sample.instance.ravel())
        seen: Counter[str] = Counter()
        for i in np.flatnonzero(pixels >= min_pixels):
            row = self.instances.get(int(i))
            if row is not None and row["kind"] == "object":
                seen[row["type"]] += 1
        return seen

    def count_objects(self, type: str | None = None, room: str | None = None) -> int:
        """How many objects (of ``type``, in ``room``) the recorded house holds."""
        return sum(1 for r in self.instances.values() if r["kind"] == "object"
                   and (type is None or r["type"] == type) and (room is None or r["room"] == room))

    def count_rooms(self, room_type: str | None = None) -> int:
        """How many rooms (of ``room_type``) the recorded house has."""
        return sum(1 for r in self.instances.values()
                   if r["kind"] == "floor" and (room_type is None or r["room_type"] == room_type))

    # ------------------------------------------------------------------ the world
    @cached_property
    def house(self) -> House:
        return load_house(int(self.meta["house"]))

    @cached_property
    def settings(self) -> Resolved:
        return Resolved.model_validate(self.footprint["settings"])

    @cached_property
    def map(self) -> Grid | None:
        """The occupancy map the sim published (the latest), or None if none was recorded."""
        path = self.dir / layout.MAP_DIR / f"{layout.MAP_NAME}.yaml"
        return read_map(path) if path.exists() else None

    @cached_property
    def camera(self) -> dict[str, dict[str, Any]]:
        """Agent -> camera intrinsics (width, height, K row-major, D, distortion_model, frame_id)."""
        path = self.dir / CAMERA_JSON
        return _read_json(path) if path.exists() else {}


def _read_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UserError(f"{path.parent}: not a ravh_sim dataset (no {path.name})") from None
    except (OSError, ValueError) as e:
        raise FileFieldError(path, "-", f"cannot read: {e}") from None


def _complete_rows(root: Path) -> list[dict[str, Any]]:
    """The rows of captures.jsonl whose files all exist. A torn last line (no newline: the writer was
    killed while appending it) and rows whose files are missing are left out with a warning; a line
    that does not parse as a capture row anywhere else refuses the dataset (UserError, file:line)."""
    path = root / layout.CAPTURES_JSONL
    text = path.read_text(encoding="utf-8") if path.exists() else ""
    *lines, torn = text.split("\n")                 # every line but a torn last one ends in a newline
    rows: list[dict[str, Any]] = []
    missing: list[int] = []
    for number, line in enumerate(lines, start=1):
        row = _row(path, number, line)
        if all((root / rel).is_file() for rel in row["files"].values()):
            rows.append(row)
        else:
            missing.append(number)
    if torn:
        log.warning("%s:%d: torn last line left out (the recorder was killed while writing it): %.60r",
                    path, len(lines) + 1, torn)
    if missing:
        log.warning("%s: %d capture(s) left out whose files are missing (line %s)", path, len(missing),
                    ", ".join(map(str, missing[:10])) + (" ..." if len(missing) > 10 else ""))
    return rows


def _row(path: Path, number: int, line: str) -> dict[str, Any]:
    """Line ``number`` of captures.jsonl as a capture row; UserError naming the file and line if it is not one."""
    try:
        row = json.loads(line)
    except ValueError as e:
        raise UserError(f"{path}:{number}: malformed capture row ({e}); the dataset is damaged") from None
    if not isinstance(row, dict) or not isinstance(row.get("files"), dict):
        raise UserError(f"{path}:{number}: malformed capture row (not an object with 'files'); "
                        "the dataset is damaged")
    return row


def _palette(instances: dict[int, dict[str, Any]]) -> np.ndarray:
    """(max id + 2, 3) uint8: row i is instance i's mask colour; 0 and unknown ids are black."""
    table = np.zeros((max(instances, default=0) + 2, 3), np.uint8)
    for i, row in instances.items():
        table[i] = row["mask_color"]
    return table
