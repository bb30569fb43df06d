"""Datasets: writer/reader round trip, crash safety, the dataset API, the raid summary, and the
recorder node against a real sim (captures, the MCAP bag, SIGKILL in the middle of a raid)."""
from __future__ import annotations

import errno
import json
import math
import os
import signal
import time
from collections import Counter
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import resolved
from rosgraph import NodeProcess, remove_orphan_shm, spin_until, start_rclpy
from test_files import file_size_limit

from ravh_msgs_py import names as n
from ravh_msgs_py.capture import CaptureEvent
from ravh_sim.dataset import layout
from ravh_sim.dataset.api import MIN_PIXELS, Dataset
from ravh_sim.dataset.writer import DatasetWriter
from ravh_sim.errors import UserError
from ravh_sim.nav.grid import FREE, OCCUPIED, UNKNOWN, Grid
from ravh_sim.nodes import convert
from ravh_sim.raids.summary import render_summary, write_summary
from ravh_sim.sensors import imaging
from ravh_sim.sensors.readings import CameraInfo, Scan
from ravh_sim.world.footprint import make_footprint
from ravh_sim.world.house import load_house

H, W = 48, 64
CAMERA = {"width": W, "height": H, "K": [50.0, 0, 32, 0, 50.0, 24, 0, 0, 1], "D": [0.0] * 5,
          "distortion_model": "plumb_bob", "frame_id": "camera_optical_frame"}
INFO = CameraInfo(CAMERA["frame_id"], W, H, "plumb_bob", tuple(CAMERA["D"]), tuple(CAMERA["K"]),
                  tuple(np.eye(3).ravel()), (50.0, 0, 32, 0, 0, 50.0, 24, 0, 0, 0, 1, 0))


def footprint_of(number: int) -> dict:
    house = load_house(number)
    return make_footprint(house, resolved(house))


@pytest.fixture(scope="module")
def footprint20() -> dict:
    return footprint_of(20)


def object_rows(footprint: dict) -> list[dict]:
    return [r for r in footprint["instances"] if r["kind"] == "object"]


def capture(rng: np.random.Generator, ids: list[int]) -> dict:
    """Synthetic capture arrays: random RGB, depth with every kind of invalid value, blocks of ids."""
    depth = rng.uniform(0.2, 9.0, (H, W)).astype(np.float32)
    depth[0, :4] = [np.nan, np.inf, 0.0, -1.0]
    instance = np.zeros((H, W), np.uint16)
    for k, i in enumerate(ids):                      # 16 x 16 blocks: 256 px each
        r, c = divmod(k, W // 16)
        instance[16 * r:16 * r + 16, 16 * c:16 * c + 16] = i
    ranges = rng.uniform(0.1, 10.0, 360).astype(np.float32)
    ranges[:3] = [np.inf, np.nan, 0.01]
    return {"rgb": rng.integers(0, 256, (H, W, 3), dtype=np.uint8), "depth": depth, "instance": instance,
            "rgb_info": INFO, "scan": Scan("laser_link", -math.pi, math.radians(179), math.radians(1.0), 0.0, 0.1,
                                           0.05, 30.0, ranges)}


def event(stamp: float, room: str | None, pose=(0.0, 0.0, 0.0), odom=(0.0, 0.0, 0.0)) -> CaptureEvent:
    return CaptureEvent("robot", stamp, tuple(pose), room, tuple(odom))


def write_dataset(root: Path, footprint: dict, poses: list[tuple[str | None, tuple[float, float, float]]],
                  seed: int = 0) -> list[dict]:
    """A dataset with one capture per (room, pose); returns the arrays written."""
    rng = np.random.default_rng(seed)
    objects = object_rows(footprint)
    written = []
    with DatasetWriter(root) as w:
        w.write_footprint(footprint)
        w.write_meta(footprint["house"], ["robot"], {"behaviour": "test"})
        grid = Grid(np.full((20, 30), FREE, np.int8), (-1.0, -2.0), 0.1)
        grid.data[0] = OCCUPIED
        grid.data[1, :5] = UNKNOWN
        w.write_map(grid)
        for k, (room, pose) in enumerate(poses):
            ids = [r["id"] for r in objects if r["room"] == room][:6] if room else []
            arrays = capture(rng, ids)
            index = w.write_capture(event(10.0 + k, room, pose, (pose[0] + 0.1, pose[1], pose[2])), arrays)
            assert index == k
            written.append(arrays)
    return written


def rooms_of(footprint: dict) -> dict[str, str]:
    return {r["room"]: r["room_type"] for r in footprint["instances"] if r["kind"] == "floor"}


# ---------------------------------------------------------------------------- writer / reader

def test_round_trip(tmp_path, footprint20):
    rooms = sorted(rooms_of(footprint20))
    poses = [(rooms[0], (-3.0, 1.0, 0.5)), (None, (-2.0, 1.0, -3.0)), (rooms[1], (-1.0, 0.5, 3.1))]
    written = write_dataset(tmp_path, footprint20, poses)
    ds = Dataset(tmp_path)
    assert len(ds) == 3
    assert ds.meta["format"] == layout.FORMAT and ds.meta["house"] == 20 and ds.meta["agents"] == ["robot"]
    assert ds.meta["raid"] == {"behaviour": "test"} and ds.meta["bag"] is None
    assert ds.settings.model_dump(mode="json") == footprint20["settings"]
    assert json.loads((tmp_path / layout.SETTINGS_JSON).read_text()) == footprint20["settings"]
    assert ds.camera == {"robot": CAMERA}
    grid = ds.map
    assert grid.shape == (20, 30) and grid.origin == (-1.0, -2.0) and grid.resolution == pytest.approx(0.1)
    assert (grid.data[0] == OCCUPIED).all() and (grid.data[1, :5] == UNKNOWN).all() and grid.data[5, 5] == FREE
    for k, (sample, arrays, (room, pose)) in enumerate(zip(ds, written, poses)):
        assert (sample.index, sample.stamp, sample.agent, sample.pose) == (k, 10.0 + k, "robot", pose)
        assert sample.odom == pytest.approx((pose[0] + 0.1, pose[1], pose[2]))
        assert sample.room == room and sample.room_type == (rooms_of(footprint20)[room] if room else None)
        assert np.array_equal(sample.rgb, arrays["rgb"])
        assert np.array_equal(sample.instance, arrays["instance"])
        assert sample.depth.dtype == np.float32
        invalid = ~np.isfinite(arrays["depth"]) | (arrays["depth"] <= 0)
        assert np.array_equal(np.isnan(sample.depth), invalid)
        assert np.abs(sample.depth[~invalid] - arrays["depth"][~invalid]).max() <= 0.0005 + 1e-6
        scan = sample.scan
        assert np.array_equal(scan.ranges, arrays["scan"].ranges, equal_nan=True)
        assert scan.angles[0] == pytest.approx(-math.pi) and scan.angles[-1] == pytest.approx(math.radians(179))
        assert (scan.range_min, scan.range_max) == (pytest.approx(0.05), 30.0)
    mask = ds[0].mask
    first = ds.instances[int(written[0]["instance"][0, 0])]
    assert tuple(mask[0, 0]) == tuple(first["mask_color"]) and tuple(mask[-1, -1]) == (0, 0, 0)


def test_a_folder_with_a_dataset_is_refused(tmp_path, footprint20):
    write_dataset(tmp_path, footprint20, [])
    with pytest.raises(UserError, match="already holds"):
        DatasetWriter(tmp_path)
    with pytest.raises(UserError, match="not a ravh_sim dataset"):
        Dataset(tmp_path / "nothing")


def test_a_crash_between_files_leaves_no_half_capture(tmp_path, footprint20, monkeypatch):
    room = sorted(rooms_of(footprint20))[0]
    real_write = layout.atomic_write

    def dying_write(path: Path, data: bytes) -> None:
        if path.parent.name == "mask":                # the other files written; dies before the mask
            path.with_name(f".{path.name}.1.tmp").write_bytes(data[:10])   # and a torn temp file
            raise KeyboardInterrupt("killed")
        real_write(path, data)

    writer = DatasetWriter(tmp_path / "a")
    writer.write_footprint(footprint20)
    writer.write_meta(20, ["robot"])
    writer.write_capture(event(1.0, room), capture(np.random.default_rng(1), []))
    monkeypatch.setattr(layout, "atomic_write", dying_write)
    with pytest.raises(KeyboardInterrupt):
        writer.write_capture(event(2.0, room), capture(np.random.default_rng(2), []))
    a = tmp_path / "a"
    assert (a / "rgb/000001.png").exists() and (a / "depth/000001.png").exists()
    assert not (a / "mask/000001.png").exists() and (a / "mask/.000001.png.1.tmp").exists()
    ds = Dataset(a)
    assert len(ds) == 1 and ds[0].stamp == 1.0 and ds[0].rgb.shape == (H, W, 3)


def test_torn_lines_and_missing_files_are_skipped(tmp_path, footprint20, caplog):
    """What a killed recorder or a power cut leaves is left out, and said (issue 31: not silently)."""
    room = sorted(rooms_of(footprint20))[0]
    root = tmp_path / "b"
    write_dataset(root, footprint20, [(room, (0.0, 0.0, 0.0))] * 2)
    with open(root / layout.CAPTURES_JSONL, "a") as f:         # killed while appending a line
        f.write('{"index": 2, "stamp": 12.0, "agent": "rob')
    (root / "rgb/000000.png").unlink()                         # a file lost in a power cut
    with caplog.at_level("WARNING", logger="ravh_sim.dataset.api"):
        ds = Dataset(root)
    assert [s.index for s in ds] == [1]
    said = [r.getMessage() for r in caplog.records if r.name == "ravh_sim.dataset.api" and r.levelname == "WARNING"]
    assert len(said) == 2, said
    assert said[0].startswith(f"{root / layout.CAPTURES_JSONL}:3: torn last line left out")
    assert said[1] == f"{root / layout.CAPTURES_JSONL}: 1 capture(s) left out whose files are missing (line 1)"


def test_a_complete_dataset_reads_without_a_warning(tmp_path, footprint20, caplog):
    room = sorted(rooms_of(footprint20))[0]
    write_dataset(tmp_path / "fine", footprint20, [(room, (0.0, 0.0, 0.0))] * 2)
    with caplog.at_level("DEBUG", logger="ravh_sim.dataset.api"):
        assert len(Dataset(tmp_path / "fine")) == 2
    assert [r for r in caplog.records if r.name == "ravh_sim.dataset.api"] == []


@pytest.mark.parametrize("bad", ['{"index": 1, "stamp": 11.0, "agent": "rob\n',     # a torn line, then more
                                 "\n", "[1, 2]\n", '{"index": 1}\n'])
def test_a_malformed_line_in_the_middle_refuses_the_dataset_naming_file_and_line(tmp_path, footprint20, bad):
    """A torn line is tolerated only last (the recorder died writing it); anywhere else captures.jsonl is
    damaged and reading on would hide it: one line names the file and the line."""
    room = sorted(rooms_of(footprint20))[0]
    root = tmp_path / "c"
    write_dataset(root, footprint20, [(room, (0.0, 0.0, 0.0))] * 3)
    path = root / layout.CAPTURES_JSONL
    lines = path.read_text().splitlines(keepends=True)
    path.write_text(lines[0] + bad + lines[2])                   # line 2 damaged, lines 1 and 3 fine
    with pytest.raises(UserError) as refused:
        Dataset(root)
    message = str(refused.value)
    assert message.startswith(f"{path}:2: malformed capture row") and "\n" not in message


def test_a_full_disk_stops_a_capture_without_a_torn_file(tmp_path, footprint20):
    """Writes past a file-size limit fail as on a full disk: the capture that did not fit raises, and the
    dataset keeps the captures before it, with no torn line, no empty file and no temp file."""
    room = sorted(rooms_of(footprint20))[0]
    root = tmp_path / "full"
    blank = {**capture(np.random.default_rng(0), []), "rgb": np.zeros((H, W, 3), np.uint8),
             "depth": np.ones((H, W), np.float32), "instance": np.zeros((H, W), np.uint16)}
    blank["scan"] = replace(blank["scan"], ranges=np.ones(8, np.float32))
    writer = DatasetWriter(root)
    writer.write_footprint(footprint20)
    writer.write_meta(20, ["robot"])
    line = 0
    with file_size_limit(1500), pytest.raises(OSError) as full:     # captures.jsonl fills up first
        for k in range(100):
            line = (root / layout.CAPTURES_JSONL).stat().st_size
            writer.write_capture(event(float(k), room), blank)
    assert full.value.errno == errno.EFBIG and 0 < writer.count < 100
    assert full.value.filename == str(root / layout.CAPTURES_JSONL)      # the error names the file (issue 24)
    assert (root / layout.CAPTURES_JSONL).stat().st_size == line        # the part-written line was cut off
    with file_size_limit(2000), pytest.raises(OSError) as image:        # an image does not fit
        writer.write_capture(event(99.0, room), capture(np.random.default_rng(0), []))
    assert image.value.filename.startswith(str(root)) and not Path(image.value.filename).name.startswith(".")
    writer.close()
    everything = [p for p in root.rglob("*") if p.is_file()]
    assert [p for p in everything if p.name.startswith(layout.TMP_PREFIX) or p.stat().st_size == 0] == []
    lines = (root / layout.CAPTURES_JSONL).read_text().splitlines(keepends=True)
    assert len(lines) == writer.count and all(ln.endswith("\n") and json.loads(ln) for ln in lines)
    ds = Dataset(root)
    assert [s.stamp for s in ds] == [float(k) for k in range(writer.count)]
    assert ds[0].rgb.shape == (H, W, 3)


def test_depth_encoding_limits():
    metres = np.array([[0.0005, 0.0004, 1.23456, 65.535, 65.6, np.nan, -np.inf]])
    mm = imaging.depth_to_png(metres)
    assert mm.dtype == np.uint16 and mm.tolist() == [[0, 0, 1235, 65535, 0, 0, 0]]
    back = imaging.depth_from_png(mm)
    assert back[0, 2] == pytest.approx(1.235) and np.isnan(back[0, 4:]).all()


# ---------------------------------------------------------------------------- the API

def test_counts_match_the_footprint_and_the_house(tmp_path, footprint20):
    write_dataset(tmp_path, footprint20, [])
    ds = Dataset(tmp_path)
    house = load_house(20)
    objects = [o for o in house.objects if o.id not in house.door_by_id and o.type != "Wall"]
    assert ds.count_objects() == len(objects)
    for obj_type, count in Counter(o.type for o in objects).items():
        assert ds.count_objects(type=obj_type) == count
    for room in house.rooms:
        assert ds.count_objects(room=room.id) == sum(o.room == room.id for o in objects)
    assert ds.count_objects(type="Chair", room=house.rooms[0].id) == sum(
        o.type == "Chair" and o.room == house.rooms[0].id for o in objects)
    assert ds.count_rooms() == len(house.rooms)
    for room_type, count in Counter(r.type for r in house.rooms).items():
        assert ds.count_rooms(room_type) == count
    assert ds.count_rooms("Garage") == 0 and ds.count_objects(type="Spaceship") == 0
    assert ds.house.number == 20


def test_objects_in_counts_visible_instances_by_type(tmp_path, footprint20):
    objects = object_rows(footprint20)
    chairs = [r for r in objects if r["type"] == "Chair"][:2]
    other = next(r for r in objects if r["type"] != "Chair")
    door = next(r for r in footprint20["instances"] if r["kind"] == "door")
    tiny = next(r for r in objects if r["type"] not in ("Chair", other["type"]))
    ds_writer_root = tmp_path / "one"
    with DatasetWriter(ds_writer_root) as w:
        w.write_footprint(footprint20)
        w.write_meta(20, ["robot"])
        arrays = capture(np.random.default_rng(0), [chairs[0]["id"], chairs[1]["id"], other["id"], door["id"]])
        arrays["instance"][-1, :MIN_PIXELS - 1] = tiny["id"]          # too small to count
        w.write_capture(event(1.0, chairs[0]["room"]), arrays)
    ds = Dataset(ds_writer_root)
    assert ds.objects_in(ds[0]) == Counter({"Chair": 2, other["type"]: 1})
    assert ds.objects_in(ds[0], min_pixels=1)[tiny["type"]] == 1


def test_filter_and_rooms_visited(tmp_path, footprint20):
    types = rooms_of(footprint20)
    a, b = sorted(types)[:2]
    write_dataset(tmp_path, footprint20, [(b, (0, 0, 0)), (None, (0, 0, 0)), (a, (0, 0, 0)), (b, (0, 0, 0))])
    ds = Dataset(tmp_path)
    assert ds.rooms_visited() == [b, a]
    assert [s.index for s in ds.filter(room=b)] == [0, 3]
    assert [s.index for s in ds.filter(room_type=types[a])] == [2]
    assert len(ds.filter(agent="robot")) == 4 and ds.filter(agent="robot2") == []
    assert ds[-1].index == 3


# ---------------------------------------------------------------------------- the summary

@pytest.mark.parametrize("number", [20, 1])          # a wide plan (sheet below) and a tall one (beside)
def test_summary_renders(tmp_path, number):
    footprint = footprint_of(number)
    house = load_house(number)
    poses = [(room.id, (*np.mean(room.floor, axis=0), 0.3 * k)) for k, room in enumerate(house.rooms)] * 5
    write_dataset(tmp_path, footprint, poses)
    ds = Dataset(tmp_path)
    image = render_summary(ds)
    assert image.dtype == np.uint8 and image.ndim == 3
    assert min(image.shape[:2]) > 1000 and max(image.shape[:2]) < 4000
    assert (image.shape[1] > image.shape[0]) == (number == 1)
    write_summary(ds, tmp_path / "summary.png")
    assert cv2.imread(str(tmp_path / "summary.png")).shape == image.shape


def test_summary_of_an_empty_dataset(tmp_path, footprint20, capsys):
    from ravh_sim.cli import main
    write_dataset(tmp_path / "ds", footprint20, [])
    assert main(["raid-summary", str(tmp_path / "ds"), "-o", str(tmp_path / "s.png")]) == 0
    assert "0 captures" in capsys.readouterr().out and (tmp_path / "s.png").exists()


# ---------------------------------------------------------------------------- the recorder

def recorder_module():
    """The recorder node module, imported where it is used so the ROS-free tests above load without rclpy."""
    from ravh_sim.nodes import recorder_node
    return recorder_node


def test_matcher_waits_for_every_part_in_any_order():
    m = recorder_module().StampMatcher({"rgb", "depth", "event"}, max_pending=3, timeout_s=5.0)
    assert m.add(1, "event", "e1", 0.0) is None              # event first
    assert m.add(1, "rgb", "r1", 0.0) is None
    assert m.add(1, "rgb", "late duplicate", 0.0) is None
    assert m.add(1, "depth", "d1", 0.1) == {"event": "e1", "rgb": "r1", "depth": "d1"}
    for stamp in range(2, 8):                                 # periodic frames: never an event
        m.add(stamp, "rgb", "r", 0.2)
    assert len(m.pending) == 3 and m.lost == []
    m.add(9, "event", "e9", 0.3)                              # an event keeps its stamp from being evicted
    for stamp in range(10, 20):
        m.add(stamp, "rgb", "r", 0.4)
    assert 9 in m.pending
    m.add(30, "rgb", "r", 10.0)                               # ...until it times out, reported lost
    assert m.lost == [9] and 9 not in m.pending


def test_matcher_refuses_a_second_capture_at_one_stamp():
    """Two events at one stamp would merge two captures: the second is refused and reported, pending or
    after the first was stored."""
    m = recorder_module().StampMatcher({"rgb", "event"})
    assert m.add(5, "event", "e5", 0.0) is None
    assert m.add(5, "event", "another e5", 0.0) is None and m.duplicates == [5]
    assert m.add(5, "rgb", "r5", 0.0) == {"event": "e5", "rgb": "r5"}
    assert m.add(5, "event", "a third e5", 0.1) is None and m.duplicates == [5, 5] and m.pending == {}
    assert m.add(6, "rgb", "r6", 0.1) is None and m.add(6, "event", "e6", 0.1) == {"rgb": "r6", "event": "e6"}
    assert m.waiting() == 0 and m.add(7, "event", "e7", 0.2) is None and m.waiting() == 1


def test_stamps_from_cdr_and_events_agree():
    rec = recorder_module()
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import LaserScan

    for seconds in (0.0, 353.6, 12.345678901, 1e6 + 0.1):
        data = serialize_message(LaserScan(header=convert.header(seconds, "laser_link")))
        assert rec.header_stamp_ns(data) == rec.event_stamp_ns(seconds)


@pytest.fixture(scope="module")
def sim():
    recorder_module()
    import rclpy
    started = time.time()
    from std_srvs.srv import Trigger
    with NodeProcess("sim", "--house", "20", "--seed", "0", "--camera-rate", "0", "--rtf", "0") as proc:
        start_rclpy()
        node = rclpy.create_node(f"dataset_probe_{os.getpid()}")
        try:
            client = node.create_client(Trigger, n.CAPTURE_SERVICE)
            assert client.wait_for_service(timeout_sec=90), f"sim did not start:\n{proc.log()[-3000:]}"
            yield proc, node, client
        finally:
            node.destroy_node()
    remove_orphan_shm(started)            # the SIGKILLed recorder's segments, now that no one maps them


def start_recorder(sim, out: Path, *args: str) -> NodeProcess:
    _, node, _ = sim
    rec = NodeProcess("recorder", "--out", str(out), *args)
    from ravh_sim.nodes.recorder_node import MATCHED_LOG
    ready = spin_until(node, lambda: (out / layout.DATASET_JSON).exists() and MATCHED_LOG in rec.log(), 30)
    if not ready:
        rec.stop()
        pytest.fail(f"recorder not ready:\n{rec.log()[-3000:]}")
    return rec


def request_capture(sim) -> CaptureEvent:
    return request_captures(sim, 1)[0]


def request_captures(sim, count: int) -> list[CaptureEvent]:
    """``count`` capture requests sent at once (the sim takes them before its clock moves); their events."""
    from std_srvs.srv import Trigger
    _, node, client = sim
    futures = [client.call_async(Trigger.Request()) for _ in range(count)]
    assert spin_until(node, lambda: all(f.done() for f in futures), 20 * count)
    assert all(f.result().success for f in futures), [f.result().message for f in futures]
    return [CaptureEvent.from_json(f.result().message) for f in futures]


def rows(out: Path) -> int:
    path = out / layout.CAPTURES_JSONL
    return path.read_text().count("\n") if path.exists() else 0


def test_recorder_writes_captures_and_a_bag(sim, tmp_path):
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore
    out = tmp_path / "raid"
    with start_recorder(sim, out, "--raid", '{"behaviour": "test"}') as rec:
        events = [request_capture(sim) for _ in range(4)]
        assert spin_until(sim[1], lambda: rows(out) == 4, 30), rec.log()[-3000:]
        assert rec.stop() == 0, rec.log()[-3000:]
    assert "Traceback" not in rec.log()

    ds = Dataset(out)
    assert len(ds) == 4 and ds.meta["raid"] == {"behaviour": "test"} and ds.meta["bag"] == "bag"
    assert ds.map is not None and set(np.unique(ds.map.data)) == {FREE, OCCUPIED, UNKNOWN}
    assert ds.camera["robot"]["width"] == 640 and ds.camera["robot"]["frame_id"] == n.CAMERA_OPTICAL_FRAME
    room_types = rooms_of(ds.footprint)
    for sample, event in zip(ds, events):
        assert sample.stamp == event.stamp and sample.pose == pytest.approx(event.pose)
        assert sample.room == event.room and sample.room_type == room_types.get(event.room)
        assert sample.rgb.shape == (480, 640, 3) and sample.instance.shape == (480, 640)
        assert np.isfinite(sample.depth).mean() > 0.5 and len(sample.scan.ranges) == 360
        ids = set(np.unique(sample.instance).tolist()) - {0}
        assert ids and ids <= set(ds.instances)

    typestore = get_typestore(Stores.ROS2_JAZZY)
    with Reader(out / layout.BAG_DIR) as bag:
        counts = {c.topic: c.msgcount for c in bag.connections}
        for topic in (n.COLOR_COMPRESSED, n.DEPTH_IMAGE, n.INSTANCE_IMAGE, n.COLOR_INFO, n.DEPTH_INFO,
                      n.CAPTURE_EVENT):
            assert counts["/" + topic] == 4, topic
        assert counts[n.MAP] >= 1 and counts[n.GROUND_TRUTH] >= 1 and counts["/" + n.INSTANCE_LABELS] == 1
        assert counts["/" + n.SCAN] >= 4 and counts["/" + n.ODOM] > 0 and counts["/" + n.GROUND_TRUTH_POSE] > 0
        assert counts[n.TF] > 0 and counts[n.TF_STATIC] == 1
        static_conn = [c for c in bag.connections if c.topic == n.TF_STATIC]
        static = [typestore.deserialize_cdr(raw, c.msgtype) for c, _, raw in bag.messages(connections=static_conn)]
        assert {t.child_frame_id for t in static[0].transforms} == {n.LASER_FRAME, n.CAMERA_FRAME,
                                                                    n.CAMERA_OPTICAL_FRAME}
        latched = next(c for c in bag.connections if c.topic == n.MAP)
        assert latched.ext.offered_qos_profiles[0].durability.name == "TRANSIENT_LOCAL"
        depth_conn = [c for c in bag.connections if c.topic == "/" + n.DEPTH_IMAGE]
        msgs = [typestore.deserialize_cdr(raw, c.msgtype) for c, _, raw in bag.messages(connections=depth_conn)]
    first = min(msgs, key=lambda m: (m.header.stamp.sec, m.header.stamp.nanosec))
    assert convert.seconds(first.header.stamp) == pytest.approx(ds[0].stamp)
    depth = convert.image_array(first)                       # a rosbags message: the same fields
    assert depth.shape == (480, 640)
    valid = np.isfinite(depth)
    assert np.array_equal(valid, np.isfinite(ds[0].depth))
    assert np.abs(depth[valid] - ds[0].depth[valid]).max() <= 0.0005 + 1e-6


def test_captures_requested_at_once_all_land_distinct(sim, tmp_path):
    """Requests that reach the sim together, before its clock moves (as under load or from several
    clients): each capture gets a stamp of its own, and the dataset holds each once, whole."""
    out = tmp_path / "burst"
    with start_recorder(sim, out) as rec:
        events = request_captures(sim, 4) + request_captures(sim, 3)
        assert len({e.stamp for e in events}) == 7
        assert spin_until(sim[1], lambda: rows(out) == 7, 60), rec.log()[-3000:]
        assert rec.stop() == 0, rec.log()[-3000:]
    ds = Dataset(out)
    assert [s.stamp for s in ds] == sorted(e.stamp for e in events)
    by_stamp = {e.stamp: e for e in events}
    for sample in ds:
        assert sample.pose == pytest.approx(by_stamp[sample.stamp].pose) and len(sample.scan.ranges) == 360


def test_a_killed_recorder_leaves_a_consistent_dataset(sim, tmp_path):
    out = tmp_path / "killed"
    with start_recorder(sim, out) as rec:
        for _ in range(3):
            request_capture(sim)
        assert spin_until(sim[1], lambda: rows(out) == 3, 30), rec.log()[-3000:]
        request_capture(sim)
        first_file = out / layout.capture_files(3)["rgb"]
        end = time.monotonic() + 20
        while not first_file.exists() and time.monotonic() < end:   # kill it while it writes capture 3
            time.sleep(0.0005)
        rec.proc.send_signal(signal.SIGKILL)
        rec.proc.wait(10)
    assert first_file.exists(), rec.log()[-3000:]
    request_capture(sim)                                      # the sim does not mind

    ds = Dataset(out)
    assert len(ds) in (3, 4)                                  # 4 only if the kill came after the line
    for sample in ds:
        assert sample.rgb.shape == (480, 640, 3) and sample.depth.shape == sample.instance.shape == (480, 640)
        assert len(sample.scan.ranges) == 360
    listed = {s.index for s in ds}
    for kind, path in layout.capture_files(0).items():
        on_disk = {int(p.stem) for p in (out / kind).glob(f"*{Path(path).suffix}")}   # not torn temp files
        assert listed <= on_disk and len(on_disk - listed) <= 1, kind   # at most the in-flight capture
    assert not (out / layout.BAG_DIR / "metadata.yaml").exists()     # the bag was not closed
