"""Smoke tests of the user tools that had none: gallery, bench, teleop (probe: test_sim_modes.py)."""
from __future__ import annotations

import json
import subprocess
import sys

import cv2
import pytest
from conftest import ROOT, subprocess_env

from ravh_sim.behaviours.teleop import ANGULAR_STEP, LINEAR_STEP, Teleop
from ravh_sim.raids.gallery import LABEL_PX


def ravh(*args: str, timeout: float = 300, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "ravh_sim.cli", *args], cwd=ROOT, env=subprocess_env(),
                          capture_output=True, text=True, timeout=timeout, **kwargs)


def test_gallery_sheet_shows_the_five_presets_and_a_random_look(tmp_path):
    """Six labelled 640 x 480 panels, 3 x 2; the night preset (raid 4) is darker than day (raid 0)."""
    out = tmp_path / "sheet.png"
    done = ravh("gallery", "20", "-o", str(out), "--pose", "-2", "1", "0", "--renderer", "tiny")
    assert done.returncode == 0 and f"wrote {out}" in done.stdout, done.stderr[-2000:]
    sheet = cv2.imread(str(out))
    panel_h = 480 + LABEL_PX
    assert sheet.shape == (2 * panel_h, 3 * 640, 3)
    panels = [sheet[r * panel_h:r * panel_h + 480, c * 640:(c + 1) * 640] for r in range(2) for c in range(3)]
    assert panels[4].mean() < panels[0].mean() - 10
    assert all(panel.std() > 5 for panel in panels)                  # pictures, not blank frames


def test_bench_load_reports_house_20():
    done = ravh("bench", "load", "--houses", "20", "--json")
    assert done.returncode == 0, done.stderr[-2000:]
    result = json.loads(done.stdout)
    assert set(result["houses"]) == {"20"} and result["houses"]["20"]["build_s"] > 0
    assert result["build_s_max"] == result["houses"]["20"]["build_s"] and result["cold_cache_build_s"] > 0
    assert result["cold_cache_house"] == 20            # the house measured, not house 15


@pytest.mark.parametrize("keys, v, w, action", [
    ("www", 3 * LINEAR_STEP, 0.0, None),
    ("w" * 100, 0.25, 0.0, None),                        # capped at the robot's top speed
    ("x" * 100 + "a" * 3, -0.25, 3 * ANGULAR_STEP, None),
    ("d" * 100, 0.0, -1.0, None),
    ("wwad ", 0.0, 0.0, None),                           # space stops
    ("wwc", 2 * LINEAR_STEP, 0.0, "capture"),
    ("wwaq", 0.0, 0.0, "quit"),                          # quitting stops the robot
])
def test_teleop_keys(keys, v, w, action):
    teleop = Teleop(max_linear=0.25, max_angular=1.0)
    actions = [teleop.press(k) for k in keys]
    assert (teleop.v, teleop.w) == pytest.approx((v, w))
    assert actions[-1] == action


def test_teleop_without_a_terminal_is_one_line():
    done = ravh("teleop", stdin=subprocess.DEVNULL, timeout=120)
    assert done.returncode == 2 and "teleop reads keys from a terminal" in done.stderr, done.stderr[-2000:]
    assert "Traceback" not in done.stderr
