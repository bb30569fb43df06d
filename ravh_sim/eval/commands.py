"""``ravh semantic-map`` and ``ravh eval ...``: parsers and thin shells over the eval modules."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ravh_sim.paper import TABLE3, TABLE4


def register(sub: argparse._SubParsersAction) -> None:
    """Add the evaluation commands to ``ravh``'s subcommands."""
    p = sub.add_parser("semantic-map", help="build a semantic map (JSON boxes) of a dataset with a reference mapper")
    p.add_argument("--dataset", type=Path, required=True, help="dataset folder")
    p.add_argument("--mapper", choices=("oracle", "degraded"), default="oracle",
                   help="oracle: true masks; degraded: with seeded detector errors (default oracle)")
    p.add_argument("--seed", type=int, default=0, help="seed of the degraded mapper's errors")
    p.add_argument("-o", "--output", type=Path, required=True, help="semantic-map JSON file")
    p.set_defaults(func=cmd_semantic_map)

    evaluation = sub.add_parser("eval", help="the paper's benchmarks: semantic maps (Table 3), localization (Table 4)")
    which = evaluation.add_subparsers(metavar="BENCHMARK")
    p = which.add_parser("semantic-map", help="precision/recall of semantic maps against the ground truth")
    p.add_argument("--dataset", type=Path, nargs="+", default=[], help="dataset folders (one per house)")
    p.add_argument("--map", type=Path, nargs="+", default=[], help="semantic-map files, one per dataset")
    p.add_argument("--paper", type=Path, nargs="?", const=TABLE3, default=None, metavar="TSV",
                   help="set the paper's Table 3 row beside each house (default TSV: config/paper/)")
    p.add_argument("--paper-protocol", action="store_true",
                   help="record one wanderer raid with a random appearance per house (--houses) into --out, "
                        "map it with --mappers and print Table 3's columns beside the paper's")
    p.add_argument("--houses", default="1-30",
                   help="--paper-protocol: houses, e.g. 1-30, 20,29 or an imported home's name")
    p.add_argument("--mappers", default="oracle,degraded", help="--paper-protocol: oracle, degraded or both")
    p.add_argument("--seed", type=int, default=0, help="--paper-protocol: seed of the raids and the degraded mapper")
    p.add_argument("--iou", type=float, default=None,
                   help="overlap threshold (intersection / smaller volume; default 0.5)")
    p.add_argument("--out", type=Path, default=None, help="folder for table3.json/.txt and the plan pictures")
    p.add_argument("--json", action="store_true", help="print JSON instead of the text table")
    p.set_defaults(func=cmd_eval_semantic_map)

    p = which.add_parser("localization", help="appearance-based localization errors, routes x maps (Table 4)")
    p.add_argument("--house", default="15", help="house: number or imported home's name (default 15)")
    p.add_argument("--out", type=Path, required=True,
                   help="folder for the recordings (reused when present), table4.json/.txt/.png")
    p.add_argument("--quick", action="store_true", help="CI-sized: 2 short routes, 2 maps of the grid nodes along them")
    p.add_argument("--descriptor", default=None,
                   help="gradient_grid (the default baseline), constant (sees nothing: odometry alone) or "
                        "'module:function' (RGB image -> vector)")
    p.add_argument("--seed", type=int, default=0, help="seed of the recordings and the odometry noise")
    p.add_argument("--night-lights", choices=("evening", "all"), default="evening",
                   help="night recordings: evening (default: each its own fair coin per light, as a home on "
                        "different evenings) or all (every ceiling light on)")
    p.add_argument("--paper", type=Path, default=TABLE4, metavar="TSV",
                   help="the paper's Table 4 to set beside ours (default: config/paper/table4_localization.tsv)")
    p.add_argument("--json", action="store_true", help="print table4.json (ours, the paper's, ratios) instead of "
                                                       "the text table")
    p.set_defaults(func=cmd_eval_localization)


def cmd_semantic_map(args: argparse.Namespace) -> int:
    from ravh_sim.dataset.api import Dataset
    from ravh_sim.eval.mappers import run_mapper
    from ravh_sim.eval.semantic_map import write_map
    semantic_map = run_mapper(Dataset(args.dataset), args.mapper, args.seed)
    write_map(semantic_map, args.output)
    print(f"wrote {args.output} ({len(semantic_map.boxes)} boxes)")
    return 0


def cmd_eval_semantic_map(args: argparse.Namespace) -> int:
    from ravh_sim.errors import UserError
    from ravh_sim.eval.semantic_eval import DEFAULT_THRESHOLD, evaluate_datasets, format_beside_paper, format_table
    from ravh_sim.paper import read_tsv
    threshold = DEFAULT_THRESHOLD if args.iou is None else args.iou
    if not 0.0 < threshold <= 1.0:
        raise UserError(f"--iou must be in (0, 1], got {threshold}")
    if args.paper_protocol:
        return _paper_protocol(args, threshold, args.paper or TABLE3)
    if not args.dataset or len(args.dataset) != len(args.map):
        raise UserError(f"give one --map per --dataset ({len(args.dataset)} datasets, {len(args.map)} maps), "
                        "or --paper-protocol")
    doc = evaluate_datasets(list(zip(args.dataset, args.map)), threshold, args.out)
    text = format_table(doc)
    if args.paper is not None:
        text += "\n\n" + format_beside_paper(doc, {int(r["house"]): r for r in read_tsv(args.paper)})
    if args.out is not None:
        (args.out / "table3.json").write_text(json.dumps(doc, indent=1) + "\n")
        (args.out / "table3.txt").write_text(text + "\n")
    print(json.dumps(doc, indent=1) if args.json else text)
    return 0


def _paper_protocol(args: argparse.Namespace, threshold: float, paper_path: Path) -> int:
    from ravh_sim.errors import UserError
    from ravh_sim.eval.mappers import MAPPERS
    from ravh_sim.eval.table3 import run_protocol
    from ravh_sim.raids.build import parse_houses
    if args.out is None:
        raise UserError("--paper-protocol needs --out (the raids are recorded there and reused)")
    houses = parse_houses(args.houses)
    mappers = [m.strip() for m in args.mappers.split(",") if m.strip()]
    if not mappers or set(mappers) - set(MAPPERS):
        raise UserError(f"--mappers: {args.mappers!r}; valid: {', '.join(MAPPERS)}")
    run_protocol(houses, args.out, mappers, args.seed, threshold, paper_path,
                 progress=lambda text: print(text, file=sys.stderr, flush=True))
    print((args.out / "table3_paper.txt").read_text(), end="")
    return 0


def cmd_eval_localization(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from ravh_sim.errors import UserError
    from ravh_sim.eval.table4 import FULL, QUICK, format_table4, run_table4
    from ravh_sim.paper import table4
    from ravh_sim.world.house import house_number
    house = house_number(args.house)                  # by number or name; unknown: the usual clear error
    protocol = replace(QUICK if args.quick else FULL, night_lights=args.night_lights)
    if not args.paper.is_file():
        raise UserError(f"--paper: no such file {args.paper}")
    try:                                              # a bad table fails now, not after the recordings
        table4(args.paper)
    except (KeyError, ValueError) as e:
        raise UserError(f"--paper {args.paper}: not Table 4's columns (config/paper/README.md): {e}") from None
    doc = run_table4(house, args.out, protocol, args.descriptor, args.seed,
                     progress=lambda text: print(text, file=sys.stderr, flush=True), paper=args.paper)
    if args.json:
        print(json.dumps(doc, indent=1))
    else:
        print(format_table4(doc))
        print(f"wrote {args.out / 'table4.json'}, table4.txt and table4.png")
    return 0
