"""The on-disk dataset format in one place: file names, pixel encodings and the atomic write.

The writer and the reader both import these, so the format (documented in README.md beside this
file) cannot drift between them. Every file is written under a temporary name in its own directory
and renamed into place, so a reader (or a recorder killed at any instant) never sees half a file.
"""
from __future__ import annotations

import io
from pathlib import Path

import cv2
import numpy as np

from ravh_sim.files import TMP_PREFIX, atomic_write  # noqa: F401  (the dataset's writes are these)

FORMAT = "ravh_sim/dataset@1"

DATASET_JSON = "dataset.json"          # format, house, agents, created, raid metadata
FOOTPRINT_JSON = "footprint.json"      # the footprint of the run (ravh_sim/footprint@1)
SETTINGS_JSON = "settings.json"        # the footprint's resolved settings, on their own
CAMERA_JSON = "camera.json"            # agent -> camera intrinsics
CAPTURES_JSONL = "captures.jsonl"      # one line per complete capture
MAP_DIR = "map"                        # map.pgm + map.yaml (map_server format)
MAP_NAME = "map"
BAG_DIR = "bag"                        # rosbag2, MCAP storage
RAID_JSON = "raid.json"                # a raid's summary, written when it ends (``ravh raid``, the engines)



def capture_file(kind: str, ext: str, index: int) -> str:
    """The relative path of capture ``index``'s file of ``kind``: one folder per kind. The kinds are
    the sensor ports' (``SensorPort.files``): rgb (8-bit RGB PNG), depth (16-bit millimetres, 0 = no
    depth), mask (16-bit instance ids, 0 = nothing), scan (float32 (N, 2) .npy: angle, range)."""
    return f"{kind}/{index:06d}{ext}"


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of an 8-bit RGB (H, W, 3) or a 16-bit (H, W) image."""
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_RGB2BGR)
    ok, buf = cv2.imencode(".png", image, [cv2.IMWRITE_PNG_COMPRESSION, 1])
    if not ok:
        raise ValueError(f"cannot encode a {image.dtype} {image.shape} image as PNG")
    return buf.tobytes()


def read_png(path: Path) -> np.ndarray:
    """The pixels of a PNG as written by :func:`encode_png` (RGB order for colour images)."""
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise OSError(f"{path}: cannot read the PNG")
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB) if image.ndim == 3 else image


def encode_scan(ranges: np.ndarray, angle_min: float, angle_increment: float) -> bytes:
    """.npy bytes of the (N, 2) float32 [angle, range] array stored per capture."""
    ranges = np.asarray(ranges, np.float32).reshape(-1)
    angles = angle_min + angle_increment * np.arange(len(ranges), dtype=np.float64)
    buf = io.BytesIO()
    np.save(buf, np.column_stack((angles.astype(np.float32), ranges)), allow_pickle=False)
    return buf.getvalue()
