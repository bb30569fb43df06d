"""``ravh``: the command-line tool for everything that is not a ROS node.

Each subcommand is a thin shell over the library: parse flags, call one function, print or write the
result. User mistakes (bad house number, malformed file, bad JSON) end with one ``ravh: error:`` line
and exit status 2, never a traceback.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import signal
import sys
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ravh_msgs_py.appearance import DOOR, DRESSING, SWITCH
from ravh_msgs_py.names import DEFAULT_PROFILE
from ravh_sim.bench import BENCHES
from ravh_sim.errors import UserError
from ravh_sim.nodes.launch import NODES
from ravh_sim.nodes.launch import main as launch_node
from ravh_sim.paths import FURNITURE_DIR, HOUSES_DIR
from ravh_sim.raids.build import add_parser as add_dataset_parser
from ravh_sim.raids.raid import QUALITY_PROFILES, RAID_QUALITY_HELP
from ravh_sim.render.backend import BACKENDS, QUALITIES

Command = Callable[[argparse.Namespace], int]


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] in NODES:                  # ROS nodes parse their own flags and --ros-args
        return launch_node(argv[0], argv[1:])
    parser = _parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return args.func(args)
    except UserError as e:
        print(f"ravh: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:                        # `ravh houses --json | head`: the reader left
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())   # no second error at exit
        return 141                                 # 128 + SIGPIPE, as a shell reports it
    except OSError as e:                           # unwritable output, full disk: files are written atomically
        print(f"ravh: error: {e.filename or ''}: {e.strerror or e}", file=sys.stderr)
        return 2


# ---------------------------------------------------------------------------- helpers

HOUSE_HELP = "house: number (1..30, or an imported home's), imported home's name, or path of a house file"


def _world_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("house", help=HOUSE_HELP)
    p.add_argument("--seed", type=int, default=None, help="seed for every random choice (default: config)")
    p.add_argument("--config", type=Path, default=None, help="settings YAML (see config/default.yaml)")
    p.add_argument("--dressing", choices=DRESSING, default=None,
                   help="what else the house holds: none, tidy or lived-in (default: config)")


def _resolved(args: argparse.Namespace):
    from ravh_sim.world.house import load_house
    from ravh_sim.world.settings import load_settings, resolve
    house = load_house(args.house)
    settings = load_settings(args.config)
    if getattr(args, "dressing", None) is not None:
        settings["dressing"] = args.dressing
    return house, resolve(settings, house, args.seed, str(args.config or "config/default.yaml"))


def _print_json(data: object) -> None:
    print(json.dumps(data, indent=2))


# ---------------------------------------------------------------------------- houses (issue: houses)

def cmd_import_houses(args: argparse.Namespace) -> int:
    from ravh_sim.importers.houses import import_houses
    written = import_houses(args.src, args.out)
    print(f"imported {len(written)} houses into {args.out}")
    return 0


def cmd_import_furniture(args: argparse.Namespace) -> int:
    from ravh_sim.importers.furniture import import_furniture, iter_archives
    archives = list(iter_archives(args.src))
    if not archives:
        raise UserError("no .sh3f or .jar furniture catalogue among " + ", ".join(map(str, args.src)))
    written = import_furniture(archives, args.out, progress=not args.quiet)
    print(f"imported {sum(map(len, written.values()))} models of {sum(1 for v in written.values() if v)} kinds "
          f"into {args.out}")
    return 0


def cmd_import_home(args: argparse.Namespace) -> int:
    from ravh_sim.importers.home import import_home
    from ravh_sim.paths import user_houses_dir
    out = args.out or user_houses_dir()
    done = import_home(args.src, out, args.name, args.level)
    if done.levels:
        print(f"levels: {', '.join(done.levels)}; imported: {done.level}")
    counts = ", ".join(f"{v} {k}" for k, v in done.counts.items())
    print(f"imported {args.src} as house {done.number} {done.name!r} in {done.seconds:.1f} s: {counts}")
    for what, count in done.left_out.items():
        print(f"  left out: {what}" + (f" ({count})" if count > 1 else ""))
    for name, x, y, yaw in done.views:
        print(f"  stored view {name!r}: --pose {x} {y} {yaw}")
    print(f"wrote {done.path}; try: ravh plan {done.name} -o plan.png")
    return 0


def cmd_houses(args: argparse.Namespace) -> int:
    from ravh_sim.world.house import available_houses, imported_houses, load_house
    rows: list[dict[str, Any]] = []
    every: list[int | str] = [*available_houses(), *imported_houses()]
    for n in every:
        h = load_house(n)
        named = {"name": h.name} if h.name else {}
        rows.append({"house": h.number, **named, "rooms": len(h.rooms), "objects": len(h.objects),
                     "doors": len(h.doors), "windows": len(h.windows), "lights": len(h.lights),
                     "rooms_by_type": dict(sorted(Counter(r.type for r in h.rooms).items())),
                     "objects_by_type": dict(sorted(Counter(o.type for o in h.objects).items()))})
    if args.json:
        _print_json(rows)
        return 0
    print(f"{'house':>5} {'rooms':>5} {'objects':>7} {'doors':>5} {'windows':>7} {'lights':>6}  room types")
    for r in rows:
        types = ", ".join(f"{k} {v}" for k, v in r["rooms_by_type"].items())
        print(f"{r['house']:>5} {r['rooms']:>5} {r['objects']:>7} {r['doors']:>5} {r['windows']:>7} "
              f"{r['lights']:>6}  {types}")
    print(f"{'all':>5} {sum(r['rooms'] for r in rows):>5} {sum(r['objects'] for r in rows):>7}")
    return 0


def cmd_plan(args: argparse.Namespace) -> int:
    from ravh_sim.viz.plan import draw_plan, write_plan
    house, resolved = _resolved(args)
    free = path = None
    if args.free_space or args.path:
        from ravh_sim.nav.freespace import free_space
        from ravh_sim.nav.planner import plan_path
        from ravh_sim.world.dressing import dressing
        free = free_space(house, resolved.doors, resolved.models,
                          dressed=dressing(house, resolved.models, resolved.dressing, resolved.seed))
        if args.path:
            x0, y0, x1, y1 = args.path
            closed = [d for d, is_open in resolved.doors.items() if not is_open]
            path = plan_path(free, (x0, y0), (x1, y1), house=house, blocked_by=closed).points
    image = draw_plan(house, door_open=resolved.doors, models=resolved.models,
                      free_space=free if args.free_space else None, path=path)
    write_plan(args.output, image)
    print(f"wrote {args.output}")
    return 0


def cmd_map(args: argparse.Namespace) -> int:
    from ravh_sim.nav.navigation import Navigation
    from ravh_sim.robot.profile import load_profile
    from ravh_sim.world.house import load_house
    from ravh_sim.world.settings import load_settings, resolve
    from ravh_sim.world.state import WorldState
    house = load_house(args.house)
    settings = load_settings(args.config)
    if args.doors:
        settings["doors"] = {"all": args.doors, "set": {}}
    resolved = resolve(settings, house, args.seed, str(args.config or "config/default.yaml"))
    profile = load_profile(args.profile or (resolved.agents[0].profile if resolved.agents else DEFAULT_PROFILE))
    navigation = Navigation(house, WorldState(resolved), profile, args.resolution)
    pgm, yaml_path = navigation.write_map(args.output, args.inflated)
    print(f"wrote {pgm} and {yaml_path}")
    return 0


def _positive(text: str) -> float:
    value = float(text)
    if not 0.0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def cmd_footprint(args: argparse.Namespace) -> int:
    from ravh_sim.world.footprint import make_footprint, write_footprint
    house, resolved = _resolved(args)
    write_footprint(make_footprint(house, resolved), args.output)
    print(f"wrote {args.output}")
    return 0


def cmd_query(args: argparse.Namespace) -> int:
    from ravh_sim.world.ground_truth import GroundTruth
    from ravh_sim.world.state import WorldState
    house, resolved = _resolved(args)
    reply = GroundTruth(house, WorldState(resolved)).answer(args.request)
    _print_json(reply)
    return 0 if reply["ok"] else 1


def cmd_render(args: argparse.Namespace) -> int:
    from ravh_sim.robot.profile import load_profile
    from ravh_sim.sensors.camera import SmartCamera, write_capture
    from ravh_sim.world.appearance import Appearance
    from ravh_sim.world.scene import World
    house, resolved = _resolved(args)
    pose = args.pose or (*house.station.position[:2], house.station.yaw)     # default: the robot's start
    house.room_at_or_raise(*pose[:2])                # an all-sky picture from outside helps nobody
    with World(house, resolved) as world:
        appearance = Appearance(world)
        if args.sun is not None:
            appearance.set_knob("sun_angle", _sun_value(args.sun))
        if args.lights is not None:
            appearance.set_lights("all", args.lights, args.seed)
        spec = load_profile(args.profile).camera
        if args.quality is not None:
            spec = dataclasses.replace(spec, quality=args.quality)
        camera = SmartCamera(world, spec, backend=args.renderer)
        paths = write_capture(camera, camera.capture(*pose), args.output)
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def cmd_gallery(args: argparse.Namespace) -> int:
    from ravh_sim.raids.gallery import dressing_gallery, gallery, object_gallery
    pose = tuple(args.pose) if args.pose else None
    if args.objects:
        written = object_gallery(args.house, args.output, args.seed, args.renderer, args.quality)
    elif args.dressing:
        written = dressing_gallery(args.house, args.output, args.seed, pose, args.renderer, args.quality)
    else:
        written = gallery(args.house, args.output, args.seed, pose, args.renderer, args.quality)
    print(f"wrote {written}")
    return 0


def _sun_value(text: str) -> float | str:
    """--sun: degrees or a preset name."""
    try:
        return float(text)
    except ValueError:
        return text


def cmd_raid(args: argparse.Namespace) -> int:
    from ravh_sim.raids.outcome import Outcome
    from ravh_sim.raids.raid import run_raid
    from ravh_sim.world.house import available_houses, load_house
    houses: list[int | str] = list(available_houses()) if args.all else [args.house]
    if not args.all:
        load_house(args.house)                        # unknown house: the usual clear error
    signal.signal(signal.SIGINT, _interrupt_once)
    results = []
    for house in houses:
        out = args.out / f"house{int(house):02d}_raid{args.raid}" if args.all else args.out
        results.append(run_raid(house, args.raid, out, fast=args.fast, seed=args.seed,
                                max_captures=args.max_captures, max_nodes=args.max_nodes, quality=args.quality))
        if Outcome.of(results[-1]["status"]) is Outcome.INTERRUPTED:       # Ctrl-C ends --all too
            break
    print(json.dumps(results if args.all else results[0], indent=1))
    return 0 if all(Outcome.of(r["status"]).complete for r in results) else 1


def _interrupt_once(signum: int, frame: Any) -> None:
    """The first Ctrl-C interrupts the raid; later presses are ignored until the process exits. Python
    resets its own handler to the default at exit, so a second press landing while the interpreter shuts
    down would otherwise kill the raid by the signal after its summary, and change its exit status."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    raise KeyboardInterrupt


def cmd_bench(args: argparse.Namespace) -> int:
    from ravh_sim import bench
    from ravh_sim.world.house import house_number
    houses = [house_number(h) for h in args.houses] if args.houses else None     # names -> numbers
    result = bench.run(args.what, houses=houses)
    if args.json:
        print(json.dumps(result, indent=1))
    else:
        for key, value in result.items():
            print(f"{key}: {value}")
    return 0


def cmd_raid_summary(args: argparse.Namespace) -> int:
    from ravh_sim.dataset.api import Dataset
    from ravh_sim.raids.summary import write_summary
    dataset = Dataset(args.dataset)
    write_summary(dataset, args.output)
    print(f"wrote {args.output} ({len(dataset)} captures)")
    return 0


# ---------------------------------------------------------------------------- parser

def _parser() -> argparse.ArgumentParser:
    nodes = ", ".join(NODES)
    parser = argparse.ArgumentParser(prog="ravh", description="Robot@VirtualHome for ROS 2: tools.",
                                     epilog=f"ROS nodes, also runnable as 'ravh NODE --help': {nodes}")
    sub = parser.add_subparsers(metavar="COMMAND")

    p = sub.add_parser("import-houses", help="convert upstream house facts into houses/")
    p.add_argument("src", type=Path, help="folder with the upstream houseNN.json files")
    p.add_argument("-o", "--out", type=Path, default=HOUSES_DIR, help="output folder (default: houses/)")
    p.set_defaults(func=cmd_import_houses)

    p = sub.add_parser("import-furniture",
                       help="convert Sweet Home 3D furniture catalogues into the furniture library (maintainers)")
    p.add_argument("src", type=Path, nargs="+",
                   help=".sh3f/.jar catalogues or folders holding them (Debian: sweethome3d-furniture, sweethome3d)")
    p.add_argument("-o", "--out", type=Path, default=FURNITURE_DIR, help="output folder (default: furniture/)")
    p.add_argument("-q", "--quiet", action="store_true", help="no line per model")
    p.set_defaults(func=cmd_import_furniture)

    p = sub.add_parser("import-home", help="import a Sweet Home 3D home (.sh3d) as a house of ours")
    p.add_argument("src", type=Path, help="the .sh3d file")
    p.add_argument("--name", default=None, help="the house's name (default: from the file name, and the level)")
    p.add_argument("--level", default=None,
                   help="the level to import, by name, id or index from the lowest (default: the lowest with rooms)")
    p.add_argument("-o", "--out", type=Path, default=None,
                   help="output folder (default: ~/.local/share/ravh_sim/houses, where names are looked up)")
    p.set_defaults(func=cmd_import_home)

    p = sub.add_parser("houses", help="list the houses with room and object counts")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.set_defaults(func=cmd_houses)

    p = sub.add_parser("plan", help="draw a top-down plan of a house")
    _world_args(p)
    p.add_argument("-o", "--output", type=Path, required=True, help="PNG file")
    p.add_argument("--free-space", action="store_true", help="overlay the robot's free area")
    p.add_argument("--path", type=float, nargs=4, metavar=("X0", "Y0", "X1", "Y1"),
                   help="overlay a planned path between two points")
    p.set_defaults(func=cmd_plan)

    p = sub.add_parser("map", help="write the house's obstacle map, as the sim's /map (ROS map_server PGM + YAML)")
    _world_args(p)
    p.add_argument("--doors", choices=(*DOOR, "default"), default=None,
                   help="every door's state (default: as the config says)")
    p.add_argument("--resolution", type=_positive, default=0.05, help="metres per cell (default 0.05)")
    p.add_argument("--profile", default=None, help="robot profile (default: the first agent's)")
    p.add_argument("--inflated", action="store_true",
                   help="write the robot's inflated free space instead (where its centre may go)")
    p.add_argument("-o", "--output", type=Path, required=True, help="folder for map.pgm and map.yaml")
    p.set_defaults(func=cmd_map)

    p = sub.add_parser("footprint", help="write the footprint (every object, id, mask colour, pose)")
    _world_args(p)
    p.add_argument("-o", "--output", type=Path, required=True, help="JSON file")
    p.set_defaults(func=cmd_footprint)

    p = sub.add_parser("query", help="ask the ground truth a JSON query (try '{\"query\": \"help\"}')")
    _world_args(p)
    p.add_argument("request", help='JSON request, e.g. \'{"query": "objects_in_room", "room": "Bedroom_1"}\'')
    p.set_defaults(func=cmd_query)

    p = sub.add_parser("render", help="render the robot camera's view: rgb, depth, mask and info.json")
    _world_args(p)
    p.add_argument("--pose", type=float, nargs=3, metavar=("X", "Y", "YAW"), default=None,
                   help="robot pose on the floor (m, m, rad; default: the robot's start)")
    p.add_argument("--sun", default=None, help="sun angle in degrees, or day, sunset, night (default: config)")
    p.add_argument("--lights", choices=SWITCH, default=None,
                   help="switch every light (default: config); random uses --seed")
    p.add_argument("--renderer", choices=BACKENDS, default="auto")
    p.add_argument("--profile", default=DEFAULT_PROFILE,
                   help=f"robot profile for the camera (default: {DEFAULT_PROFILE})")
    p.add_argument("--quality", choices=QUALITIES, default=None,
                   help="camera quality (default: the profile's); dataset: realistic shading of the furniture "
                        "library's finer models and textures")
    p.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("gallery", help="contact sheet of one view under the five raid presets and a random look")
    p.add_argument("house", help=HOUSE_HELP)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--pose", type=float, nargs=3, metavar=("X", "Y", "YAW"), default=None,
                   help="robot pose (default: the room-centre view with the most objects)")
    sheet = p.add_mutually_exclusive_group()
    sheet.add_argument("--objects", action="store_true",
                       help="instead: sofas, beds, tables, chairs, fridges, ovens, toilets... each from the front, "
                            "by day and at night")
    sheet.add_argument("--dressing", action="store_true",
                       help="instead: the view with no dressing beside lived-in, by day and at night")
    p.add_argument("--renderer", choices=BACKENDS, default="auto")
    p.add_argument("--quality", choices=QUALITY_PROFILES, default="realistic",
                   help="camera: realistic (default) or dataset (the library's finer models and textures)")
    p.add_argument("-o", "--output", type=Path, required=True, help="PNG file")
    p.set_defaults(func=cmd_gallery)

    p = sub.add_parser("raid", help="collect a dataset: sim + behaviour + recorder with a paper preset")
    p.add_argument("--house", default="15", help=HOUSE_HELP + " (default 15)")
    p.add_argument("--raid", type=int, default=1, choices=range(5),
                   help="0 grid/day, 1 wanderer/day, 2 random paint+models, 3 sunset, 4 night")
    p.add_argument("--out", type=Path, required=True, help="dataset folder (with --all: parent folder)")
    p.add_argument("--fast", action="store_true", help="run the sim faster than real time")
    p.add_argument("--all", action="store_true", help="every house")
    p.add_argument("--seed", type=int, default=None, help="default: house * 10 + raid")
    p.add_argument("--max-captures", type=int, default=0, help="stop after this many captures (0: no limit)")
    p.add_argument("--max-nodes", type=int, default=0, help="grid raids: visit only this many nodes (0: all)")
    p.add_argument("--quality", choices=QUALITY_PROFILES, default="realistic", help=RAID_QUALITY_HELP)
    p.set_defaults(func=cmd_raid)

    p = sub.add_parser("bench", help="measure speed; prints JSON with --json")
    p.add_argument("what", choices=BENCHES, help="what to measure")
    p.add_argument("--houses", nargs="*", default=None,
                   help="houses to measure, by number or imported home's name (default: all)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_bench)

    p = sub.add_parser("raid-summary", help="picture of a recorded dataset: trajectory on the plan, sample captures")
    p.add_argument("dataset", type=Path, help="dataset folder written by the recorder")
    p.add_argument("-o", "--output", type=Path, required=True, help="PNG file")
    p.set_defaults(func=cmd_raid_summary)

    add_dataset_parser(sub)
    from ravh_sim.eval.commands import register as register_eval
    register_eval(sub)
    return parser


if __name__ == "__main__":
    sys.exit(main())
