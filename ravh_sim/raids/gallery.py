"""``ravh gallery``: one view of a house under the paper's five raid presets (Table 1) and a random
appearance, as one contact sheet, to judge the renderer's look at a glance.

The view is chosen automatically unless given: among room centres and eight headings, the one that
shows the most labelled objects from at least MIN_VIEW_DEPTH_M away (counted on a fast render).
"""
from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from ravh_sim.nav.grid import Grid
from ravh_sim.raids.raid import PRESETS, preset_settings
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.camera import SmartCamera
from ravh_sim.viz.figure import figure_bgr, new_figure
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.facing import choose_facing, front_axis
from ravh_sim.world.geometry import polygon_centroid
from ravh_sim.world.house import House, HouseObject, load_house
from ravh_sim.world.scene import World
from ravh_sim.world.settings import Resolved, load_settings, resolve

MIN_OBJECT_PIXELS = 800          # an object counts as seen in a candidate view from this many pixels
MIN_VIEW_DEPTH_M = 2.5           # median depth of a candidate view: a room, not a close-up
WIDE_VIEW_DEPTH_M = 4.0          # views this deep or deeper count their objects in full
LABEL_PX = 30


def best_view(world: World, camera: SmartCamera, kinds: tuple[str, ...] = ("object",),
              stand_back: bool = False) -> tuple[float, float, float]:
    """The room-centre pose and heading that sees the most instances of ``kinds`` from far enough
    back (the station's pose when no candidate qualifies); ``stand_back`` also tries the points
    halfway from each room's centre to its corners, where a photographer takes in the whole room,
    those the robot fits at (navigation free space)."""
    from ravh_sim.nav.navigation import Navigation
    from ravh_sim.world.state import WorldState
    free = Navigation(world.house, WorldState(world.state.settings()), load_profile()).map() if stand_back else None
    counted = {inst.id for inst in world.instances if inst.kind in kinds}
    best, best_count = None, -1.0
    for room in world.house.rooms:
        x, y = polygon_centroid(room.floor)
        if not room.contains(x, y):
            continue
        spots = [(x, y)] + ([((x + cx) / 2, (y + cy) / 2) for cx, cy in room.floor
                             if free is not None and free.is_free((x + cx) / 2, (y + cy) / 2)])
        for (sx, sy), k in itertools.product(spots, range(8)):
            if not room.contains(sx, sy):
                continue
            pose = (sx, sy, k * math.pi / 4)
            capture = camera.capture(*pose)
            depth = float(np.nanmedian(capture.depth)) if np.isfinite(capture.depth).any() else 0.0
            if depth < MIN_VIEW_DEPTH_M:
                continue
            counts = np.bincount(capture.instance.ravel())
            seen = sum(1 for i in np.flatnonzero(counts >= MIN_OBJECT_PIXELS) if i in counted)
            score = seen * min(1.0, depth / WIDE_VIEW_DEPTH_M)
            if score > best_count:
                best, best_count = pose, score
    if best is None:
        station = world.house.station
        return station.position[0], station.position[1], station.yaw
    return best


def gallery(house_number: int, output: Path, seed: int = 0,
            pose: tuple[float, float, float] | None = None, renderer: str = "auto",
            quality: str = "realistic") -> Path:
    """Write the contact sheet (3 x 2 panels) to ``output``; returns it. ``quality``: the camera's."""
    house = load_house(house_number)
    profile = load_profile()
    with World(house, _preset(house, 0, seed)) as world:
        appearance = Appearance(world)
        pose = pose or _best_view(world, renderer)
        camera = SmartCamera(world, replace(profile.camera, quality=quality), backend=renderer)
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
    return _write(np.vstack([np.hstack(panels[:3]), np.hstack(panels[3:])]), output)


def dressing_gallery(house_number: int, output: Path, seed: int = 0,
                     pose: tuple[float, float, float] | None = None, renderer: str = "auto",
                     quality: str = "realistic") -> Path:
    """Write a 2 x 2 sheet to ``output``: one view with no dressing (the paper's objects only) beside
    the default ``lived-in`` dressing, by day (raid 0's look) and at night (raid 4's); returns it. The
    view, unless given, is the one that shows the most objects, dressing included."""
    house = load_house(house_number)
    profile = load_profile()
    with World(house, _preset(house, 0, seed, DRESSING_SHOWN[-1])) as world:
        appearance = Appearance(world)
        pose = pose or _best_view(world, renderer, ("object", "dressing"), True)
        camera = SmartCamera(world, replace(profile.camera, quality=quality), backend=renderer)
        rows = []
        for raid, look in LOOKS:
            row = []
            for dressing in DRESSING_SHOWN:
                appearance.apply(_preset(house, raid, seed, dressing))
                row.append(_labelled(camera.capture(*pose).rgb, f"dressing {dressing}, {look}"))
            rows.append(np.hstack(row))
        camera.close()
    return _write(np.vstack(rows), output)


def _best_view(world: World, renderer: str, kinds: tuple[str, ...] = ("object",),
               stand_back: bool = False) -> tuple[float, float, float]:
    """:func:`best_view` counted on a fast render."""
    scout = SmartCamera(world, replace(load_profile().camera, quality="fast"), backend=renderer)
    try:
        return best_view(world, scout, kinds, stand_back)
    finally:
        scout.close()


def _write(sheet: np.ndarray, output: Path) -> Path:
    output.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(output), cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR)):
        raise OSError(f"could not write {output}")
    return output


def _preset(house, raid: int, seed: int, dressing: str | None = None) -> Resolved:
    """The resolved settings of a raid preset: the defaults with the preset's sections over them
    (and ``dressing`` over the preset's, when given)."""
    settings = load_settings()
    for section, values in preset_settings(PRESETS[raid], seed).items():
        settings[section] = {**settings[section], **values} if isinstance(values, dict) else values
    if dressing is not None:
        settings["dressing"] = dressing
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
LOOKS = ((0, "day"), (4, "night"))
"""The raids whose look the object and dressing sheets show, side by side, from one pose."""
DRESSING_SHOWN = ("none", "lived-in")
OBJECTS_PER_TYPE = 4              # objects of a type tried for a view (the house's order)
VIEW_AZIMUTHS_DEG = (0.0, -20.0, 20.0, -40.0, 40.0, -60.0, 60.0, 90.0, -90.0)
"""Where the photographer may stand, as an angle from the object's front (its sides last)."""
VIEW_DISTANCE_RANGE_M = (0.8, 6.0)   # robot to object centre, scanned in VIEW_DISTANCE_STEP_M steps
VIEW_DISTANCE_STEP_M = 0.1
FRAME_MARGIN = 0.04               # share of the frame kept free around the object's projected box
FILL_RANGE = (0.15, 0.5)          # share of the frame the object's projected box should cover
RENDERED_PER_OBJECT = 6           # candidate poses per object scored on fast renders, per look
MIN_SEEN_PIXELS = 300             # a render that shows less of the object than this does not count
MAX_OUTSIDE = 0.3                 # where no pose frames an object whole, at most this share of its box cut
WALL_SHARE_FREE = 0.55           # walls may take this share of a view before they cost anything


@dataclass(frozen=True)
class Shot:
    """A candidate pose for photographing one object, and what the renders said of it."""
    object_id: str
    pose: tuple[float, float, float]
    azimuth: float                # rad from the object's front
    box_share: float              # share of the frame the object's projected box covers
    outside: float = 0.0          # share of the projected box outside the frame's margin (0: framed)
    free: bool = True             # the robot fits there (navigation free space); else only a room
    score: float = 0.0
    seen: float = 0.0             # per look (worst): object pixels / its projected box's pixels
    cut: float = 0.0              # per look (worst): object pixels on the frame's edge / its outline
    blocked: float = 0.0          # per look (worst): share of the box's pixels hidden by nearer things
    fill: float = 0.0             # per look (worst): share of the frame the object's pixels cover
    walls: float = 0.0            # per look (worst): share of the frame that is wall


def object_box(house: House, obj: HouseObject, model: int | None) -> tuple[np.ndarray, float]:
    """The 8 corners (8, 3) of an object's box as ``model`` shows it (house frame), and the heading
    of its front: the library model's, else the side away from the nearest wall (world/facing.py)."""
    from ravh_sim.world.solids import object_parts
    placed = object_parts(house, obj, model)
    lo, hi = placed.extent()
    local = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    c, s = math.cos(placed.yaw), math.sin(placed.yaw)
    corners = local @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]) + np.asarray(placed.position)
    if placed.front is not None:
        return corners, placed.front
    box = obj.box(model)
    walls = [(w.a, w.b) for w in house.walls if w.room == obj.room and w.kind != "lintel"]
    facing = choose_facing(tuple(box.position[:2]), obj.yaw, tuple(box.size), walls, front_axis(obj.type))
    return corners, obj.yaw + facing * math.pi / 2


def candidate_shots(world: World, camera: SmartCamera, obj: HouseObject, corners: np.ndarray, front: float,
                    free: list[Grid]) -> list[Shot]:
    """Poses that frame ``corners`` (every look's box of ``obj``): per azimuth around its front, the
    distances at which the box's projection lies inside the frame with a margin and covers a good
    share of it, at robot positions free in every map of ``free``; best framed first. Where the room is
    too small to frame the box whole, poses that cut at most MAX_OUTSIDE of it (any, where none does),
    least cut first; poses in the object's own room only, where there are any."""
    house = world.house
    centre = corners.mean(axis=0)
    w, h = camera.width, camera.height
    mx, my = FRAME_MARGIN * w, FRAME_MARGIN * h
    frame = np.array([[mx, my], [w - mx, my], [w - mx, h - my], [mx, h - my]], np.float32)
    shots: list[Shot] = []
    steps = int(round((VIEW_DISTANCE_RANGE_M[1] - VIEW_DISTANCE_RANGE_M[0]) / VIEW_DISTANCE_STEP_M)) + 1
    for azimuth_deg in VIEW_AZIMUTHS_DEG:
        azimuth = math.radians(azimuth_deg)
        heading = front + azimuth
        for k in range(steps):
            distance = VIEW_DISTANCE_RANGE_M[0] + k * VIEW_DISTANCE_STEP_M
            x, y = centre[0] + distance * math.cos(heading), centre[1] + distance * math.sin(heading)
            room = house.room_at(x, y)
            if room is None or not all(grid.is_free(x, y) for grid in free):
                continue
            pose = (float(x), float(y), float(math.atan2(centre[1] - y, centre[0] - x)))
            uv = camera.project(corners, *pose, floor_z=room.floor_z)
            if not np.isfinite(uv).all():
                continue
            hull = cv2.convexHull(uv.astype(np.float32))
            area = float(cv2.contourArea(hull))
            framed = (uv[:, 0].min() >= mx and uv[:, 0].max() <= w - mx
                      and uv[:, 1].min() >= my and uv[:, 1].max() <= h - my)
            inside, _ = cv2.intersectConvexConvex(hull, frame)
            outside = 0.0 if framed else 1.0 - float(inside) / max(area, 1e-9)
            if outside < 1.0:
                shots.append(Shot(obj.id, pose, azimuth, min(area, float(inside)) / (w * h), outside, bool(free)))
    home = [shot for shot in shots if getattr(house.room_at(*shot.pose[:2]), "id", None) == obj.room]
    shots = home or shots        # from the object's own room, not through a wall, where it can
    framed = [shot for shot in shots if shot.outside <= MAX_OUTSIDE]
    return sorted(framed or shots, key=_framing)


def _framing(shot: Shot) -> float:
    """Lower is better: off the good fill range, and away from the object's front."""
    low, high = FILL_RANGE
    off = (low - shot.box_share) / low if shot.box_share < low else max(0.0, shot.box_share - high) / high
    return off + abs(shot.azimuth) / math.pi + 4.0 * shot.outside


def _spread(shots: list[Shot], count: int) -> list[Shot]:
    """The ``count`` best-framed shots, one per azimuth first (so the renders see different sides)."""
    chosen: list[Shot] = []
    for shot in shots:
        if len(chosen) < count and all(abs(shot.azimuth - c.azimuth) > 1e-6 for c in chosen):
            chosen.append(shot)
    for shot in shots:
        if len(chosen) < count and shot not in chosen:
            chosen.append(shot)
    return chosen


def judge(camera: SmartCamera, shot: Shot, instance: int, corners: np.ndarray,
          walls: np.ndarray) -> dict[str, float]:
    """What a fast render from ``shot`` shows of the object (``instance``, box ``corners``):
    ``seen``, ``cut``, ``blocked``, ``fill`` and ``walls`` as in :class:`Shot`. ``walls``: per
    instance id, whether it is a wall."""
    capture = camera.capture(*shot.pose)
    mask = capture.instance == instance
    pixels = int(mask.sum())
    uv = camera.project(corners, *shot.pose)
    hull = np.zeros(mask.shape, np.uint8)
    cv2.fillConvexPoly(hull, np.round(cv2.convexHull(uv.astype(np.float32))).astype(np.int32), 1)
    inside = hull.astype(bool)
    position, rotation = camera.optical_pose(*shot.pose)
    nearest = float(((corners - position) @ rotation)[:, 2].min())
    depth = np.nan_to_num(capture.depth, nan=np.inf)
    blocked = float((inside & ~mask & (depth < nearest - 0.05)).sum()) / max(1, int(inside.sum()))
    edge = int(mask[0].sum() + mask[-1].sum() + mask[1:-1, 0].sum() + mask[1:-1, -1].sum())
    if pixels:
        rows, cols = np.nonzero(mask)
        outline = 2 * (rows.max() - rows.min() + 1 + cols.max() - cols.min() + 1)
    else:
        outline = 1
    return {"seen": min(1.0, pixels / max(1, int(inside.sum()))), "cut": edge / outline, "blocked": blocked,
            "fill": pixels / mask.size, "walls": float(walls[capture.instance].mean()),
            "pixels": float(pixels)}


def _score(shot: Shot, look: dict[str, float]) -> float:
    """Higher is better: the object seen whole and unhidden, framed, from its front, walls kept back."""
    if look["pixels"] < MIN_SEEN_PIXELS:
        return -10.0
    return (look["seen"] - 3.0 * look["blocked"] - 4.0 * look["cut"] - 1.5 * max(0.0, look["walls"] - WALL_SHARE_FREE)
            - 0.5 * _framing(shot) - (0.0 if shot.free else 0.5))


def object_views(world: World, camera: SmartCamera, types: tuple[str, ...] = SHOWCASE_TYPES,
                 looks: Sequence[Resolved] = ()) -> list[tuple[str, Shot]]:
    """Per type the house has, a photographer's pose for one of its objects: candidate poses around
    its front that frame its box (:func:`candidate_shots`), in free space, the best framed few
    scored on fast renders by ``camera`` (:func:`judge`) in every look of ``looks`` (the world's
    current one when empty; the world is left in the last), the best worst-look score kept. Where the
    robot fits nowhere in view of an object, any pose in a room serves (``Shot.free`` says).
    Deterministic: no randomness, ties go to the house's object order."""
    from ravh_sim.nav.navigation import Navigation
    from ravh_sim.world.state import WorldState
    house = world.house
    states = list(looks) or [world.state.settings()]
    profile = load_profile()
    free = [Navigation(house, WorldState(state), profile).map() for state in states]
    walls = np.zeros(max(i.id for i in world.instances) + 1, bool)
    walls[[i.id for i in world.instances if i.kind == "walls"]] = True
    plans: dict[str, list[tuple[Shot, np.ndarray]]] = {}
    for object_type in types:
        plans[object_type] = []
        for obj in [o for o in house.objects if o.type == object_type][:OBJECTS_PER_TYPE]:
            boxes = [object_box(house, obj, state.models.get(obj.id)) for state in states]
            corners = np.concatenate([c for c, _ in boxes])
            found = candidate_shots(world, camera, obj, corners, boxes[0][1], free)
            if not found:        # a bathroom too small for the robot: a photographer still fits
                found = candidate_shots(world, camera, obj, corners, boxes[0][1], [])
            for shot in _spread(found, RENDERED_PER_OBJECT):
                plans[object_type].append((shot, corners))
    judged: dict[tuple[str, int], list[dict[str, float]]] = {}
    appearance = Appearance(world)
    for state in states:
        if looks:
            appearance.apply(state)
        for object_type, shots in plans.items():
            for n, (shot, _) in enumerate(shots):
                obj = house.object_by_id[shot.object_id]
                corners, _front = object_box(house, obj, world.state.models.get(obj.id))
                judged.setdefault((object_type, n), []).append(
                    judge(camera, shot, world.instance(obj.id).id, corners, walls))
    views = []
    for object_type, shots in plans.items():
        best: Shot | None = None
        for n, (shot, _) in enumerate(shots):
            results = judged[(object_type, n)]
            score = min(_score(shot, r) for r in results)
            scored = replace(shot, score=score, seen=min(r["seen"] for r in results),
                             fill=min(r["fill"] for r in results), cut=max(r["cut"] for r in results),
                             blocked=max(r["blocked"] for r in results), walls=max(r["walls"] for r in results))
            if best is None or scored.score > best.score:
                best = scored
        if best is not None and best.score > -10.0:
            views.append((object_type, best))
    return views


def object_gallery(house_number: int, output: Path, seed: int = 0, renderer: str = "auto",
                   quality: str = "realistic") -> Path:
    """Write a sheet of the showcase types of a house, each seen from the front by day (raid 0's
    look) and at night with the lights on (raid 4's), side by side. ``quality``: the camera's."""
    house = load_house(house_number)
    profile = load_profile()
    with World(house, _preset(house, 0, seed)) as world:
        appearance = Appearance(world)
        scout = SmartCamera(world, replace(profile.camera, quality="fast"), backend=renderer)
        views = [(name, shot.pose) for name, shot in
                 object_views(world, scout, looks=[_preset(house, raid, seed) for raid, _ in LOOKS])]
        scout.close()
        camera = SmartCamera(world, replace(profile.camera, quality=quality), backend=renderer)
        panels: dict[str, list[np.ndarray]] = {name: [] for name, _ in views}
        for raid, look in LOOKS:
            appearance.apply(_preset(house, raid, seed))
            for name, pose in views:
                panels[name].append(_labelled(camera.capture(*pose).rgb, f"{name}, {look}"))
        camera.close()
    pairs = [np.hstack(p) for p in panels.values()]
    rows = [np.hstack(pairs[k:k + 2]) if k + 1 < len(pairs) else np.hstack([pairs[k], np.zeros_like(pairs[k])])
            for k in range(0, len(pairs), 2)]
    return _write(cv2.resize(np.vstack(rows), None, fx=0.5, fy=0.5, interpolation=cv2.INTER_AREA), output)
