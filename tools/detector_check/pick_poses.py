"""Maintainer tool (detector check, step 1): choose a photographer's pose per house and object type.

A detector trained on real photos is only a fair judge of how photo-like the renders are when each
object is shown the way a photographer would frame it: whole, from its front, not hidden. The
simulator's gallery already knows how to choose such a pose (:func:`ravh_sim.raids.gallery.object_views`);
this script asks it for one pose per object type of each house, judged on both dressings the check
renders (lived-in and none) in raid 0's day look, so the same pose serves both renders.

Usage (from the repository root, with the live tree first on the path)::

    PYTHONPATH=. .venv/bin/python tools/detector_check/pick_poses.py OUT_DIR HOUSE [HOUSE ...]

Writes ``OUT_DIR/poses.json`` (every pose, with the gallery's score) and ``OUT_DIR/poses.tsv`` (house,
type, x, y, yaw: what run.sh renders). Houses already in ``poses.json`` are kept, not picked again.
"""
from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

from ravh_sim.raids.gallery import object_views
from ravh_sim.raids.raid import PRESETS, preset_settings
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.camera import SmartCamera
from ravh_sim.world.house import House, load_house
from ravh_sim.world.scene import World
from ravh_sim.world.settings import Resolved, load_settings, resolve

DRESSINGS = ("lived-in", "none")
"""The dressings the check renders; a pose must suit both."""
RAID = 0          # the raid preset whose look (day, lights on) the poses are judged in
SEED = 0
TYPES = ("Sofa", "Armchair", "Bed", "Table", "Chair", "Refrigerator", "Oven", "Toilet", "Tv",
         "Washbasin", "Desk", "Closet", "Sink", "Microwave", "WashingMachine", "Dishwasher",
         "Bathtub", "Stool", "Laptop")
"""Object types a pose is chosen for (the ones without a COCO class still carry others into view)."""


def look(house: House, dressing: str) -> Resolved:
    """Raid ``RAID``'s resolved settings with ``dressing`` over them (as the gallery builds a look)."""
    settings = load_settings()
    for section, values in preset_settings(PRESETS[RAID], SEED).items():
        settings[section] = {**settings[section], **values} if isinstance(values, dict) else values
    settings["dressing"] = dressing
    return resolve(settings, house, SEED)


def house_poses(number: int) -> list[dict[str, Any]]:
    """One pose per object type the house has, as the gallery chooses it over both dressings."""
    house = load_house(number)
    looks = [look(house, dressing) for dressing in DRESSINGS]
    with World(house, looks[0]) as world:
        scout = SmartCamera(world, replace(load_profile().camera, quality="fast"), backend="auto")
        try:
            views = object_views(world, scout, types=TYPES, looks=looks)
        finally:
            scout.close()
    return [{"house": number, "type": object_type, "object_id": shot.object_id,
             "pose": [float(v) for v in shot.pose], "score": float(shot.score), "seen": float(shot.seen),
             "cut": float(shot.cut), "free": bool(shot.free)} for object_type, shot in views]


def write_tsv(poses: list[dict[str, Any]], path: Path) -> None:
    """The poses as ``house<TAB>type<TAB>x<TAB>y<TAB>yaw`` lines, for the shell to render."""
    lines = [f"{p['house']}\t{p['type']}\t{p['pose'][0]:.4f}\t{p['pose'][1]:.4f}\t{p['pose'][2]:.4f}" for p in poses]
    path.write_text("".join(f"{line}\n" for line in lines))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="output folder (poses.json, poses.tsv)")
    parser.add_argument("houses", type=int, nargs="+", help="house numbers")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    store = args.out / "poses.json"
    poses: list[dict[str, Any]] = json.loads(store.read_text()) if store.exists() else []
    done = {p["house"] for p in poses}
    for number in args.houses:
        if number in done:
            continue
        picked = house_poses(number)
        poses.extend(picked)
        store.write_text(json.dumps(poses, indent=1))       # after each house: an interrupted run resumes
        print(f"house {number}: {', '.join(p['type'] for p in picked)}", flush=True)
    wanted = set(args.houses)
    write_tsv([p for p in poses if p["house"] in wanted], args.out / "poses.tsv")


if __name__ == "__main__":
    main()
