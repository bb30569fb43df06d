"""The sensor suite: every sensor port an agent carries, in the order they are read and published.

The runtime, the sim node, the recorder and the dataset writer iterate over :data:`SENSORS`; a new
sensor is one module with its port (ravh_sim.sensors.ports) and one line here.
"""
from __future__ import annotations

from ravh_sim.dataset import layout
from ravh_sim.sensors import camera, laser
from ravh_sim.sensors.ports import SensorPort

# Cheap sensors first: a scan due in the same tick as a camera frame is published before the render
# (~50 ms on a CPU) instead of after it, as scans were before the suite existed (SLAM waits on them).
SENSORS: tuple[SensorPort, ...] = (laser.PORT, camera.PORT)


def capture_files(index: int) -> dict[str, str]:
    """Relative paths of dataset sample ``index``'s files, by kind (every sensor's)."""
    return {kind: layout.capture_file(kind, ext, index) for port in SENSORS for kind, ext in port.files.items()}

