"""The sensor suite: every sensor port an agent carries, in the order they are read and published.

The runtime, the sim node, the recorder and the dataset writer and reader iterate over
:data:`SENSORS`; a new sensor is one module with its port class (ravh_sim.sensors.ports) and one line
here.
"""
from __future__ import annotations

from typing import Any

from ravh_sim.sensors import camera, laser
from ravh_sim.sensors.ports import SensorPort

# Cheap sensors first: a scan due in the same tick as a camera frame is published before the render
# (~50 ms on a CPU) instead of after it, as scans were before the suite existed (SLAM waits on them).
SENSORS: tuple[SensorPort[Any, Any, Any], ...] = (laser.PORT, camera.PORT)
