"""The sensor suite: every sensor port an agent carries, in the order they are read and published.

The runtime, the sim node, the recorder and the dataset writer iterate over :data:`SENSORS`; a new
sensor is one module with its port (ravh_sim.sensors.ports) and one line here.
"""
from __future__ import annotations

from ravh_sim.dataset import layout
from ravh_sim.sensors import camera, laser
from ravh_sim.sensors.ports import SensorPort

SENSORS: tuple[SensorPort, ...] = (camera.PORT, laser.PORT)


def capture_files(index: int) -> dict[str, str]:
    """Relative paths of dataset sample ``index``'s files, by kind (every sensor's)."""
    return {kind: layout.capture_file(kind, ext, index) for port in SENSORS for kind, ext in port.files.items()}

