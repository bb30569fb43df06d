"""``ravh raid``: the paper's data collection, run as three ROS processes (sim, behaviour, recorder).

A raid is one house under one appearance preset, explored by one behaviour while the recorder writes
the dataset. The presets are the paper's five; each becomes a settings file (saved in the output folder,
so the raid can be rerun) passed to the sim node. A raid runs on the user's ROS_DOMAIN_ID when one is
set, else on one of its own so raids on one machine never hear each other (it says which). Processes
are stopped with SIGINT in the order that loses nothing: behaviour done -> recorder (once it has every
capture the behaviour was given, or has given up) -> sim.

Raids are reproducible: sim and behaviour run in lockstep (sim time advances only as the behaviour
grants it), so the same seed gives the same captures, poses and images. Nothing is lost silently: the
behaviour runs with ``--wait-recorder`` (a capture counts once the
recorder confirms it), and the status is ``done`` only when the behaviour finished, every process
exited cleanly and the dataset holds every capture the behaviour logged. The output folder must be new
or empty; raid.json is written atomically, also after Ctrl-C, and says what happened.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path

import yaml
from tqdm import tqdm

from ravh_msgs_py.names import DEFAULT_AGENT, DEFAULT_PROFILE
from ravh_sim.dataset import layout
from ravh_sim.errors import UserError
from ravh_sim.nodes.common import ros_domain_id
from ravh_sim.raids.outcome import LOSS_SEPARATOR, Outcome
from ravh_sim.world.house import load_house
from ravh_sim.world.settings import check_seed

FAST_RTF = 4.0                   # --fast: sim seconds per wall second asked of the sim node
POLL_S = 0.5
RECORDER_START_S = 120.0         # the recorder is ready once the sim's footprint reached it
DISCOVERY_S = 2.0
HANDOVER_GRACE_S = 30.0          # wall seconds the recorder gets to store the behaviour's last captures
# a raid's camera quality -> the robot profile that has it (config/robots/): the live level, or the
# furniture library's finer models and textures for datasets (ravh_sim.world.library DETAILS)
QUALITY_PROFILES = {"realistic": DEFAULT_PROFILE, "dataset": "giraff_dataset"}
RAID_QUALITY_HELP = ("camera: realistic (the live level, default) or dataset (the furniture library's finer "
                     "models and textures: slower, sharper)")


@dataclass(frozen=True)
class RaidPreset:
    behaviour: str               # grid | wanderer
    sun: str                     # day | sunset | night
    lamps: str                   # on | off | random
    ceiling: str
    paint: str                   # default | random
    models: str                  # default | random


PRESETS = (
    RaidPreset("grid", "day", "off", "on", "default", "default"),
    RaidPreset("wanderer", "day", "off", "on", "default", "default"),
    RaidPreset("wanderer", "day", "off", "off", "random", "random"),
    RaidPreset("wanderer", "sunset", "random", "off", "random", "random"),
    RaidPreset("wanderer", "night", "random", "on", "random", "random"),
)


def preset_settings(preset: RaidPreset, seed: int, quality: str = "realistic") -> dict:
    """The settings file of a raid preset (keys as in config/default.yaml); ``quality`` (a key of
    QUALITY_PROFILES) picks the robot profile, so the footprint records which camera made the raid."""
    return {"seed": seed,
            "lights": {"sun_angle": preset.sun, "ceiling": preset.ceiling, "lamps": preset.lamps},
            "paint": {"walls": preset.paint, "floors": preset.paint},
            "models": {"all": preset.models},
            "dressing": "none",          # the paper's raids: the paper's objects, nothing else
            "agents": [{"name": DEFAULT_AGENT, "profile": quality_profile(quality)}]}


def quality_profile(quality: str) -> str:
    """The robot profile of a raid's camera quality (QUALITY_PROFILES); an unknown one is a UserError."""
    if quality not in QUALITY_PROFILES:
        raise UserError(f"unknown raid quality {quality!r}; valid: {', '.join(QUALITY_PROFILES)}")
    return QUALITY_PROFILES[quality]


def run_raid(house: int | str, raid: int, out: Path, fast: bool = False, seed: int | None = None,
             max_captures: int = 0, max_nodes: int = 0, timeout: float = 3600.0, quiet: bool = False,
             meta: dict | None = None, quality: str = "realistic") -> dict:
    """Run one raid into the new folder ``out``; returns its summary (also written to ``out/raid.json``).
    ``meta``: more keys for dataset.json's ``raid`` and the summary (a build's parameters); ``quality``:
    the camera's (QUALITY_PROFILES)."""
    if not 0 <= raid < len(PRESETS):
        raise UserError(f"unknown raid {raid}; valid: {', '.join(map(str, range(len(PRESETS))))}")
    preset = PRESETS[raid]
    home = load_house(house)                  # by number, name or path (the sim is given the same words)
    number = home.number
    seed = check_seed(number * 10 + raid if seed is None else seed)
    settings = preset_settings(preset, seed, quality)
    logs = out / "logs"
    settings_path = out / "raid_settings.yaml"
    with _writing(out):
        if out.exists() and (not out.is_dir() or any(out.iterdir())):
            raise UserError(f"{out} exists and is not empty; raid into a new folder")
        logs.mkdir(parents=True)
        layout.atomic_write(settings_path, yaml.safe_dump(settings, sort_keys=False).encode())
    domain, how = ros_domain_id(os.getpid() * 7 + number * 5 + raid)
    if not quiet:
        print(f"ravh raid: ROS_DOMAIN_ID {domain} ({how})", file=sys.stderr)
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE=os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE",
                                                                          "LOCALHOST"), ROS_DOMAIN_ID=domain)
    rtf = FAST_RTF if fast else 1.0
    behaviour_args = (["--order", "once", "--capture-period", "0.5"] if preset.behaviour == "wanderer"
                      else ["--captures", "10", "--max-nodes", str(max_nodes)])
    start = time.monotonic()
    imported = {"house_name": home.name, "attribution": home.attribution} if home.name else {}
    raid_meta = {"house": number, **imported, "raid": raid, "preset": preset.__dict__, "seed": seed,
                 "quality": quality, "fast": fast,
                 "ros_domain_id": domain, **(meta or {})}
    captures, given = out / layout.CAPTURES_JSONL, logs / "behaviour_captures.jsonl"
    status = Outcome.DONE.status()
    sim = recorder = behaviour = None
    wind_down = ExitStack()
    progress = tqdm(total=max_captures or None, unit="capture", desc=f"{home.title} raid {raid}",
                    disable=quiet, file=sys.stderr, leave=True)
    with wind_down, progress:
        try:
            sim = _spawn(["sim", "--house", str(house), "--config", str(settings_path), "--rtf", str(rtf),
                          "--camera-rate", "0", "--lockstep"], env, logs / "sim.log")
            recorder = _spawn(["recorder", "--out", str(out), "--raid", json.dumps(raid_meta)], env,
                              logs / "recorder.log")
            _wait_for(lambda: (out / layout.DATASET_JSON).exists() or sim.poll() is not None
                      or recorder.poll() is not None, RECORDER_START_S)
            time.sleep(DISCOVERY_S)                  # let the recorder's capture subscriptions match
            behaviour = _spawn([preset.behaviour, "--log", str(given), "--wait-recorder", "--lockstep",
                                *behaviour_args],
                               env, logs / "behaviour.log")
            while behaviour.poll() is None:
                rows = _rows(captures)
                progress.update(len(rows) - progress.n)
                progress.set_postfix(rooms=len({r.get("room") for r in rows if r.get("room")}), refresh=False)
                stopped = [(name, proc) for name, proc in (("sim", sim), ("recorder", recorder))
                           if proc.poll() is not None]
                if stopped:
                    name, proc = stopped[0]
                    status = Outcome.PROCESS_STOPPED.status(name=name, code=proc.returncode)
                    break
                if max_captures and len(rows) >= max_captures:
                    status = Outcome.STOPPED.status(captures=max_captures)
                    break
                if time.monotonic() - start > timeout:
                    status = Outcome.TIMED_OUT.status(limit=f"{timeout:.0f} s")
                    break
                time.sleep(POLL_S)
        except KeyboardInterrupt:
            status = Outcome.INTERRUPTED.status()
        finally:
            wind_down.enter_context(_ctrl_c_ignored())       # a second Ctrl-C must not lose raid.json
            _stop(behaviour)
            if recorder is not None:
                _wait_for(lambda: len(_rows(captures)) >= len(_rows(given)) or recorder.poll() is not None,
                          HANDOVER_GRACE_S)
            _stop(recorder)
            _stop(sim)
        rows, requested = _stored(out), len(_rows(given))
        status = _final_status(status, requested, len(rows), behaviour, recorder)
        summary = {**raid_meta, "status": status, "captures": len(rows), "requested": requested,
                   "rooms_visited": sorted({r["room"] for r in rows if r.get("room")}),
                   "wall_s": round(time.monotonic() - start, 1),
                   "sim_s": round(rows[-1]["stamp"] - rows[0]["stamp"], 1) if len(rows) > 1 else 0.0}
        with _writing(out, f"; the raid ended: {status}"):
            layout.atomic_write(out / layout.RAID_JSON, (json.dumps(summary, indent=1) + "\n").encode())
    return summary


def _final_status(status: str, requested: int, recorded: int, behaviour: subprocess.Popen | None,
                  recorder: subprocess.Popen | None) -> str:
    """What the raid amounts to: losses first, then a process that failed, then how it ended."""
    outcome = Outcome.of(status)
    if recorded < requested:
        lost = Outcome.LOST.status(lost=requested - recorded, requested=requested)
        return status + LOSS_SEPARATOR + lost if outcome is Outcome.INTERRUPTED else lost
    if outcome is Outcome.DONE:
        for name, proc in (("behaviour", behaviour), ("recorder", recorder)):
            if proc is not None and proc.returncode not in (0, None):
                return Outcome.PROCESS_FAILED.status(name=name, code=proc.returncode)
    return status


@contextmanager
def _ctrl_c_ignored():
    """Ignore SIGINT while a raid winds down (stopping its processes, writing raid.json): a second Ctrl-C
    would otherwise lose the summary. The processes, in the terminal's process group, still get it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextmanager
def _writing(out: Path, context: str = ""):
    """OSErrors while writing the raid folder become one line naming the file."""
    try:
        yield
    except OSError as e:
        raise UserError(f"{e.filename or out}: cannot write the raid: {e.strerror}{context}") from None


def _wait_for(condition, timeout: float) -> None:
    end = time.monotonic() + timeout
    while not condition() and time.monotonic() < end:
        time.sleep(0.2)


def _spawn(args: list[str], env: dict[str, str], log: Path) -> subprocess.Popen:
    with open(log, "w") as f:
        return subprocess.Popen([sys.executable, "-m", "ravh_sim.cli", *args], env=env, stdout=f,
                                stderr=subprocess.STDOUT)


def _stop(proc: subprocess.Popen | None, timeout: float = 30.0) -> None:
    if proc is not None and proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def _stored(out: Path) -> list[dict]:
    """The rows of the dataset whose files are all on disk: what raid.json counts as recorded."""
    return [row for row in _rows(out / layout.CAPTURES_JSONL)
            if all((out / rel).is_file() for rel in row.get("files", {}).values())]


def _rows(path: Path) -> list[dict]:
    if not path.exists():
        return []
    rows = []
    for line in path.read_text().splitlines():
        try:
            rows.append(json.loads(line))
        except ValueError:
            break                                   # a line being written right now
    return rows
