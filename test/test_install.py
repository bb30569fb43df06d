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
                         env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"}, timeout=120)
    assert out.returncode == 0 and Path(out.stdout.strip()) == PREFIX / "share/ravh_sim/houses"


JAZZY_TFMESSAGE_HASH = "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"


def test_tf2_msgs_has_the_official_jazzy_type_hash():
    """tools/setup.sh builds tf2_msgs when the install has none; its TFMessage must be the wire type
    every ROS tool expects (the hash is what DDS endpoints compare)."""
    code = ("import rclpy; from tf2_msgs.msg import TFMessage; rclpy.init(); n = rclpy.create_node('hash');"
            "n.create_publisher(TFMessage, '/tf_hash_probe', 1);"
            "print(n.get_publishers_info_by_topic('/tf_hash_probe')[0].topic_type_hash)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         env=dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST"))
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == JAZZY_TFMESSAGE_HASH


def test_package_xml_declares_every_ros_package_the_code_imports():
    import re
    import xml.etree.ElementTree as ET
    root = Path(__file__).resolve().parents[1]
    declared = {e.text for e in ET.parse(root / "package.xml").getroot().iter("exec_depend")}
    imported = set()
    for source in [*(root / "ravh_sim").rglob("*.py"), *(root / "ravh_msgs_py").rglob("*.py")]:
        imported |= set(re.findall(r"^\s*(?:from|import) (rclpy|\w+_(?:msgs|srvs|interfaces))\b", source.read_text(),
                                   re.MULTILINE))
    assert {"tf2_msgs", "diagnostic_msgs", "rclpy"} <= imported
    assert imported <= declared, imported - declared


def test_one_version_in_the_package_setup_py_and_package_xml():
    """A dataset build records ravh_sim.__version__ with every raid (a resume redoes raids of another)."""
    import re

    import ravh_sim
    root = Path(__file__).resolve().parents[1]
    assert f'version="{ravh_sim.__version__}"' in (root / "setup.py").read_text()
    assert re.search(rf"<version>{re.escape(ravh_sim.__version__)}</version>", (root / "package.xml").read_text())
