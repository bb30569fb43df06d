"""Shared fixtures: houses are loaded once per session; worlds are built where a test needs pybullet."""
from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")

# A suite started as a background job of a non-interactive shell (`nohup tools/test.sh &`, some CI
# runners) inherits an ignored SIGINT, which every child would inherit too: the Ctrl-C tests would then
# signal processes that cannot hear it. Children get Python's default handling back.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

ROOT = Path(__file__).resolve().parents[1]
UPSTREAM = ROOT.parent / "shared" / "upstream-houses"


def subprocess_env(**extra: str) -> dict[str, str]:
    """Environment for child processes: this checkout first on the import path."""
    path = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path, **extra}


@pytest.fixture(scope="session")
def houses():
    from ravh_sim.world.house import available_houses, load_house
    return {n: load_house(n) for n in available_houses()}


@pytest.fixture(scope="session")
def default_settings():
    from ravh_sim.world.settings import load_settings
    return load_settings()


def resolved(house, settings=None, seed=0):
    from ravh_sim.world.settings import load_settings, resolve
    return resolve(settings or load_settings(), house, seed)


@pytest.fixture(scope="module")
def world(houses):
    """House 15 built with the TinyRenderer, shared by a module's tests (a module may define its own)."""
    from ravh_sim.world.scene import World
    with World(houses[15], resolved(houses[15])) as w:
        yield w


@pytest.fixture()
def appearance(world):
    """The appearance manager of the shared world, put back to its initial settings after each test."""
    from ravh_sim.world.appearance import Appearance
    app = Appearance(world)
    yield app
    app.apply(resolved(world.house))


def pytest_sessionfinish(session, exitstatus) -> None:
    """Remove the node logs this run wrote (rosgraph.NodeProcess): a failing test has already quoted them."""
    import glob
    for path in glob.glob(f"/tmp/ravh_*_{os.getpid()}_*.log"):
        os.remove(path)


@pytest.hookimpl(trylast=True)
def pytest_sessionstart(session) -> None:
    """Say which ROS domain the run uses, after the header and also under -q (which hides the header)."""
    from rosgraph import DOMAIN_ID, DOMAIN_ID_SOURCE
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None:
        reporter.write_line(f"ROS_DOMAIN_ID {DOMAIN_ID} ({DOMAIN_ID_SOURCE})")
