"""Model swaps cost no memory once every model an object has been shown was built (issue 24: the sim
grew 2-3 MB per model-changing request and a long randomised session ended out of memory).

pybullet frees neither a removed body's memory nor its shapes, so a swapped-out model's body is parked
out of the house and comes back with its model; the GL renderer keeps only the arrays of models the
World shows and releases its material table on each upload. RSS is measured in a fresh process
(this suite's own process carries every other test's heap)."""
from __future__ import annotations

import json
import subprocess
import sys

import pybullet as pb
import pytest
from conftest import ROOT, subprocess_env

from ravh_msgs_py.appearance import parse
from ravh_sim.world.dressing import dressing
from ravh_sim.world.scene import OPEN_DOOR_DROP
from ravh_sim.world.solids import model_count

MB = 2**20
SWAPS = 200
GROWTH_LIMIT_MB = 50.0          # the issue's bound for 200 model swaps
STEADY_LIMIT_MB = 8.0           # once every model was built: flat
POOL_LIMIT_MB = 200.0           # every model of every object built once (house 23 has 525 of them)

CHILD = r"""
import ctypes, json, os, random, sys
from dataclasses import replace
from ravh_sim.robot.profile import load_profile
from ravh_sim.runtime import SimRuntime
from ravh_sim.sensors.camera import SmartCamera
from ravh_sim.world.solids import model_count

def rss():
    ctypes.CDLL("libc.so.6").malloc_trim(0)          # what the heap holds, not what it has not returned
    return int(open("/proc/self/statm").read().split()[1]) * os.sysconf("SC_PAGE_SIZE")

house, renderer, kind, swaps, render = int(sys.argv[1]), sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5] == "1"
rt = SimRuntime(house, renderer=renderer)
camera = None
if render:                 # a frame after every swap: the renderer re-uploads the house each time
    camera = SmartCamera(rt.world, replace(load_profile("giraff").camera, quality="fast"))
    x, y, yaw = rt.agents[0].robot.pose
    camera.render(x, y, yaw)
objects, rng = [o for o in rt.house.objects if model_count(o) > 1], random.Random(24)
samples = {"0": rss()}
for i in range(swaps):
    if kind == "one":      # one object, another of its models
        obj = rng.choice(objects)
        others = [m for m in range(model_count(obj)) if m != rt.world.state.models[obj.id]]
        request = {"models": {obj.id: rng.choice(others)}}
    else:                  # every object a new random model
        request = {"models": {"all": "random"}, "seed": i}
    reply = rt.change_appearance(request)
    assert reply["ok"], reply
    if camera is not None:
        camera.render(x, y, yaw)
    if (i + 1) % (swaps // 2) == 0:
        samples[str(i + 1)] = rss()
samples["changed"] = sum(a != b for a, b in zip(rt.initial.models.values(), rt.world.state.models.values()))
print(json.dumps(samples))
"""


def _rss_during_swaps(house: int, renderer: str, kind: str, swaps: int = SWAPS, render: bool = False
                      ) -> dict[str, float]:
    """RSS in MB at the start, half-way and at the end of ``swaps`` model changes in a fresh process."""
    done = subprocess.run([sys.executable, "-c", CHILD, str(house), renderer, kind, str(swaps), str(int(render))],
                          cwd=ROOT, env=subprocess_env(), capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    rss = json.loads(done.stdout.strip().splitlines()[-1])
    return {"start": rss["0"] / MB, "half": rss[str(swaps // 2)] / MB, "end": rss[str(swaps)] / MB,
            "changed": rss["changed"]}


@pytest.mark.parametrize("house", [15, 23])
def test_200_model_swaps_grow_rss_by_less_than_50_mb(house):
    """200 model swaps (one object, another of its models), with the sim's GL renderer: before, every
    swap left a body and its shapes behind (house 15: ~120 kB each, without end)."""
    rss = _rss_during_swaps(house, "gl", "one")
    print(f"house {house}: RSS {rss['start']:.0f} -> {rss['half']:.0f} -> {rss['end']:.0f} MB over {SWAPS} swaps")
    assert rss["end"] - rss["start"] < GROWTH_LIMIT_MB


@pytest.mark.parametrize("house", [15, 23])
def test_swapping_every_object_grows_nothing_once_each_model_was_built(house):
    """200 requests that each draw a new model for every object (60-130 bodies per request): memory
    grows only until each object's every model was built once, then not at all (before: house 15
    gained ~5.7 MB per request, 275 -> 846 MB over 100)."""
    rss = _rss_during_swaps(house, "tiny", "all")
    print(f"house {house}: RSS {rss['start']:.0f} -> {rss['half']:.0f} -> {rss['end']:.0f} MB over {SWAPS} "
          "all-object requests")
    assert rss["changed"] > 20
    assert rss["half"] - rss["start"] < POOL_LIMIT_MB
    assert rss["end"] - rss["half"] < STEADY_LIMIT_MB


def test_model_swaps_rendered_by_the_gl_renderer_grow_nothing():
    """The GL renderer drawing a frame after every all-object swap: flat once every model was built."""
    rss = _rss_during_swaps(15, "gl", "all", swaps=60, render=True)
    print(f"GL: RSS {rss['start']:.0f} -> {rss['half']:.0f} -> {rss['end']:.0f} MB")
    assert rss["end"] - rss["half"] < STEADY_LIMIT_MB


# ------------------------------------------------------------------ what the World keeps

def test_a_swapped_out_model_is_parked_out_of_the_house_and_comes_back(world, appearance):
    c = world.client
    body, pose = world.instance("Bed_0").body, world.object_pose("Bed_0")
    start = world.state.models["Bed_0"]
    other = (start + 1) % 2
    appearance.set_object_model("Bed_0", other)
    swapped = world.instance("Bed_0").body
    assert swapped != body and body not in world.visuals and swapped in world.visuals
    # a ray down through the bed hits the new model; with the new model hidden from it, the old body would
    # be next in its way if it had stayed: it hits neither, and a ray through the parking spot hits it
    (x, y, z), _ = pose
    down = ([[x, y, z + 3.0]], [[x, y, world.floor_z - 1.0]])
    on_bed = {d.id for d in dressing(world.house, world.state.models, world.state.dressing, world.state.seed)
              if d.slot.support == "Bed_0"}                         # pillows and a duvet lie on the bed
    dressing_bodies = [world.instance(name).body for name in on_bed]
    assert world.cast_rays(*down, mask=world.ray_mask(dressing_bodies))[0][0] == swapped
    assert world.cast_rays(*down, mask=world.ray_mask([swapped, *dressing_bodies]))[0][0] not in (body, swapped)
    parked = z - OPEN_DOOR_DROP
    assert world.cast_rays([[x, y, parked + 3.0]], [[x, y, parked - 3.0]])[0][0] == body
    assert pb.getBasePositionAndOrientation(body, physicsClientId=c)[0] == pytest.approx((x, y, parked))
    assert world.object_pose("Bed_0")[0][2] > world.floor_z - 1.0               # the new model is in the house
    appearance.set_object_model("Bed_0", start)
    assert world.instance("Bed_0").body == body and world.object_pose("Bed_0") == pose
    assert swapped not in world.visuals
    assert pb.getBasePositionAndOrientation(swapped, physicsClientId=c)[0][2] < world.floor_z - OPEN_DOOR_DROP / 2
    for model in range(model_count(world.house.object("Bed_0"))):
        appearance.set_object_model("Bed_0", model)
    count = world.body_to_instance_lut().size
    for seed in range(10):                                   # every model built: no new body after that
        appearance.change(parse({"models": {"Bed_0": "random"}, "seed": seed}))
    appearance.set_object_model("Bed_0", other)
    assert world.body_to_instance_lut().size == count


def test_the_gl_scene_builder_keeps_only_models_the_world_shows(world, appearance):
    """Every model an object has shown is remembered here, by (object, model index); after each swap the
    builder keeps the arrays of none of those the state no longer shows (worked out from the state, not
    from the World's visuals, which the builder itself reads)."""
    from ravh_sim.look.geometry import SceneBuilder
    from ravh_sim.look.materials import MaterialTable
    builder = SceneBuilder(world, MaterialTable())
    sources: dict[tuple[str, int], int] = {}                  # (object, model) -> id of what draws it
    objects = [inst for inst in world.instances if inst.kind == "object"]
    forgotten = 0
    for seed in range(6):
        appearance.change(parse({"models": {"all": "random"}, "seed": seed}))
        builder.build()
        models = world.state.models
        for inst in objects:
            visual = world.visuals[inst.body]
            sources[inst.name, models[inst.name]] = id(visual.model if visual.model is not None else visual.mesh)
        shown = {key for (name, model), key in sources.items() if models[name] == model}
        swapped_out = {key for (name, model), key in sources.items() if models[name] != model} - shown
        assert shown <= set(builder._arrays)                   # what is drawn has its arrays
        assert not swapped_out & set(builder._arrays), seed     # swapped-out (parked) models: forgotten
        forgotten += len(swapped_out)
    assert forgotten > 20                                      # the seeds did swap models out
