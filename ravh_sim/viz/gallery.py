"""``ravh gallery``: one view of a house under the paper's five raid presets (Table 1) and a random
appearance, as one contact sheet, to judge the renderer's look at a glance.

The view is chosen automatically unless given: among room centres and eight headings, the one that
shows the most labelled objects from at least MIN_VIEW_DEPTH_M away (counted on a fast render).
"""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

from ravh_sim.dataset.raid import PRESETS, preset_settings
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.camera import SmartCamera
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.geometry import polygon_centroid
from ravh_sim.world.house import load_house
from ravh_sim.world.scene import World
from ravh_sim.world.settings import Resolved, load_settings, resolve

MIN_OBJECT_PIXELS = 800          # an object counts as seen in a candidate view from this many pixels
MIN_VIEW_DEPTH_M = 2.5           # median depth of a candidate view: a room, not a close-up
WIDE_VIEW_DEPTH_M = 4.0          # views this deep or deeper count their objects in full
LABEL_PX = 30


def best_view(world: World, camera: SmartCamera) -> tuple[float, float, float]:
    """The room-centre pose and heading that sees the most labelled objects from far enough back
    (the station's pose when no candidate qualifies)."""
    objects = {inst.id for inst in world.instances if inst.kind == "object"}
    best, best_count = None, -1.0
    for room in world.house.rooms:
        x, y = polygon_centroid(room.floor)
        if not room.contains(x, y):
            continue
        for k in range(8):
            pose = (x, y, k * math.pi / 4)
            capture = camera.capture(*pose)
            depth = float(np.nanmedian(capture.depth)) if np.isfinite(capture.depth).any() else 0.0
            if depth < MIN_VIEW_DEPTH_M:
                continue
            counts = np.bincount(capture.instance.ravel())
            seen = sum(1 for i in np.flatnonzero(counts >= MIN_OBJECT_PIXELS) if i in objects)
            score = seen * min(1.0, depth / WIDE_VIEW_DEPTH_M)
            if score > best_count:
                best, best_count = pose, score
    if best is None:
        station = world.house.station
        return station.position[0], station.position[1], station.yaw
    return best


def gallery(house_number: int, output: Path, seed: int = 0,
            pose: tuple[float, float, float] | None = None, renderer: str = "auto") -> Path:
    """Write the contact sheet (3 x 2 panels) to ``output``; returns it."""
    house = load_house(house_number)
    profile = load_profile()
    with World(house, _preset(house, 0, seed), renderer=renderer) as world:
        appearance = Appearance(world)
        if pose is None:
            scout = SmartCamera(world, replace(profile.camera, quality="fast"))
            pose = best_view(world, scout)
            scout.close()
        camera = SmartCamera(world, profile.camera)
        panels = []
        for k, preset in enumerate(PRESETS):
            appearance.apply(_preset(house, k, seed))
            label = (f"raid {k}: {preset.sun}, ceiling {preset.ceiling}, lamps {preset.lamps}, "
                     f"paint {preset.paint}, models {preset.models}")
            panels.append(_labelled(camera.capture(*pose).rgb, label))
        appearance.randomise(seed + 1)
        panels.append(_labelled(camera.capture(*pose).rgb,
                                f"random: sun {world.state.sun_angle:.0f} deg, paint, models, lights"))
        camera.close()
    sheet = np.vstack([np.hstack(panels[:3]), np.hstack(panels[3:])])
    output.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(output), cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR)):
        raise OSError(f"could not write {output}")
    return output


def _preset(house, raid: int, seed: int) -> Resolved:
    """The resolved settings of a raid preset: the defaults with the preset's sections over them."""
    settings = load_settings()
    for section, values in preset_settings(PRESETS[raid], seed).items():
        settings[section] = {**settings[section], **values} if isinstance(values, dict) else values
    return resolve(settings, house, seed)


def _labelled(rgb: np.ndarray, text: str) -> np.ndarray:
    strip = np.full((LABEL_PX, rgb.shape[1], 3), 24, np.uint8)
    cv2.putText(strip, text, (8, LABEL_PX - 10), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (235, 235, 235), 1, cv2.LINE_AA)
    return np.vstack([rgb, strip])
