"""The package as installed by tools/setup.sh (pip, non-editable): ROS layout, data files, launchers."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

PREFIX = Path(sys.prefix)


def test_ament_index_and_share_files():
    assert (PREFIX / "share/ament_index/resource_index/packages/ravh_sim").exists()
    share = PREFIX / "share/ravh_sim"
    assert (share / "package.xml").exists()
    assert len(list((share / "houses").glob("house*.json"))) == 30
    assert (share / "config/default.yaml").exists() and (share / "config/fastdds_large_shm.xml").exists()


def test_ros2_run_launchers_exist_and_start(tmp_path):
    for exe in ("sim", "wanderer", "grid", "teleop", "recorder"):
        launcher = PREFIX / "lib/ravh_sim" / exe
        assert launcher.exists() and os.access(launcher, os.X_OK), exe
    env = dict(os.environ, PATH=f"{PREFIX / 'bin'}{os.pathsep}{os.environ['PATH']}")
    out = subprocess.run([str(PREFIX / "lib/ravh_sim/sim"), "--help"], capture_output=True, text=True,
                         env=env, cwd=tmp_path, timeout=60)
    assert out.returncode == 0 and "--house" in out.stdout


def test_installed_package_finds_its_data(tmp_path):
    code = "from ravh_sim.paths import HOUSES_DIR; print(HOUSES_DIR)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                         env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"})
    assert out.returncode == 0 and Path(out.stdout.strip()) == PREFIX / "share/ravh_sim/houses"
