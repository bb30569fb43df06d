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

from ravh_sim.raids.raid import PRESETS, preset_settings
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.camera import SmartCamera
from ravh_sim.viz.figure import figure_bgr, new_figure
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
    with World(house, _preset(house, 0, seed)) as world:
        appearance = Appearance(world)
        if pose is None:
            scout = SmartCamera(world, replace(profile.camera, quality="fast"), backend=renderer)
            pose = best_view(world, scout)
            scout.close()
        camera = SmartCamera(world, profile.camera, backend=renderer)
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
    """The RGB picture above a dark strip that names it."""
    strip = new_figure(rgb.shape[1], LABEL_PX)
    strip.set_facecolor((24 / 255,) * 3)
    strip.text(8 / rgb.shape[1], 0.5, text, color=(235 / 255,) * 3, fontsize=10, va="center")
    return np.vstack([rgb, cv2.cvtColor(figure_bgr(strip), cv2.COLOR_BGR2RGB)])


SHOWCASE_TYPES = ("Sofa", "Armchair", "Bed", "Table", "Chair", "Refrigerator", "Oven", "Toilet", "Tv",
                  "Washbasin", "Desk", "Closet")
"""The object types ``ravh gallery --objects`` shows: what a detector trained on photos must find."""
VIEW_DISTANCES_M = (1.6, 2.2, 2.8)
VIEW_OFFSETS_RAD = (0.0, -0.45, 0.45)
OBJECT_VIEWS_PER_TYPE = 3         # objects of a type tried for a view


def object_views(world: World, camera: SmartCamera, types: tuple[str, ...] = SHOWCASE_TYPES
                 ) -> list[tuple[str, tuple[float, float, float]]]:
    """Per type the house has, a robot pose that sees one of its objects from the front: among
    poses 1.6-2.8 m in front of it, the one whose camera sees most of it (counted on ``camera``)."""
    from ravh_sim.world.solids import object_parts
    house = world.house
    views = []
    for object_type in types:
        best, best_pixels = None, 0
        for obj in [o for o in house.objects if o.type == object_type][:OBJECT_VIEWS_PER_TYPE]:
            placed = object_parts(house, obj, world.state.models[obj.id])
            front = placed.yaw if placed.front is None else placed.front
            x0, y0 = placed.position[:2]
            instance = world.instance(obj.id).id
            for distance in VIEW_DISTANCES_M:
                for offset in VIEW_OFFSETS_RAD:
                    heading = front + offset
                    x, y = x0 + distance * math.cos(heading), y0 + distance * math.sin(heading)
                    room = house.room_at(x, y)
                    if room is None:
                        continue
                    pose = (x, y, heading + math.pi)
                    pixels = int((camera.capture(*pose, floor_z=room.floor_z).instance == instance).sum())
                    if pixels > best_pixels:
                        best, best_pixels = pose, pixels
        if best is not None:
            views.append((object_type, best))
    return views


def object_gallery(house_number: int, output: Path, seed: int = 0, renderer: str = "auto") -> Path:
    """Write a sheet of the showcase types of a house, each seen from the front by day (raid 0's
    look) and at night with the lights on (raid 4's), side by side."""
    house = load_house(house_number)
    profile = load_profile()
    with World(house, _preset(house, 0, seed)) as world:
        appearance = Appearance(world)
        scout = SmartCamera(world, replace(profile.camera, quality="fast"), backend=renderer)
        views = object_views(world, scout)
        scout.close()
        camera = SmartCamera(world, profile.camera, backend=renderer)
        panels: dict[str, list[np.ndarray]] = {name: [] for name, _ in views}
        for raid, look in ((0, "day"), (4, "night")):
            appearance.apply(_preset(house, raid, seed))
            for name, pose in views:
                panels[name].append(_labelled(camera.capture(*pose).rgb, f"{name}, {look}"))
        camera.close()
    pairs = [np.hstack(p) for p in panels.values()]
    rows = [np.hstack(pairs[k:k + 2]) if k + 1 < len(pairs) else np.hstack([pairs[k], np.zeros_like(pairs[k])])
            for k in range(0, len(pairs), 2)]
    sheet = cv2.resize(np.vstack(rows), None, fx=0.5, fy=0.5, interpolation=cv2.INTER_AREA)
    output.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(output), cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR)):
        raise OSError(f"could not write {output}")
    return output
