"""``ravh``: the command-line tool for everything that is not a ROS node.

Each subcommand is a thin shell over the library: parse flags, call one function, print or write the
result. User mistakes (bad house number, malformed file, bad JSON) end with one ``ravh: error:`` line
and exit status 2, never a traceback.
"""
from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path
from typing import Callable

from ravh_sim.errors import UserError
from ravh_sim.paths import HOUSES_DIR

Command = Callable[[argparse.Namespace], int]


def main(argv: list[str] | None = None) -> int:
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


# ---------------------------------------------------------------------------- helpers

def _world_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("house", type=int, help="house number (1..30)")
    p.add_argument("--seed", type=int, default=None, help="seed for every random choice (default: config)")
    p.add_argument("--config", type=Path, default=None, help="settings YAML (see config/default.yaml)")


def _resolved(args: argparse.Namespace):
    from ravh_sim.world.house import load_house
    from ravh_sim.world.settings import load_settings, resolve
    house = load_house(args.house)
    settings = load_settings(args.config)
    return house, resolve(settings, house, args.seed, str(args.config or "config/default.yaml"))


def _print_json(data: object) -> None:
    print(json.dumps(data, indent=2))


# ---------------------------------------------------------------------------- houses (issue: houses)

def cmd_import_houses(args: argparse.Namespace) -> int:
    from ravh_sim.world.importer import import_houses
    written = import_houses(args.src, args.out)
    print(f"imported {len(written)} houses into {args.out}")
    return 0


def cmd_houses(args: argparse.Namespace) -> int:
    from ravh_sim.world.house import available_houses, load_house
    rows = []
    for n in available_houses():
        h = load_house(n)
        rows.append({"house": n, "rooms": len(h.rooms), "objects": len(h.objects),
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
        free = free_space(house, resolved.doors, resolved.models)
        if args.path:
            x0, y0, x1, y1 = args.path
            closed = [d for d, is_open in resolved.doors.items() if not is_open]
            path = plan_path(free, (x0, y0), (x1, y1), house=house, blocked_by=closed).points
    image = draw_plan(house, door_open=resolved.doors, models=resolved.models,
                      free_space=free if args.free_space else None, path=path)
    write_plan(args.output, image)
    print(f"wrote {args.output}")
    return 0


def cmd_footprint(args: argparse.Namespace) -> int:
    from ravh_sim.world.footprint import make_footprint, write_footprint
    house, resolved = _resolved(args)
    write_footprint(make_footprint(house, resolved), args.output)
    print(f"wrote {args.output}")
    return 0


def cmd_query(args: argparse.Namespace) -> int:
    from ravh_sim.world.ground_truth import GroundTruth
    house, resolved = _resolved(args)
    reply = GroundTruth(house, resolved).answer(args.request)
    _print_json(reply)
    return 0 if reply["ok"] else 1


def cmd_bench(args: argparse.Namespace) -> int:
    from ravh_sim import bench
    result = bench.run(args.what, houses=args.houses)
    if args.json:
        print(json.dumps(result, indent=1))
    else:
        for key, value in result.items():
            print(f"{key}: {value}")
    return 0


# ---------------------------------------------------------------------------- parser

def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ravh", description="Robot@VirtualHome for ROS 2: tools.")
    sub = parser.add_subparsers(metavar="COMMAND")

    p = sub.add_parser("import-houses", help="convert upstream house facts into houses/")
    p.add_argument("src", type=Path, help="folder with the upstream houseNN.json files")
    p.add_argument("-o", "--out", type=Path, default=HOUSES_DIR, help="output folder (default: houses/)")
    p.set_defaults(func=cmd_import_houses)

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

    p = sub.add_parser("footprint", help="write the footprint (every object, id, mask colour, pose)")
    _world_args(p)
    p.add_argument("-o", "--output", type=Path, required=True, help="JSON file")
    p.set_defaults(func=cmd_footprint)

    p = sub.add_parser("query", help="ask the ground truth a JSON query (try '{\"query\": \"help\"}')")
    _world_args(p)
    p.add_argument("request", help='JSON request, e.g. \'{"query": "objects_in_room", "room": "Bedroom_1"}\'')
    p.set_defaults(func=cmd_query)

    p = sub.add_parser("bench", help="measure speed; prints JSON with --json")
    p.add_argument("what", choices=("load",), help="what to measure")
    p.add_argument("--houses", type=int, nargs="*", default=None, help="houses to measure (default: all)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_bench)
    return parser


if __name__ == "__main__":
    sys.exit(main())
