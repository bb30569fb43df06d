"""Where the package's data lives: houses, the furniture library, config and robot profiles.

In a source checkout the data sits beside the package (the repository root); installed by pip or
colcon it sits in <prefix>/share/ravh_sim, three levels above site-packages. One place decides, so
every module agrees.
"""
from __future__ import annotations

import os
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent
_CHECKOUT = _PACKAGE.parent
_INSTALLED = _PACKAGE.parents[3] / "share" / "ravh_sim" if len(_PACKAGE.parents) > 3 else _CHECKOUT
DATA_DIR = _CHECKOUT if (_CHECKOUT / "houses").is_dir() else _INSTALLED

HOUSES_DIR = DATA_DIR / "houses"
FURNITURE_DIR = DATA_DIR / "furniture"
CONFIG_DIR = DATA_DIR / "config"
ROBOTS_DIR = CONFIG_DIR / "robots"
DEFAULT_CONFIG = CONFIG_DIR / "default.yaml"
FASTDDS_PROFILE = CONFIG_DIR / "fastdds_large_shm.xml"
PAPER_DIR = CONFIG_DIR / "paper"                 # the paper's Tables 1-4 as TSV (README there)


def user_houses_dir() -> Path:
    """Where ``ravh import-home`` writes homes by default and where names are looked up:
    ``$XDG_DATA_HOME/ravh_sim/houses`` (``~/.local/share/ravh_sim/houses``); read at each call, so a
    test or a user can point it elsewhere."""
    base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(base) / "ravh_sim" / "houses"
