"""The ravh tool: outputs for people and scripts, and one clear line (no traceback) for user mistakes."""
from __future__ import annotations

import json
import subprocess
import sys

import cv2
import pytest
from conftest import subprocess_env

from ravh_sim.cli import main


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_houses_json_counts(capsys, houses):
    code, out, _ = run_cli(capsys, "houses", "--json")
    rows = json.loads(out)
    assert code == 0 and len(rows) == 30
    assert sum(r["rooms"] for r in rows) == 239 and sum(r["objects"] for r in rows) == 3108
    row15 = next(r for r in rows if r["house"] == 15)
    assert row15["rooms_by_type"] == {"Bathroom": 2, "Bedroom": 2, "Corridor": 1, "KitchenLivingRoom": 1}
    assert sum(row15["objects_by_type"].values()) == len(houses[15].objects)


def test_houses_table(capsys):
    code, out, _ = run_cli(capsys, "houses")
    assert code == 0 and out.splitlines()[-1].split()[:3] == ["all", "239", "3108"]


def test_footprint_same_seed_byte_identical(capsys, tmp_path):
    a, b, c = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "c.json"
    for path, seed in ((a, "4"), (b, "4"), (c, "5")):
        assert run_cli(capsys, "footprint", "20", "--seed", seed, "-o", str(path))[0] == 0
    assert a.read_bytes() == b.read_bytes()
    assert json.loads(a.read_text())["settings"]["seed"] == 4 and a.read_bytes() != c.read_bytes()


def test_query_answers_and_fails_cleanly(capsys):
    code, out, _ = run_cli(capsys, "query", "20", '{"query": "rooms"}')
    assert code == 0 and len(json.loads(out)["result"]) == 3
    code, out, _ = run_cli(capsys, "query", "20", '{"query": "object", "id": "Nope_1"}')
    reply = json.loads(out)
    assert code == 1 and reply["error"]["code"] == "unknown_id" and reply["error"]["valid"]


def test_plan_writes_a_picture(capsys, tmp_path):
    out = tmp_path / "plan.png"
    assert run_cli(capsys, "plan", "20", "-o", str(out), "--free-space")[0] == 0
    image = cv2.imread(str(out))
    assert image is not None and image.shape[0] > 300 and image.shape[1] > 300


@pytest.mark.parametrize("argv, needle", [
    (["plan", "31", "-o", "x.png"], "unknown house 31; valid: 1, 2, 3"),
    (["footprint", "15", "--config", "/nonexistent.yaml", "-o", "x.json"], "/nonexistent.yaml"),
])
def test_user_errors_are_one_line_without_traceback(argv, needle, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "ravh_sim.cli", *argv], capture_output=True, text=True,
                          cwd=tmp_path, env=subprocess_env(), timeout=120)
    assert proc.returncode == 2
    assert needle in proc.stderr and "Traceback" not in proc.stderr
    assert proc.stderr.strip().count("\n") == 0


def test_bad_config_field_is_named(capsys, tmp_path):
    cfg = tmp_path / "bad.yaml"
    cfg.write_text("doors:\n  all: ajar\n")
    code, _, err = run_cli(capsys, "footprint", "15", "--config", str(cfg), "-o", str(tmp_path / "f.json"))
    assert code == 2 and f"{cfg}: doors.all:" in err and "ajar" in err


@pytest.mark.parametrize("argv", [["houses", "--json"], ["query", "15", '{"query": "help"}']])
def test_a_reader_that_leaves_early_is_no_error(argv):
    """`ravh houses --json | head`: the pipe closes before ravh writes; no traceback."""
    proc = subprocess.Popen([sys.executable, "-m", "ravh_sim.cli", *argv], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env=subprocess_env())
    proc.stdout.close()
    _, err = proc.communicate(timeout=120)
    assert b"Traceback" not in err and b"BrokenPipe" not in err, err.decode()[-2000:]
    assert proc.returncode == 141


def test_render_outside_every_room_names_the_nearest_room(capsys, tmp_path):
    code, _, err = run_cli(capsys, "render", "15", "--pose", "1000", "1000", "0", "-o", str(tmp_path / "r"))
    assert code == 2 and "outside every room of house 15; nearest room: " in err
    assert not (tmp_path / "r").exists()
