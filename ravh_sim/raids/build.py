"""``ravh dataset build``: the paper's raids for many houses into one folder, on one machine or many.

Every (house, raid) runs the paper's preset (:data:`ravh_sim.raids.raid.PRESETS`) into
``OUT/houseNN/raidK`` in the dataset format, with the direct engine (one process per raid, no DDS)
or the ROS engine (``ravh raid``'s three processes). Raids run on a local process pool, or as Ray
tasks on a cluster (``--ray ADDRESS``; ``pip install ravh_sim[ray]``) whose nodes share OUT.

The output folder is the only state: a raid whose raid.json says it finished with the parameters
asked for now (seed, preset, max captures and nodes, engine, camera quality, ravh_sim version: :func:`parameters`)
is skipped; one recorded with other parameters is named with what differs and run again, and any
other raid folder is an interrupted or failed run and is deleted before the raid runs again, so a
build can be stopped at any moment and resumed with the same command. Progress counts the lines of the
raids' captures.jsonl, so it covers every worker of a cluster with no messages between them.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import multiprocessing
import os
import re
import shutil
import statistics
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ravh_sim import __version__
from ravh_sim.dataset import layout
from ravh_sim.errors import UserError
from ravh_sim.paper import RAID_COLUMNS, TABLE2, table2
from ravh_sim.raids.outcome import Outcome
from ravh_sim.raids.raid import (
    PRESETS,
    QUALITY_PROFILES,
    RAID_QUALITY_HELP,
    preset_settings,
    quality_profile,
    run_raid,
)

ENGINES = ("direct", "ros")
POLL_S = 0.5
RAY_RETRIES = 2                         # a raid whose task fails is run again this many times


@dataclass(frozen=True, order=True)
class Job:
    house: int
    raid: int
    seed: int

    @property
    def name(self) -> str:
        return f"house{self.house:02d}/raid{self.raid}"


@dataclass(frozen=True)
class BuildOptions:
    engine: str = "direct"
    max_captures: int = 0               # per raid, 0: no limit (small test builds)
    max_nodes: int = 0                  # grid raids: only this many nodes, 0: all
    quality: str = "realistic"          # the camera's: a key of ravh_sim.raids.raid.QUALITY_PROFILES


def parse_numbers(text: str, valid: Iterable[int], what: str) -> list[int]:
    """'1-30', '20,29' or '0-2,4' as a sorted list; numbers outside ``valid`` are a UserError."""
    valid = set(valid)
    numbers: set[int] = set()
    for part in text.split(","):
        try:
            lo, _, hi = part.strip().partition("-")
            first, last = int(lo), int(hi or lo)
        except ValueError:
            raise UserError(f"--{what}: {text!r} is not a list of numbers or ranges like 1-30,32") from None
        numbers.update(range(first, last + 1))
    unknown = sorted(numbers - valid)
    if unknown or not numbers:
        raise UserError(f"--{what}: no such {what} {unknown or text}; valid: {min(valid)}-{max(valid)}")
    return sorted(numbers)


def parse_houses(text: str, what: str = "houses") -> list[int]:
    """--houses: numbers, ranges ('1-30') and imported homes' names ('studio'), comma-separated, as the
    sorted house numbers; an unknown number or name is a UserError listing the valid ones."""
    from ravh_sim.world.house import house_number, house_numbers
    parts = [part.strip() for part in text.split(",")]
    ranges = [part for part in parts if re.fullmatch(r"\d+\s*(-\s*\d+)?", part)]
    names = [part for part in parts if part and part not in ranges]
    numbers = set(parse_numbers(",".join(ranges), house_numbers(), what)) if ranges else set()
    numbers.update(house_number(name) for name in names)
    if not numbers:
        raise UserError(f"--{what}: {text!r} names no house; give numbers, ranges like 1-30 or imported homes' names")
    return sorted(numbers)


def raid_seed(house: int, raid: int, base: int | None) -> int:
    """The seed of one raid: ``ravh raid``'s default (house * 10 + raid), offset per base seed."""
    return house * 10 + raid + (0 if base is None else base * 1000)


def finished(folder: Path) -> dict[str, Any] | None:
    """The summary of a raid that ran to its end (or to the limit it was given), else None."""
    try:
        summary = json.loads((folder / layout.RAID_JSON).read_text())
    except (OSError, ValueError):
        return None
    try:
        return summary if Outcome.of(str(summary.get("status"))).complete else None
    except ValueError:
        return None


def parameters(job: Job, options: BuildOptions) -> dict[str, Any]:
    """What a raid of a build is recorded with (raid.json's ``build``): a finished raid is resumed
    only when these equal the request's. ``max_nodes`` counts for grid raids only."""
    preset = PRESETS[job.raid]
    return {"seed": job.seed, "preset": dict(preset.__dict__), "max_captures": options.max_captures,
            "max_nodes": options.max_nodes if preset.behaviour == "grid" else 0, "engine": options.engine,
            "quality": options.quality, "version": __version__}


PARAMETER_NAMES = {"seed": "seed", "preset": "preset", "max_captures": "max captures", "max_nodes": "max nodes",
                   "engine": "engine", "quality": "quality", "version": "ravh_sim version"}


def difference(summary: dict[str, Any], wanted: dict[str, Any]) -> str | None:
    """Why a finished raid is not the one asked for (None: it is), e.g. 'max captures 5, asked for 0'."""
    recorded = summary.get("build")
    if not isinstance(recorded, dict):
        return "recorded without its build parameters (an older ravh_sim)"
    differ = [f"{PARAMETER_NAMES[key]} {_shown(key, recorded.get(key))}, asked for {_shown(key, value)}"
              for key, value in wanted.items() if recorded.get(key) != value]
    return "; ".join(differ) or None


def _shown(key: str, value: Any) -> str:
    if value is None:
        return "(not recorded)"
    if key in ("max_captures", "max_nodes") and value == 0:
        return "0 (no limit)"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} {v}" for k, v in value.items()) + "}"
    return str(value)


def clear_unfinished(folder: Path) -> None:
    """Delete what an interrupted or failed run left, so the raid starts from an empty folder."""
    if folder.exists() and finished(folder) is None:
        shutil.rmtree(folder)


def run_job(job: Job, root: Path, options: BuildOptions) -> dict[str, Any]:
    """One raid into ``root/houseNN/raidK`` (in a worker process or a Ray task)."""
    out = root / job.name
    clear_unfinished(out)                    # a retried task finds its own earlier attempt
    preset = PRESETS[job.raid]
    recorded = {"build": parameters(job, options)}          # in raid.json: what a resume compares
    if options.engine == "ros":
        return run_raid(job.house, job.raid, out, fast=True, seed=job.seed, max_captures=options.max_captures,
                        max_nodes=options.max_nodes, quiet=True, meta=recorded, quality=options.quality)
    (out / "logs").mkdir(parents=True)
    with _output_to(out / "logs" / "direct.log"):
        from ravh_sim.raids.direct import GridSpec, WandererSpec, record
        spec = GridSpec(max_nodes=options.max_nodes) if preset.behaviour == "grid" else WandererSpec()
        return record(out, job.house, spec, settings=preset_settings(preset, job.seed, options.quality),
                      seed=job.seed, max_captures=options.max_captures,
                      raid={"raid": job.raid, "preset": preset.__dict__, **recorded})


@contextlib.contextmanager
def _output_to(log: Path) -> Iterator[None]:
    """Send this process's stdout and stderr (pybullet's C-level banners included) to ``log`` for
    the duration, so workers do not scribble over the progress bar."""
    sys.stdout.flush(), sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with open(log, "ab") as f:
        os.dup2(f.fileno(), 1), os.dup2(f.fileno(), 2)
        try:
            yield
        finally:
            sys.stdout.flush(), sys.stderr.flush()
            os.dup2(saved[0], 1), os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)


# ---------------------------------------------------------------------------- the build

def build(root: Path, houses: list[int], raids: list[int], workers: int = 1, engine: str = "direct",
          seed: int | None = None, ray_address: str | None = None, max_captures: int = 0,
          max_nodes: int = 0, show_progress: bool = True,
          on_redo: Callable[[str, str], None] | None = None, quality: str = "realistic") -> dict[str, Any]:
    """Run every (house, raid) not yet finished under ``root`` with these parameters; returns every
    raid's summary, the names of those that failed and of those redone because they had been
    recorded with other parameters (each also passed to ``on_redo(name, why)`` before anything runs)."""
    if engine not in ENGINES:
        raise UserError(f"--engine: unknown engine {engine!r}; valid: {', '.join(ENGINES)}")
    if workers < 1:
        raise UserError(f"--workers must be >= 1, got {workers}")
    quality_profile(quality)                  # an unknown quality fails here, before any raid runs
    root.mkdir(parents=True, exist_ok=True)
    jobs = [Job(h, r, raid_seed(h, r, seed)) for h in houses for r in raids]
    options = BuildOptions(engine, max_captures, max_nodes, quality)
    done: dict[Job, dict[str, Any]] = {}
    redone: dict[str, str] = {}
    for job in jobs:
        summary = finished(root / job.name)
        if summary is None:
            continue
        why = difference(summary, parameters(job, options))
        if why is None:
            done[job] = summary
        else:
            redone[job.name] = why
            if on_redo is not None:
                on_redo(job.name, why)
    todo = [job for job in jobs if job not in done]
    for job in todo:
        if job.name in redone:
            shutil.rmtree(root / job.name)
        clear_unfinished(root / job.name)
    progress = Progress(root, todo, show_progress)
    failed: dict[str, str] = {}

    def on_result(job: Job, summary: dict[str, Any] | None, error: str | None) -> None:
        if summary is not None and finished(root / job.name) is not None:
            done[job] = summary
        else:
            failed[job.name] = error or f"status: {summary.get('status') if summary else 'none'}"
        progress.raid_done(job, job.name not in failed)

    start = time.monotonic()
    try:
        runner = _run_on_ray if ray_address else _run_on_pool
        runner(todo, root, options, workers, ray_address, on_result, progress.poll)
    finally:
        progress.close()
    summaries = [done[j] for j in jobs if j in done]
    return {"raids": summaries, "skipped": len(jobs) - len(todo), "redone": redone, "failed": failed,
            "wall_s": round(time.monotonic() - start, 1)}


OnResult = Callable[[Job, "dict[str, Any] | None", "str | None"], None]


def _run_on_pool(todo: list[Job], root: Path, options: BuildOptions, workers: int, _address: str | None,
                 on_result: OnResult, poll: Callable[[], None]) -> None:
    """Local processes, a fresh one per raid (spawned: no pybullet or EGL state inherited)."""
    if not todo:
        return
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(min(workers, len(todo)), mp_context=context, max_tasks_per_child=1) as pool:
        running: dict[Future, Job] = {pool.submit(run_job, job, root, options): job for job in todo}
        try:
            while running:
                ready, _ = wait(running, timeout=POLL_S, return_when=FIRST_COMPLETED)
                for future in ready:
                    job = running.pop(future)
                    error = future.exception()
                    on_result(job, None if error else future.result(), _describe(error))
                poll()
        except BaseException:
            for future in running:
                future.cancel()
            raise


def _run_on_ray(todo: list[Job], root: Path, options: BuildOptions, _workers: int, address: str | None,
                on_result: OnResult, poll: Callable[[], None]) -> None:
    """One Ray task per raid (one CPU each), retried on failure; OUT must be shared by the nodes."""
    try:
        import ray
    except ImportError:
        raise UserError("--ray needs Ray: pip install 'ravh_sim[ray]'") from None
    if not todo:
        return
    ray.init(address=address, logging_level="warning", log_to_driver=False)
    try:
        # max_calls=1: a fresh worker process per raid, as on the local pool (pybullet and EGL state
        # of one raid never meets the next; in a process that started Ray, only its first World
        # renders bit-exactly the images a fresh process does)
        task = ray.remote(num_cpus=1, max_retries=RAY_RETRIES, retry_exceptions=True,
                          max_calls=1)(_run_job_on_ray)
        running = {task.remote(job, root, options): job for job in todo}
        try:
            while running:
                ready, _ = ray.wait(list(running), num_returns=1, timeout=POLL_S)
                for ref in ready:
                    job = running.pop(ref)
                    try:
                        on_result(job, ray.get(ref), None)
                    except ray.exceptions.RayError as e:
                        on_result(job, None, _describe(e))
                poll()
        except BaseException:
            for ref in running:                  # no task left writing into OUT after we stop
                ray.cancel(ref, force=True)
            raise
    finally:
        ray.shutdown()


def _run_job_on_ray(job: Job, root: Path, options: BuildOptions) -> dict[str, Any]:
    """:func:`run_job`, its summary naming the Ray node that ran it."""
    import ray
    return {**run_job(job, root, options), "ray_node": ray.get_runtime_context().get_node_id()}


def _describe(error: BaseException | None) -> str | None:
    """One line for a raid's failure; a write error (a full disk) names the file, as ``ravh`` does."""
    if error is None:
        return None
    if isinstance(error, OSError) and error.strerror:
        return f"{error.filename}: {error.strerror}" if error.filename else f"{error.strerror} (errno {error.errno})"
    return f"{type(error).__name__}: {str(error).strip().splitlines()[-1] if str(error).strip() else ''}"


class Progress:
    """A tqdm bar over the raids to run, with the captures written so far (read from the raids'
    captures.jsonl, wherever the worker runs), captures per second and tqdm's ETA. A raid that fails
    does not advance the bar: it is counted as failed beside it, and the bar turns red."""

    def __init__(self, root: Path, todo: list[Job], show: bool) -> None:
        from tqdm import tqdm
        self.root, self.open = root, set(todo)
        self.closed_captures = 0
        self.failed = 0
        self.start = time.monotonic()
        self.bar = tqdm(total=len(todo), unit="raid", disable=not show, file=sys.stderr,
                        dynamic_ncols=True, smoothing=0.1)

    def captures(self) -> int:
        return self.closed_captures + sum(_lines(self.root / job.name / layout.CAPTURES_JSONL)
                                          for job in self.open)

    def poll(self) -> None:
        captures = self.captures()
        rate = captures / max(time.monotonic() - self.start, 1e-9)
        failed = f", {self.failed} raid{'s' if self.failed > 1 else ''} FAILED" if self.failed else ""
        self.bar.set_postfix_str(f"{captures} captures, {rate:.1f} captures/s{failed}", refresh=True)

    def raid_done(self, job: Job, ok: bool = True) -> None:
        self.open.discard(job)
        self.closed_captures += _lines(self.root / job.name / layout.CAPTURES_JSONL)
        if ok:
            self.bar.update(1)
        else:
            self.failed += 1
            self.bar.colour = "red"
            self.poll()

    def close(self) -> None:
        self.poll()
        self.bar.close()


def _lines(path: Path) -> int:
    try:
        with open(path, "rb") as f:
            return f.read().count(b"\n")
    except OSError:
        return 0


# ---------------------------------------------------------------------------- the report

def summary_table(result: dict[str, Any], paper: dict[int, dict[int, int]] | None = None) -> str:
    """Captures per house and raid beside the paper's Table 2 (ours / paper = ratio), then per raid
    preset: totals, and the median and range of the per-house ratios."""
    paper = table2() if paper is None else paper
    ours = {(int(s["house"]), int(s["raid"])): int(s["captures"]) for s in result["raids"]}
    raids = sorted({raid for _, raid in ours})
    cell = 20
    lines = [f"{'house':<6}" + "".join(f"{f'raid {r} ({RAID_COLUMNS[r]})':>{cell}}" for r in raids)]
    for house in sorted({h for h, _ in ours}):
        row = f"{house:<6}"
        for raid in raids:
            n, theirs = ours.get((house, raid)), paper.get(house, {}).get(raid)
            text = "-" if n is None else f"{n}" if not theirs else f"{n}/{theirs} {n / theirs:.2f}"
            row += f"{text:>{cell}}"
        lines.append(row)
    lines.append("")
    lines.append(f"{'raid':<5}{'preset':<40}{'raids':>6}{'captures':>10}{'paper':>9}{'ratio median (range)':>24}")
    for raid in raids:
        p = PRESETS[raid]
        preset = (f"{p.behaviour}, sun {p.sun}, ceiling {p.ceiling}, lamps {p.lamps}"
                  + (", random look" if p.paint == "random" else ""))
        houses = [h for h, r in ours if r == raid]
        total = sum(ours[h, raid] for h in houses)
        compared = [h for h in houses if paper.get(h, {}).get(raid)]
        ratios = sorted(ours[h, raid] / paper[h][raid] for h in compared)
        paper_total = sum(paper[h][raid] for h in compared)
        spread = (f"{statistics.median(ratios):.2f} ({ratios[0]:.2f}-{ratios[-1]:.2f})" if ratios else "-")
        lines.append(f"{raid:<5}{preset:<40}{len(houses):>6}{total:>10}{paper_total:>9}{spread:>24}")
    lines.append(f"paper: Table 2 ({TABLE2.name}), raid 0 = its grid column, raids 1-4 = W1-W4")
    return "\n".join(lines)


# ---------------------------------------------------------------------------- the command

def add_parser(sub: argparse._SubParsersAction) -> None:
    """``ravh dataset build ...`` (registered by ravh_sim.cli)."""
    dataset = sub.add_parser("dataset", help="build the paper's dataset: many houses and raids at once")
    commands = dataset.add_subparsers(metavar="COMMAND")
    p = commands.add_parser("build", help="every (house, raid) into OUT/houseNN/raidK; resumable")
    p.add_argument("--houses", default="1-30",
                   help="houses, e.g. 1-30, 20,29, or with imported homes' names: 1-3,studio (default 1-30)")
    p.add_argument("--raids", default="0-4", help="paper presets 0-4 (default all): 0 grid/day, 1 wanderer/day, "
                   "2 random paint+models, 3 sunset, 4 night")
    p.add_argument("--out", type=Path, required=True, help="dataset folder (shared by the nodes with --ray)")
    p.add_argument("--workers", type=int, default=1,
                   help="raids at once on this machine (default 1; with --ray, Ray gives each raid a CPU)")
    p.add_argument("--engine", choices=ENGINES, default="direct",
                   help="direct: one process, no DDS (default); ros: sim, behaviour and recorder nodes")
    p.add_argument("--seed", type=int, default=None,
                   help="base seed (default: each raid's seed is house * 10 + raid, as ravh raid's)")
    p.add_argument("--ray", metavar="ADDRESS", default=None,
                   help="run the raids as tasks on this Ray cluster ('auto': the local one)")
    p.add_argument("--max-captures", type=int, default=0, help="stop each raid after N captures (0: no limit)")
    p.add_argument("--max-nodes", type=int, default=0, help="grid raids: visit only N nodes (0: all)")
    p.add_argument("--quality", choices=QUALITY_PROFILES, default="realistic", help=RAID_QUALITY_HELP)
    p.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
    p.set_defaults(func=cmd_build)
    e = commands.add_parser("export", help="datasets under DIR in a detector-training format (COCO)")
    e.add_argument("dir", type=Path, metavar="DIR", help="a dataset folder, or a build's OUT with many")
    e.add_argument("--format", choices=("coco",), required=True,
                   help="coco: instances.json (boxes, RLE masks, categories) + semantic/ class images")
    e.add_argument("--out", type=Path, default=None, help="where instances.json goes (default DIR/coco)")
    e.add_argument("--min-pixels", type=int, default=1, help="annotate objects covering at least N pixels")
    e.set_defaults(func=cmd_export)
    dataset.set_defaults(func=lambda args: dataset.print_help() or 2)


def cmd_export(args: argparse.Namespace) -> int:
    from ravh_sim.dataset.coco import INSTANCES_JSON, export_coco
    out = args.out or args.dir / "coco"
    counts = export_coco(args.dir, out, args.min_pixels)
    print(f"{counts['images']} images, {counts['annotations']} annotations from {counts['datasets']} datasets: "
          f"{out / INSTANCES_JSON} (semantic class images in each dataset's semantic/)")
    return 0


def cmd_build(args: argparse.Namespace) -> int:
    houses = parse_houses(args.houses)
    raids = parse_numbers(args.raids, range(len(PRESETS)), "raids")

    def say_redo(name: str, why: str) -> None:
        print(f"ravh: raid {name} was recorded with other parameters, redoing it: {why}", file=sys.stderr)

    result = build(args.out, houses, raids, args.workers, args.engine, args.seed, args.ray,
                   args.max_captures, args.max_nodes, args.progress, say_redo, args.quality)
    print(summary_table(result))
    redone = f", {len(result['redone'])} redone with other parameters" if result["redone"] else ""
    print(f"{len(result['raids'])} raids in {args.out} ({result['skipped']} already there{redone}), "
          f"{result['wall_s']:.0f} s")
    for name, why in sorted(result["failed"].items()):
        print(f"ravh: raid {name} failed: {why} (see {args.out / name})", file=sys.stderr)
    return 1 if result["failed"] else 0
