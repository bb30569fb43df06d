"""ravh_sim: an ament_python package that also installs with plain pip.

Data files land under <prefix>/share/ravh_sim (houses, config, the Fast DDS profile) where
ravh_sim.paths finds them, and the ament index marker makes ``ros2 pkg`` / ``ros2 run`` see the package.
"""
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE = "ravh_sim"


def tree(folder: str) -> list[tuple[str, list[str]]]:
    """data_files entries that copy ``folder`` recursively into share/ravh_sim/<folder>."""
    entries: dict[str, list[str]] = {}
    for path in sorted(Path(folder).rglob("*")):
        if path.is_file():
            entries.setdefault(f"share/{PACKAGE}/{path.parent}", []).append(str(path))
    return sorted(entries.items())


setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(include=["ravh_sim", "ravh_sim.*", "ravh_msgs_py", "ravh_msgs_py.*"]),
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"lib/{PACKAGE}", sorted(str(p) for p in Path("scripts").iterdir())),
        *tree("houses"),
        *tree("furniture"),
        *tree("config"),
    ],
    package_data={"ravh_sim.render": ["shaders/*.glsl", "shaders/*.vert", "shaders/*.frag"],
                  "ravh_sim.eval": ["weights/*"]},
    install_requires=["numpy", "pybullet", "opencv-python-headless", "pyyaml", "pydantic>=2", "trimesh", "rosbags",
                      "moderngl", "tqdm", "pycocotools",
                      "matplotlib",     # the pictures: plans, raid summaries, the Table-4 heat map
                      "shapely>=2"],    # floor outlines: areas, inside tests, label spots on plans
    extras_require={"ray": ["ray"],           # ravh dataset build --ray: raids as tasks on a Ray cluster
                    # the EfficientNet-Lite0 localization descriptor (its ONNX file ships in ravh_sim/eval/weights)
                    "cnn": ["onnxruntime"]},
    zip_safe=True,
    maintainer="ravh_sim developers",
    description="Robot@VirtualHome for ROS 2: realistic virtual houses in pybullet",
    license="MIT",
    tests_require=["pytest"],
    entry_points={"console_scripts": ["ravh = ravh_sim.cli:main"]},
)
