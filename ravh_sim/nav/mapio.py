"""Occupancy maps on disk in the ROS map_server format (a PGM picture plus a YAML description).

Writing the maps this way lets the ROS 2 side (nav2 map_server, RViz) load exactly the sim's /map
(the obstacle map) or the free space it plans on, and lets users inspect or hand-edit them with any
picture editor.

Format (trinary mode): P5 PGM, 254 free, 0 occupied, 205 unknown; image row 0 is the highest y (a
picture is drawn top-down, the grid counts rows from the lowest y). The YAML says where the picture
lies: ``origin`` is the (x, y, yaw) of the lower-left pixel's corner.

``free_thresh`` is written as 0.196, not the nav2 saver's old default of 0.25: a loader turns a
pixel p into occupancy (255 - p) / 255 and calls it free below ``free_thresh``; unknown pixels (205)
give 0.196..., so with 0.25 every unknown cell would load as FREE and a ROS planner would drive out
of the house (nav2 fixed its saver the same way, ros-navigation/navigation2#5278).
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import yaml

from ravh_sim.errors import FileFieldError
from ravh_sim.files import atomic_write
from ravh_sim.nav.grid import FREE, OCCUPIED, UNKNOWN, Grid

FREE_PIXEL, OCCUPIED_PIXEL, UNKNOWN_PIXEL = 254, 0, 205
OCCUPIED_THRESH, FREE_THRESH = 0.65, 0.196


def write_map(grid: Grid, directory: str | Path, name: str = "map") -> tuple[Path, Path]:
    """Write ``<name>.pgm`` and ``<name>.yaml`` into ``directory`` (created if needed)."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    pgm_path, yaml_path = directory / f"{name}.pgm", directory / f"{name}.yaml"
    pixels = np.full(grid.shape, UNKNOWN_PIXEL, np.uint8)
    pixels[grid.data == FREE] = FREE_PIXEL
    pixels[grid.data == OCCUPIED] = OCCUPIED_PIXEL
    rows, cols = grid.shape
    header = f"P5\n# ravh_sim map, {grid.resolution} m/cell\n{cols} {rows}\n255\n".encode()
    atomic_write(pgm_path, header + pixels[::-1].tobytes())
    description = {
        "image": pgm_path.name,
        "mode": "trinary",
        "resolution": float(grid.resolution),
        "origin": [float(grid.origin[0]), float(grid.origin[1]), 0.0],
        "negate": 0,
        "occupied_thresh": OCCUPIED_THRESH,
        "free_thresh": FREE_THRESH,
    }
    atomic_write(yaml_path, yaml.safe_dump(description, sort_keys=False, default_flow_style=None).encode())
    return pgm_path, yaml_path


def read_map(yaml_path: str | Path) -> Grid:
    """Load a trinary map written by :func:`write_map` (or by ROS map_saver) as a :class:`Grid`.

    Pixels are classified as map_server does, with the file's thresholds and ``negate`` flag.
    """
    yaml_path = Path(yaml_path)
    try:
        meta = yaml.safe_load(yaml_path.read_text())
    except OSError as e:
        raise FileFieldError(yaml_path, "-", f"cannot read: {e.strerror}") from None
    except yaml.YAMLError as e:
        raise FileFieldError(yaml_path, "-", f"invalid YAML: {e}") from None
    if not isinstance(meta, dict):
        raise FileFieldError(yaml_path, "(top level)", "expected a mapping")
    mode = meta.get("mode", "trinary")
    if mode != "trinary":
        raise FileFieldError(yaml_path, "mode", f"only 'trinary' maps are supported, got {mode!r}")
    resolution = _number(meta, "resolution", yaml_path)
    origin = meta.get("origin")
    if not (isinstance(origin, list) and len(origin) == 3
            and all(isinstance(v, (int, float)) for v in origin)):
        raise FileFieldError(yaml_path, "origin", f"expected [x, y, yaw], got {origin!r}")
    if "image" not in meta:
        raise FileFieldError(yaml_path, "image", "missing")
    pixels = _read_pgm(yaml_path.parent / str(meta["image"]))
    shade = pixels.astype(np.float64) / 255.0
    occupancy = shade if meta.get("negate", 0) else 1.0 - shade
    data = np.full(pixels.shape, UNKNOWN, np.int8)
    data[occupancy > _number(meta, "occupied_thresh", yaml_path)] = OCCUPIED
    data[occupancy < _number(meta, "free_thresh", yaml_path)] = FREE
    return Grid(np.ascontiguousarray(data[::-1]), (float(origin[0]), float(origin[1])), resolution)


def _number(meta: dict, key: str, path: Path) -> float:
    value = meta.get(key)
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise FileFieldError(path, key, f"expected a number, got {value!r}")
    return float(value)


def _read_pgm(path: Path) -> np.ndarray:
    """The pixels of an 8-bit greyscale PGM, top row first."""
    try:
        raw = path.read_bytes()
    except OSError as e:
        raise FileFieldError(path, "-", f"cannot read: {e.strerror}") from None
    pixels = cv2.imdecode(np.frombuffer(raw, np.uint8), cv2.IMREAD_UNCHANGED) if raw[:2] in (b"P2", b"P5") else None
    if pixels is None or pixels.ndim != 2:
        raise FileFieldError(path, "header", "not a greyscale PGM, or its pixels are cut short")
    if pixels.dtype != np.uint8:
        raise FileFieldError(path, "header", f"expected 8-bit pixels (maxval 255), got {pixels.dtype}")
    return pixels
