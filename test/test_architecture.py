"""Dependencies point one way: processes that only navigate or run a behaviour load no simulator."""
from __future__ import annotations

import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import ravh_sim.behaviours

SIMULATOR_MODULES = ("pybullet", "moderngl", "ravh_sim.world.scene", "ravh_sim.world.furniture",
                     "ravh_sim.robot.robot")
ROOT = Path(__file__).resolve().parents[1]
BEHAVIOUR_NODES = ["ravh_sim.nodes.behaviour_node", "ravh_sim.nodes.wanderer_node", "ravh_sim.nodes.grid_node",
                   "ravh_sim.nodes.teleop_node"]
BEHAVIOURS = [f"ravh_sim.behaviours.{m.name}" for m in pkgutil.iter_modules(ravh_sim.behaviours.__path__)]


def _loaded_simulator_modules(modules: list[str]) -> list[str]:
    """The simulator modules that importing ``modules`` in a fresh interpreter loads."""
    probe = (f"import sys\nfor m in {modules!r}: __import__(m)\n"
             f"print(','.join(m for m in {SIMULATOR_MODULES!r} if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120,
                          cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return [m for m in done.stdout.strip().split(",") if m]


@pytest.mark.parametrize("modules", [["ravh_sim.nav.follower"], BEHAVIOURS, BEHAVIOUR_NODES],
                         ids=["follower", "behaviours", "behaviour_nodes"])
def test_navigation_and_behaviours_load_no_simulator(modules):
    assert len(modules) > 0
    assert _loaded_simulator_modules(modules) == []


def test_the_probe_sees_a_simulator_module_when_one_is_loaded():
    loaded = _loaded_simulator_modules(["ravh_sim.robot.robot"])
    assert "pybullet" in loaded and "ravh_sim.robot.robot" in loaded

