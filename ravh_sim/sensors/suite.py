"""The sensor suite: every sensor port an agent carries, in the order they are read and published.

The runtime, the sim node, the recorder and the dataset writer iterate over :data:`SENSORS`; a new
sensor is one module with its port (ravh_sim.sensors.ports) and one line here.
"""
from __future__ import annotations

from ravh_sim.sensors import camera, laser
from ravh_sim.sensors.ports import SensorPort

SENSORS: tuple[SensorPort, ...] = (laser.PORT, camera.PORT)

