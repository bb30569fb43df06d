"""The project's own checks as tests: ruff (ruff.toml) over the code and the tests, mypy (setup.cfg)
over the packages."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TOOLS = Path(sys.executable).parent            # ruff and mypy come with the venv (tools/requirements.txt)


def _run(*command: str) -> subprocess.CompletedProcess:
    return subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=600)


@pytest.mark.timeout(1200)
def test_ruff_finds_nothing():
    done = _run(str(TOOLS / "ruff"), "check", "--no-cache", "ravh_sim", "ravh_msgs_py", "test")
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.timeout(1200)
def test_mypy_finds_nothing():
    done = _run(str(TOOLS / "mypy"), "ravh_sim", "ravh_msgs_py")
    assert done.returncode == 0, done.stdout + done.stderr
