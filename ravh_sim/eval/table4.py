"""The paper's localization benchmark (§5.5, Table 4) on one house: record, localize, tabulate.

Maps are Grid raids (nodes every 0.5 m, 10 images per node) under the map lightings; routes are
Wanderer raids (about :attr:`Protocol.route_m` metres, an image every :attr:`Protocol.capture_period`
s) under the route lightings. Lighting is the sun angle l_a (degrees: 90 noon, 180 sunset, > 180
night) with the rest of config/default.yaml (ceiling lights on, lamps off, default paint and
models), so only the light differs between a route and a map. At night a home has the lights its
people switched on that evening, not every light in the house: under :attr:`Protocol.night_lights`
``"evening"`` (the default) each night recording draws every light on or off by a fair coin, a
draw of its own (another evening), while ``"all"`` keeps every ceiling light on (the paper's raid-4
preset without its lamps: the night looks like the day, see the README). The CI-sized protocol
(:data:`QUICK`) keeps two maps and two short routes; its maps hold only the grid nodes along the
first route, captured in place. Every recording is an ordinary
dataset under ``OUT/maps/`` and ``OUT/routes/``; a later run reuses recordings made with the same
protocol and seed. Each route is localized against each map (:mod:`ravh_sim.eval.localization`)
:data:`RUNS` times with different odometry noise; a cell of the table is the median over the runs
of each run's median position error (m) and rotation error (deg). Each cell also has its top-1
retrieval (:func:`retrieval`: the share of route images whose most similar map image lies within
:data:`TOP1_M` m and :data:`TOP1_DEG` degrees of the route image's true pose, no odometry), and the
table sets the paper's cell (``config/paper/table4_localization.tsv``) beside each of ours, with the
median of each map's column, each column against the first map's (day) and ours against the paper's
(:func:`beside_paper`).
"""
from __future__ import annotations

import json
import math
import random
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ravh_sim.behaviours.waypoints import Layout, grid_nodes
from ravh_sim.dataset.api import Dataset
from ravh_sim.dataset.layout import RAID_JSON
from ravh_sim.errors import UserError
from ravh_sim.eval.descriptors import Descriptor, describe, load_descriptor
from ravh_sim.eval.localization import Localizer, errors, noisy_odometry
from ravh_sim.paper import TABLE4, TABLE4_METHOD, table4
from ravh_sim.raids.direct import MAX_SIM_S, GridSpec, PosesSpec, WandererSpec, record
from ravh_sim.viz.figure import figure_bgr, new_figure
from ravh_sim.world.house import House, load_house

RUNS = 5
TOP1_M, TOP1_DEG = 1.0, 45.0       # a top-1 retrieval is right when the most similar map image is this close
SPEED = 0.25                       # m/s, the Wanderer's cruise speed (the giraff profile's maximum)


@dataclass(frozen=True)
class Lighting:
    name: str                      # day | sunset | night
    sun_angle: float               # l_a, degrees

    @property
    def label(self) -> str:
        return f"{self.name} {self.sun_angle:g}"

    @property
    def folder(self) -> str:
        return f"{self.name}_{self.sun_angle:g}"


MAPS = (Lighting("day", 170), Lighting("sunset", 179), Lighting("night", 200))
ROUTES = (Lighting("day", 90), Lighting("sunset", 175), Lighting("night", 185), Lighting("night", 195),
          Lighting("day", 25), Lighting("day", 165))


@dataclass(frozen=True)
class Protocol:
    maps: tuple[Lighting, ...] = MAPS
    routes: tuple[Lighting, ...] = ROUTES
    grid_spacing: float = 0.5
    images_per_node: int = 10
    grid_nodes: int = 0            # 0: the whole house
    route_m: float = 25.0          # the Wanderer stops after route_m / SPEED s of sim time; its turns
                                   # make the route shorter (house 15: 20.8 m)
    capture_period: float = 1.0    # s between route images
    map_near_route_m: float = 0.0  # > 0: the map is only the grid nodes this close to the first
                                   # route, captured in place (scripted poses): the CI-sized map
    night_lights: str = "evening"  # evening: each night recording its own coin per light | all:
                                   # every ceiling light on, lamps off (the settings' default)


NIGHT_LIGHTS = ("evening", "all")
FULL = Protocol()
QUICK = Protocol(maps=MAPS[::2], routes=(ROUTES[0], ROUTES[2]), route_m=8.0, map_near_route_m=0.5)


def run_table4(house: int, out: Path, protocol: Protocol = FULL, descriptor: str | Descriptor | None = None,
               seed: int = 0, progress: Callable[[str], None] | None = None,
               paper: Path | None = TABLE4) -> dict[str, Any]:
    """Record what is missing, localize every route on every map, write table4.json/.txt/.png;
    ``paper``: the paper's Table 4 (TSV) to set beside ours (None: ours alone)."""
    if callable(descriptor):
        name, function = getattr(descriptor, "__name__", "custom"), descriptor
    else:
        name, function = load_descriptor(descriptor)
    say = progress or (lambda _: None)
    started = time.monotonic()
    route_spec, route_s = WandererSpec("once", protocol.capture_period, seed), protocol.route_m / SPEED
    if protocol.night_lights not in NIGHT_LIGHTS:
        raise UserError(f"night lights must be one of {', '.join(NIGHT_LIGHTS)}, got {protocol.night_lights!r}")
    home = load_house(house)
    lit: dict[str, int] = {}                  # lights on in each night recording (role/folder)

    def recording(role: str, light: Lighting, spec: GridSpec | WandererSpec | PosesSpec, sim_s: float) -> Dataset:
        switches = light_switches(home, protocol, light, f"{role}/{light.folder}", seed)
        if switches:
            lit[f"{role}/{light.folder}"] = sum(state == "on" for state in switches.values())
        return _recording(out / role / light.folder, house, light, switches, spec, sim_s, seed, say)

    routes = {r: recording("routes", r, route_spec, route_s) for r in protocol.routes}
    map_spec = _map_spec(protocol, routes[protocol.routes[0]])
    maps = {m: recording("maps", m, map_spec, 0.0) for m in protocol.maps}
    recorded = time.monotonic()
    say("describing images")
    map_side = {m: _described(ds, function) for m, ds in maps.items()}
    route_side = {r: _described(ds, function) for r, ds in routes.items()}
    cells = []
    for r, (route_desc, truth) in route_side.items():
        row = []
        for m, (map_desc, map_poses) in map_side.items():
            localizer = Localizer(map_desc, map_poses)
            runs = []
            for run in range(RUNS):
                odometry = noisy_odometry(truth, np.random.default_rng([seed, run]))
                position, rotation = errors(localizer.localize(route_desc, odometry), truth)
                runs.append((float(np.median(position)), float(np.median(rotation))))
            top1, nearest = retrieval(route_desc, truth, map_desc, map_poses)
            row.append({"route": r.label, "map": m.label,
                        "position_m": round(float(np.median([p for p, _ in runs])), 3),
                        "rotation_deg": round(float(np.median([a for _, a in runs])), 2),
                        "top1_pct": round(top1, 1), "nearest_map_image_m": round(nearest, 3),
                        "runs": [{"position_m": round(p, 3), "rotation_deg": round(a, 2)} for p, a in runs]})
        cells.append(row)
    doc = {"house": house, "descriptor": name, "seed": seed, "runs": RUNS,
           "protocol": _protocol_doc(protocol), "house_lights": len(home.lights), "night_lights_on": lit,
           "maps": {m.label: {"images": len(maps[m]), "dataset": str(maps[m].dir)} for m in protocol.maps},
           "routes": {r.label: {"images": len(routes[r]), "length_m": round(_length(route_side[r][1]), 2),
                                "dataset": str(routes[r].dir)} for r in protocol.routes},
           "cells": cells,
           "top1": {"within_m": TOP1_M, "within_deg": TOP1_DEG},
           "wall_s": {"record": round(recorded - started, 1), "evaluate": round(time.monotonic() - recorded, 1)}}
    if paper is not None:
        doc["paper"] = beside_paper(doc, table4(paper), paper)
    out.mkdir(parents=True, exist_ok=True)
    (out / "table4.json").write_text(json.dumps(doc, indent=1) + "\n")
    (out / "table4.txt").write_text(format_table4(doc) + "\n")
    cv2.imwrite(str(out / "table4.png"), draw_table4(doc))
    return doc


def retrieval(route_descriptors: np.ndarray, truth: np.ndarray, map_descriptors: np.ndarray,
              map_poses: np.ndarray) -> tuple[float, float]:
    """(top-1 retrieval %, nearest map image m) of a route on a map: the share of route images whose
    most similar map image (cosine similarity of the descriptors) lies within TOP1_M m and TOP1_DEG
    degrees of the image's true pose; and the median over the route images of the distance to the
    nearest map image's position (the floor the map's spacing sets for any localizer)."""
    best = map_poses[np.argmax(route_descriptors @ map_descriptors.T, axis=1)]
    turn = (best[:, 2] - truth[:, 2] + np.pi) % (2 * np.pi) - np.pi
    near = (np.hypot(best[:, 0] - truth[:, 0], best[:, 1] - truth[:, 1]) <= TOP1_M) \
        & (np.degrees(np.abs(turn)) <= TOP1_DEG)
    gaps = np.hypot(truth[:, None, 0] - map_poses[None, :, 0], truth[:, None, 1] - map_poses[None, :, 1])
    return 100.0 * float(np.mean(near)), float(np.median(gaps.min(axis=1)))


def beside_paper(doc: dict[str, Any], paper: dict[tuple[str, str], tuple[float, float]],
                 source: str | Path = TABLE4) -> dict[str, Any]:
    """The paper's cell beside each of ours (None where the paper has no such route and map), and per
    map the median position error of its column, ours and the paper's, each column's median over the
    first map's (the day map: how much harder its light is) and ours over the paper's."""
    maps = list(doc["maps"])
    cells = [[None if (c["route"], c["map"]) not in paper else
              {"route": c["route"], "map": c["map"], "position_m": paper[c["route"], c["map"]][0],
               "rotation_deg": paper[c["route"], c["map"]][1],
               "ours_over_paper": _ratio(c["position_m"], paper[c["route"], c["map"]][0])} for c in row]
             for row in doc["cells"]]
    columns: list[dict[str, Any]] = []
    for j, m in enumerate(maps):
        theirs = [cell["position_m"] for cell in (row[j] for row in cells) if cell is not None]
        ours = round(float(np.median([row[j]["position_m"] for row in doc["cells"]])), 3)
        median = round(float(np.median(theirs)), 3) if theirs else None
        columns.append({"map": m, "ours_median_m": ours, "paper_median_m": median, "paper_routes": len(theirs),
                        "ours_over_paper": _ratio(ours, median)})
    for column in columns:
        column["ours_over_first_map"] = _ratio(column["ours_median_m"], columns[0]["ours_median_m"])
        column["paper_over_first_map"] = _ratio(column["paper_median_m"], columns[0]["paper_median_m"])
    worst = {"ours": _worst([c for row in doc["cells"] for c in row]),
             "paper": _worst([c for row in cells for c in row if c is not None])}
    return {"source": str(source), "method": TABLE4_METHOD, "cells": cells, "columns": columns, "worst": worst}


def _ratio(a: float | None, b: float | None) -> float | None:
    return None if a is None or not b else round(a / b, 2)


def _worst(cells: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The cell with the largest position error."""
    if not cells:
        return None
    c = max(cells, key=lambda c: c["position_m"])
    return {"route": c["route"], "map": c["map"], "position_m": c["position_m"]}


def _map_spec(protocol: Protocol, route: Dataset) -> GridSpec | PosesSpec:
    """The Grid behaviour, or (CI-sized) its nodes near ``route`` captured in place, the same
    number of headings per node."""
    if protocol.map_near_route_m <= 0:
        return GridSpec(protocol.grid_spacing, protocol.images_per_node, protocol.grid_nodes)
    if route.map is None:
        raise UserError(f"{route.dir}: the route recorded no occupancy map to place the map's nodes on")
    route_xy = np.array([s.pose[:2] for s in route])
    nodes = grid_nodes(Layout.of(route.house), route.map, tuple(route_xy[0]), protocol.grid_spacing)
    near = [n for n in nodes if np.hypot(*(route_xy - n).T).min() <= protocol.map_near_route_m]
    k = protocol.images_per_node
    return PosesSpec(tuple((x, y, 2 * math.pi * i / k) for x, y in near for i in range(k)))


def light_switches(house: House, protocol: Protocol, light: Lighting, recording: str, seed: int
                   ) -> dict[str, str]:
    """The lights one recording switches away from the settings' (ceiling on, lamps off): none by
    day and at sunset; at night, under ``evening``, every light of the house on or off by a fair
    coin from the recording's own stream (``recording`` names it: maps/night_200), so a route and a
    map are two evenings with other rooms lit."""
    if light.sun_angle <= 180.0 or protocol.night_lights == "all":
        return {}
    coin = random.Random(f"{seed}/table4/evening/{recording}")
    return {lt.id: "on" if coin.random() < 0.5 else "off" for lt in house.lights}


def _recording(folder: Path, house: int, light: Lighting, switches: dict[str, str],
               behaviour: GridSpec | WandererSpec | PosesSpec, max_sim_s: float, seed: int,
               say: Callable[[str], None]) -> Dataset:
    """The dataset of one map or route: reused if recorded before with the same request."""
    limits = {"max_sim_s": max_sim_s} if max_sim_s > 0 else {}
    lights = {"lights": switches} if switches else {}
    request = json.loads(json.dumps({"benchmark": "table4", "house": house, "sun_angle": light.sun_angle,
                                     "seed": seed, "behaviour": behaviour.name, "spec": asdict(behaviour),
                                     **lights, **limits}))
    summary_path = folder / RAID_JSON
    if summary_path.exists():
        if json.loads(summary_path.read_text()).get("request") == request:
            return Dataset(folder)
        raise UserError(f"{folder} holds a recording of other settings; use another --out or remove it")
    say(f"recording {behaviour.name} {light.label} into {folder}")
    settings = {"lights": {"sun_angle": light.sun_angle, "set": switches}}
    summary = record(folder, house, behaviour, settings=settings, seed=seed,
                     raid={"request": request}, max_sim_s=max_sim_s if max_sim_s > 0 else MAX_SIM_S)
    if not summary["captures"]:
        raise UserError(f"{folder}: the {behaviour.name} recorded no images ({summary['status']})")
    return Dataset(folder)


def _described(dataset: Dataset, descriptor: Descriptor) -> tuple[np.ndarray, np.ndarray]:
    """(descriptors, poses) of a dataset's captures."""
    return describe((s.rgb for s in dataset), descriptor), np.array([s.pose for s in dataset])


def _length(poses: np.ndarray) -> float:
    return float(np.hypot(*np.diff(poses[:, :2], axis=0).T).sum()) if len(poses) > 1 else 0.0


def _protocol_doc(protocol: Protocol) -> dict[str, Any]:
    doc = asdict(protocol)
    doc["maps"] = [m.label for m in protocol.maps]
    doc["routes"] = [r.label for r in protocol.routes]
    return doc


def format_table4(doc: dict[str, Any]) -> str:
    """Routes x maps: median position error (m) / rotation error (deg), the paper's cell beside each
    of ours when the document has them (``paper``) with the columns' medians and ratios, then the
    top-1 retrieval per cell and what was recorded."""
    maps = list(doc["maps"])
    night = doc["protocol"].get("night_lights", "all")
    lines = [f"House {doc['house']}, descriptor {doc['descriptor']}: median position (m) / rotation (deg) "
             f"error, median of {doc['runs']} runs; night lights: {night}"]
    paper = doc.get("paper")
    if paper is None:
        lines.append(f"{ROUTE_MAP:<14}" + "".join(f"{m:>18}" for m in maps))
        lines += [f"{row[0]['route']:<14}" + "".join(f"{_pair(c):>18}" for c in row) for row in doc["cells"]]
    else:
        lines += _format_beside_paper(doc, paper)
    lines += _format_retrieval(doc)
    lines += _format_recordings(doc)
    return "\n".join(line.rstrip() for line in lines)


ROUTE_MAP = "route \\ map"
W, L = 13, 24                              # characters per column, of the row names


def _pair(cell: dict[str, Any] | None) -> str:
    return "-" if cell is None else f"{cell['position_m']:.2f} / {cell['rotation_deg']:4.1f}"


def _times(v: float | None) -> str:
    return "-" if v is None else f"{v:.2f}x"


def _metres(v: float | None) -> str:
    return "-" if v is None else f"{v:.2f} m"


def _format_beside_paper(doc: dict[str, Any], paper: dict[str, Any]) -> list[str]:
    maps, columns = list(doc["maps"]), paper["columns"]
    lines = [f"the paper's cell ({paper['method']}, {Path(paper['source']).name}) beside each of ours",
             f"{ROUTE_MAP:<{L}}" + "".join(f"{m:^{2 * W}}" for m in maps),
             f"{'':<{L}}" + f"{'ours':>{W}}{'paper':>{W}}" * len(maps)]
    for ours_row, paper_row in zip(doc["cells"], paper["cells"]):
        lines.append(f"{ours_row[0]['route']:<{L}}" + "".join(f"{_pair(o):>{W}}{_pair(p):>{W}}"
                                                             for o, p in zip(ours_row, paper_row)))
    lines.append(f"{'median of the column':<{L}}" + "".join(
        f"{_metres(c['ours_median_m']):>{W}}{_metres(c['paper_median_m']):>{W}}" for c in columns))
    lines.append(f"{'ratio to ' + maps[0] + ' column':<{L}}" + "".join(
        f"{_times(c['ours_over_first_map']):>{W}}{_times(c['paper_over_first_map']):>{W}}" for c in columns))
    lines.append(f"{'ours / paper':<{L}}" + "".join(f"{_times(c['ours_over_paper']):>{W}}{'':>{W}}" for c in columns))
    short = [f"{c['map']}: {c['paper_routes']} of {len(doc['cells'])} routes" for c in columns
             if c["paper_routes"] < len(doc["cells"])]
    if short:
        lines.append("the paper's column medians cover " + ", ".join(short))
    worst = [f"{who} {w['route']} on {w['map']} ({w['position_m']:.2f} m)"
             for who, w in paper["worst"].items() if w is not None]
    lines.append("largest position error: " + "; ".join(worst))
    return lines


def _format_retrieval(doc: dict[str, Any]) -> list[str]:
    if not all("top1_pct" in c for row in doc["cells"] for c in row):
        return []
    top1 = doc.get("top1", {"within_m": TOP1_M, "within_deg": TOP1_DEG})
    lines = ["", f"top-1 retrieval, ours: % of route images whose most similar map image lies within "
                 f"{top1['within_m']:g} m and {top1['within_deg']:g} deg (no odometry);",
             "nearest: median distance from a route image to the nearest map image (the map's floor)",
             f"{ROUTE_MAP:<{L}}" + "".join(f"{m:>{W}}" for m in doc["maps"]) + f"{'nearest':>{W}}"]
    for row in doc["cells"]:
        nearest = sorted({f"{c['nearest_map_image_m']:.2f}" for c in row}, key=float)
        span = nearest[0] if len(nearest) == 1 else f"{nearest[0]}-{nearest[-1]}"
        lines.append(f"{row[0]['route']:<{L}}" + "".join(f"{c['top1_pct']:>{W - 2}.1f} %" for c in row)
                     + f"{span + ' m':>{W}}")
    return lines


def _format_recordings(doc: dict[str, Any]) -> list[str]:
    maps = ", ".join(f"{m} {v['images']}" for m, v in doc["maps"].items())
    routes = ", ".join(f"{r} {v['images']} ({v['length_m']:.1f} m)" for r, v in doc["routes"].items())
    lines = ["", f"images: maps {maps}; routes {routes}"]
    if doc.get("night_lights_on"):
        lit = ", ".join(f"{k} {n}" for k, n in doc["night_lights_on"].items())
        lines.append(f"lights on at night (of the house's {doc['house_lights']}): {lit}")
    if "wall_s" in doc:
        lines.append(f"wall time of this run: recording {doc['wall_s']['record']:.0f} s (recordings already "
                     f"there are reused), describing and localizing {doc['wall_s']['evaluate']:.0f} s")
    return lines


# --------------------------------------------------------------------------- the heat map

CELL_W, CELL_H = 120, 44          # px per table cell
MARGIN_W, MARGIN_H = 300, 150     # px around the cells: route names, map names, titles, colour bars


def draw_table4(doc: dict[str, Any]) -> np.ndarray:
    """Two heat maps side by side, position and rotation error, routes x maps (BGR); each colour
    scale runs from 0 to the panel's largest value."""
    routes, maps = [row[0]["route"] for row in doc["cells"]], list(doc["maps"])
    figure = new_figure(2 * (MARGIN_W + CELL_W * len(maps)), MARGIN_H + CELL_H * len(routes))
    figure.suptitle(f"House {doc['house']} localization ({doc['descriptor']}), median of {doc['runs']} runs",
                    fontsize=12)
    panels = figure.subplots(1, 2, gridspec_kw={"left": 0.1, "right": 0.95, "wspace": 0.6,
                                                "top": 1 - 70 / figure.bbox.height, "bottom": 0.06})
    for axes, (key, heading, fmt) in zip(panels, (("position_m", "position error (m)", "{:.2f}"),
                                                  ("rotation_deg", "rotation error (deg)", "{:.1f}"))):
        values = np.array([[c[key] for c in row] for row in doc["cells"]], float)
        top = values.max() if values.size and values.max() > 0 else 1.0
        image = axes.imshow(values, cmap="viridis", vmin=0.0, vmax=top, aspect="auto")
        axes.set_title(heading, fontsize=11, pad=24)
        axes.set_xticks(range(len(maps)), [f"map {m}" for m in maps], fontsize=9)
        axes.set_yticks(range(len(routes)), routes, fontsize=9)
        axes.xaxis.tick_top()
        axes.tick_params(length=0)
        for i, j in np.ndindex(values.shape):
            axes.text(j, i, fmt.format(values[i, j]), ha="center", va="center", fontsize=11,
                      color="black" if values[i, j] / top > 0.6 else "white")
        figure.colorbar(image, ax=axes, fraction=0.08, pad=0.03)
    return figure_bgr(figure)
