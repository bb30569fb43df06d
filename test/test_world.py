"""The pybullet World: every house builds, every labelled object is its own body, run-time changes work."""
from __future__ import annotations

import math

import numpy as np
import pybullet as pb
import pytest
from conftest import resolved

from ravh_sim.world.appearance import Appearance
from ravh_sim.world.footprint import build_instances, dressing_instances, make_footprint
from ravh_sim.world.library import record
from ravh_sim.world.scene import World
from ravh_sim.world.solids import model_count, object_parts


def test_every_house_builds_with_one_body_per_labelled_object(houses):
    for n, house in houses.items():
        with World(house, resolved(house)) as world:
            objects = [i for i in world.instances if i.kind in ("object", "door", "window")]
            assert len(objects) == len(house.objects), n
            # a dressing object the layout leaves out has no body (ravh_sim.world.dressing)
            bodies = [i.body for i in world.instances if i.kind != "dressing" or i.body >= 0]
            assert len(set(bodies)) == len(bodies) and min(bodies) >= 0, n
            assert pb.getNumBodies(physicsClientId=world.client) == len(bodies) + 1, n   # + the ground
            lut = world.body_to_instance_lut()
            assert all(lut[i.body] == i.id for i in world.instances if i.body >= 0), n


def test_house_23_geometry_budget(houses):
    with World(houses[23], resolved(houses[23])) as world:
        assert 0 < world.triangle_count < 200_000


def test_instances_match_the_pure_instance_table(houses):
    with World(houses[15], resolved(houses[15])) as world:
        assert [(i.id, i.name, i.mask_color) for i in world.instances] == \
               [(i.id, i.name, i.mask_color) for i in build_instances(houses[15])
                + dressing_instances(houses[15], world.state.seed)]


def test_collision_boxes_fit_the_object_boxes(houses):
    house = houses[20]
    settings = resolved(house)
    filled = []
    with World(house, settings) as world:
        for obj in house.objects:
            if obj.type in ("Door", "Station"):
                continue
            box = obj.box(settings.models[obj.id])
            lo, hi = pb.getAABB(world.instance(obj.id).body, physicsClientId=world.client)
            bottom, top = box.position[2] - box.size[2] / 2, box.position[2] + box.size[2] / 2
            assert lo[2] == pytest.approx(bottom, abs=0.02), obj.id        # on the box's floor
            assert hi[2] <= top + 0.02, obj.id                             # inside it
            filled.append((hi[2] - lo[2]) / box.size[2])
    assert np.median(filled) > 0.95                                        # library models fill heights


def test_doors_open_and_close_at_run_time(houses):
    house = houses[15]
    with World(house, resolved(house)) as world:
        door, appearance = house.doors[0], Appearance(world)
        appearance.set_door(door.id, False)
        closed_z = world.object_pose(door.id)[0][2]
        nx, ny = -math.sin(door.yaw), math.cos(door.yaw)          # across the doorway
        x, y = door.position[:2]

        def ray_hit() -> int:
            return pb.rayTest([x - 0.6 * nx, y - 0.6 * ny, 1.0], [x + 0.6 * nx, y + 0.6 * ny, 1.0],
                              physicsClientId=world.client)[0][0]

        assert ray_hit() == world.instance(door.id).body
        appearance.set_door(door.id, True)
        assert ray_hit() == -1
        assert world.object_pose(door.id)[0][2] < closed_z - 10
        assert world.state.doors[door.id] is True


def test_model_swap_rebuilds_the_body(houses):
    house = houses[15]
    settings = resolved(house)
    with World(house, settings) as world:
        inst = world.instance("Bed_0")
        before, shown = inst.body, record(world.visuals[inst.body].model).id
        Appearance(world).set_object_model("Bed_0", (settings.models["Bed_0"] + 1) % 3)
        after = world.instance("Bed_0").body
        assert after != before and before not in world.visuals
        assert record(world.visuals[after].model).id != shown
        assert world.body_to_instance_lut()[world.instance("Bed_0").body] == inst.id


def test_the_world_has_no_visual_shapes_of_its_own(houses):
    """The World's bodies only collide; the TinyRenderer draws its own visual-only mirror of them, and
    leaves the world's bodies (which pybullet would draw as their collision shapes) out of its images."""
    from ravh_sim.render.tiny_scene import TinyScene
    with World(houses[20], resolved(houses[20])) as world:
        shown = [inst for inst in world.instances if inst.body in world.visuals]     # dressing: some unshown
        bodies = [world.ground, *(inst.body for inst in shown)]
        before = pb.getNumBodies(physicsClientId=world.client)
        scene = TinyScene.of(world)
        assert TinyScene.of(world) is scene                  # one mirror a world, however many cameras
        mirrored = pb.getNumBodies(physicsClientId=world.client) - before
        assert mirrored == len(world.visuals) > 0
        for body in bodies:
            assert all(shape[7][3] == 0.0 for shape in pb.getVisualShapeData(body, physicsClientId=world.client))
        for inst in shown:
            mirror = next(b for b, i in enumerate(scene.lut) if i == inst.id)
            hit = pb.getVisualShapeData(mirror, physicsClientId=world.client)
            assert len(hit) == 1 and hit[0][7][3] == 1.0
            assert np.allclose(pb.getBasePositionAndOrientation(mirror, physicsClientId=world.client)[0],
                               pb.getBasePositionAndOrientation(inst.body, physicsClientId=world.client)[0])


def test_every_variant_of_every_object_lies_in_its_footprint_box(houses):
    """The footprint's box of an object (position, size, yaw) contains the model the world draws and
    collides with, for every object of every house and every model variant (no dressing: it is laid
    out anew for each set of models, and these are the house's objects)."""
    checked = 0
    for n, house in houses.items():
        settings = resolved(house).changed(dressing="none")
        for variant in range(max(model_count(o) for o in house.objects)):
            models = {o.id: variant for o in house.objects}
            rows = {r["name"]: r for r in make_footprint(house, settings.changed(models=models))["instances"]}
            for obj in house.objects:
                row, placed = rows[obj.id], object_parts(house, obj, variant)
                if obj.id in house.door_by_id:
                    continue                        # the leaf in the doorway, not an upstream box
                lo, hi = placed.extent()
                assert placed.position == pytest.approx(row["position"], abs=1e-4), (n, obj.id, variant)
                assert placed.yaw == pytest.approx(row["yaw"], abs=1e-4), (n, obj.id, variant)
                half = np.asarray(row["size"]) / 2 + 1e-4
                assert (-half <= lo).all() and (hi <= half).all(), (n, obj.id, variant, lo, hi, row["size"])
                checked += 1
    assert checked > 3000
