"""The on-disk dataset format in one place: file names, where each sensor's files go, and the atomic write.

The writer and the reader both import these, so the format (documented in README.md beside this
file) cannot drift between them; what is inside a sensor's files (pixel encodings, the scan array)
is its port's to encode and decode (ravh_sim.sensors.ports). Every file is written under a temporary
name in its own directory and renamed into place, so a reader (or a recorder killed at any instant)
never sees half a file.
"""
from __future__ import annotations

from ravh_sim.files import TMP_PREFIX, atomic_write  # noqa: F401  (the dataset's writes are these)
from ravh_sim.sensors.suite import SENSORS

FORMAT = "ravh_sim/dataset@1"

DATASET_JSON = "dataset.json"          # format, house, agents, created, raid metadata
FOOTPRINT_JSON = "footprint.json"      # the footprint of the run (ravh_sim/footprint@1)
SETTINGS_JSON = "settings.json"        # the footprint's resolved settings, on their own
CAPTURES_JSONL = "captures.jsonl"      # one line per complete capture
MAP_DIR = "map"                        # map.pgm + map.yaml (map_server format)
MAP_NAME = "map"
BAG_DIR = "bag"                        # rosbag2, MCAP storage
RAID_JSON = "raid.json"                # a raid's summary, written when it ends (``ravh raid``, the engines)


def capture_file(kind: str, ext: str, index: int) -> str:
    """The relative path of capture ``index``'s file of ``kind``: one folder per kind. The kinds, and
    what their files hold, are the sensor ports' (``SensorPort.files``, ``encode`` and ``decode``)."""
    return f"{kind}/{index:06d}{ext}"


def capture_files(index: int) -> dict[str, str]:
    """Relative paths of dataset sample ``index``'s files, by kind (every sensor's)."""
    return {kind: capture_file(kind, ext, index) for port in SENSORS for kind, ext in port.files.items()}
