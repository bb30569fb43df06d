"""Sensor ports and the suite: rates, topics, reads from a runtime agent, and the dataset round trip."""
from __future__ import annotations

import numpy as np
import pytest

from ravh_msgs_py import names as n
from ravh_sim.dataset import layout
from ravh_sim.dataset.api import Dataset
from ravh_sim.dataset.writer import DatasetWriter
from ravh_sim.errors import UserError
from ravh_sim.nodes import convert
from ravh_sim.runtime import ODOM, SimRuntime
from ravh_sim.sensors.ports import noise_rng
from ravh_sim.sensors.readings import CameraInfo, Scan
from ravh_sim.sensors.suite import SENSORS

EXPECTED_FIRST_DRAW = 1507402568       # numpy SeedSequence([5, 1, crc32("robot"), 0])


@pytest.fixture(scope="module")
def runtime():
    rt = SimRuntime(20, seed=4, renderer="tiny")
    yield rt
    rt.close()


def test_the_suite_is_well_formed():
    assert [p.name for p in SENSORS] == ["scan", "camera"]          # cheap first: scans wait on no render
    kinds = [kind for p in SENSORS for kind in p.files]
    assert len(kinds) == len(set(kinds)) and all(ext.startswith(".") for p in SENSORS for ext in p.files.values())
    keys = [t.key for p in SENSORS for t in p.topics]
    assert len(keys) == len(set(keys))                                  # publishers are indexed by key
    assert {t.kind for p in SENSORS for t in p.topics} <= set(convert.KINDS)
    bases = [t.base for p in SENSORS for t in p.topics]
    assert len(bases) == len(set(bases)) and all(not b.startswith("/") for b in bases)   # per agent


def test_rates_come_from_the_robot_profile(runtime):
    agent = runtime.agents[0]
    assert agent.rates == {ODOM: agent.profile.odom_rate, "camera": agent.profile.camera.rate,
                           "scan": agent.profile.laser.rate}
    assert all(port.rate(agent.profile.spec(port)) > 0 for port in SENSORS)


def test_rate_overrides_apply_on_top_and_unknown_rates_are_refused():
    rt = SimRuntime(20, renderer="tiny", rates={"camera": 0.0, ODOM: 25.0})
    try:
        agent = rt.agents[0]
        assert agent.rates == {ODOM: 25.0, "camera": 0.0, "scan": agent.profile.laser.rate}
        due = {"camera": 0, ODOM: 0}
        for _ in range(240):                                            # one sim second
            rt.step()
            for what in due:
                due[what] += rt.due(agent, what)
        assert due == {"camera": 0, ODOM: pytest.approx(25, abs=1)}
    finally:
        rt.close()
    with pytest.raises(UserError, match="unknown rate imu"):
        SimRuntime(20, renderer="tiny", rates={"imu": 5.0})


def test_each_port_reads_data_of_the_declared_shape(runtime):
    agent = runtime.agents[0]
    profile = agent.profile
    for port in SENSORS:
        data = runtime.read(agent, port.name)
        frame = n.agent_name(port.frame, agent.name, agent.first)
        for topic in port.topics:
            value = port.value(topic.key, data, agent.sensors[port.name], frame)
            msg = convert.KINDS[topic.kind].to_message(value, convert.header(runtime.time, frame))
            assert isinstance(msg, convert.KINDS[topic.kind].msg_type)
            if topic.kind == "rgb8":
                assert value.shape == (profile.camera.height_px, profile.camera.width, 3)
            elif topic.kind in ("32FC1", "16UC1"):
                assert value.shape == (profile.camera.height_px, profile.camera.width)
            elif topic.kind == "camera_info":
                assert isinstance(value, CameraInfo) and value.frame_id == frame
                assert (value.width, value.height) == (profile.camera.width, profile.camera.height_px)
            elif topic.kind == "laser_scan":
                assert isinstance(value, Scan) and value.ranges.shape == (profile.laser.ray_count,)
            else:
                assert topic.kind == "jpeg" and value[:2] == b"\xff\xd8"


def test_mounts_are_every_sensor_frame_on_base_link(runtime):
    children = [child for _, child, _, _ in runtime.static_transforms(runtime.agents[0])]
    assert sorted(children) == sorted([n.CAMERA_FRAME, n.CAMERA_OPTICAL_FRAME, n.LASER_FRAME])
    assert {port.frame for port in SENSORS} <= set(children)


def test_each_port_stores_the_files_it_declares(runtime):
    _, values = runtime.sample(runtime.agents[0])
    for port in SENSORS:
        assert set(port.encode(values).files) == set(port.files)
    assert layout.capture_files(7) == {"rgb": "rgb/000007.png", "depth": "depth/000007.png",
                                       "mask": "mask/000007.png", "scan": "scan/000007.npy"}   # the README's layout


def test_a_sample_round_trips_through_a_dataset_and_through_the_topics(runtime, tmp_path):
    """What the direct engine writes from the runtime equals what the recorder writes from the
    decoded messages, and the dataset reads both back as the sensors saw them."""
    agent = runtime.agents[0]
    runtime.command(agent, 0.2, 0.3)
    runtime.step(120)
    event, values = runtime.sample(agent)
    hdr = convert.header(event.stamp, values["rgb_info"].frame_id)
    decoded = {}
    for port in SENSORS:
        for topic in port.topics:
            if topic.dataset:
                kind = convert.KINDS[topic.kind]
                decoded[topic.key] = kind.from_message(kind.to_message(values[topic.key], hdr))
    for folder, vals in (("direct", values), ("ros", decoded)):
        with DatasetWriter(tmp_path / folder) as w:
            w.write_footprint(runtime.footprint())
            w.write_meta(runtime.house.number, [agent.name])
            assert w.write_capture(event, vals) == 0
    for kind, path in layout.capture_files(0).items():
        assert (tmp_path / "direct" / path).read_bytes() == (tmp_path / "ros" / path).read_bytes(), kind
    ds = Dataset(tmp_path / "direct")
    sample = ds[0]
    assert (sample.agent, sample.stamp, sample.room) == (agent.name, event.stamp, event.room)
    assert sample.pose == pytest.approx(event.pose) and sample.odom == pytest.approx(event.odom)
    assert np.array_equal(sample.rgb, values["rgb"]) and np.array_equal(sample.instance, values["instance"])
    assert np.array_equal(sample.scan.ranges, values["scan"].ranges)
    assert np.allclose(sample.depth, values["depth"], atol=0.0005, equal_nan=True)       # 1 mm steps
    assert sample.read("mask") is sample.instance                     # decoded by its port once
    assert ds.camera[agent.name]["frame_id"] == n.CAMERA_OPTICAL_FRAME
    assert ds.camera[agent.name]["K"] == list(values["rgb_info"].K)


def test_noise_streams_are_stable_across_processes():
    """A stable hash of the agent's name (not Python's salted hash()): the same seed gives the same
    noise in every run."""
    assert noise_rng(5, 1, "robot", 0).integers(0, 2**31) == noise_rng(5, 1, "robot", 0).integers(0, 2**31)
    assert noise_rng(5, 1, "robot", 0).integers(0, 2**31) != noise_rng(5, 1, "robot2", 0).integers(0, 2**31)
    assert int(noise_rng(5, 1, "robot", 0).integers(0, 2**31)) == EXPECTED_FIRST_DRAW

