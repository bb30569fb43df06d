"""Dressing (ravh_sim.world.dressing): seeded, reproducible from the footprint, every object resting on
its support or hung on its wall and clear of its neighbours, as pybullet's own rays find them (not the
placement code's numbers), big things colliding and rugs not, in masks, and changed at run time all or
nothing."""
from __future__ import annotations

import json
import math

import numpy as np
import pybullet as pb
import pytest

from ravh_msgs_py.appearance import parse
from ravh_msgs_py.query import QueryError
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.camera import SmartCamera
from ravh_sim.world import dressing as dressing_module
from ravh_sim.world.appearance import Appearance
from ravh_sim.world.dressing import dressing, slots
from ravh_sim.world.footprint import load_footprint, make_footprint, write_footprint
from ravh_sim.world.ground_truth import GroundTruth
from ravh_sim.world.scene import World
from ravh_sim.world.settings import load_settings, resolve
from ravh_sim.world.state import WorldState

HUNG = ("Picture", "Towel", "Curtain", "Blind")     # on a wall or at a window; the rest rest on something
TOUCH_M = 0.004               # a support within this below an object's bottom (behind a hung one's back)
INSIDE_M = 0.002              # nothing of a neighbour may reach this far into an object
PROFILE = load_profile("giraff")


def _settings(house, level: str, seed: int = 0):
    cfg = load_settings()
    cfg["dressing"] = level
    return resolve(cfg, house, seed)


def _rows(footprint: dict) -> list[dict]:
    return [r for r in footprint["instances"] if r["kind"] == "dressing"]


@pytest.mark.parametrize("number", [15, 23])
def test_dressing_is_seeded_and_tidy_is_a_subset(houses, number):
    house = houses[number]
    lived = _rows(make_footprint(house, _settings(house, "lived-in")))
    tidy = _rows(make_footprint(house, _settings(house, "tidy")))
    assert lived and tidy and len(tidy) < len(lived)
    assert all(r["dressing"] is True and "dressing" in r["tags"] for r in lived)
    assert _rows(make_footprint(house, _settings(house, "lived-in"))) == lived      # same seed, same world
    assert {json.dumps(r, sort_keys=True) for r in tidy} <= {json.dumps(r, sort_keys=True) for r in lived}
    other = _rows(make_footprint(house, _settings(house, "lived-in", seed=5)))
    assert [(r["name"], r["position"]) for r in other] != [(r["name"], r["position"]) for r in lived]
    assert not _rows(make_footprint(house, _settings(house, "none")))
    ids = {o.id for o in house.objects}
    assert not ids & {r["name"] for r in lived}, "a dressing id repeats one of the house's"
    first = max(r["id"] for r in make_footprint(house, _settings(house, "none"))["instances"])
    assert min(r["id"] for r in lived) > first, "dressing instances come after the house's"


def test_footprint_rebuilds_the_same_world(houses, tmp_path):
    house = houses[15]
    settings = _settings(house, "lived-in", seed=3)
    path = tmp_path / "footprint.json"
    write_footprint(make_footprint(house, settings), path)
    number, again = load_footprint(path)
    assert number == 15 and again.dressing == "lived-in"
    assert make_footprint(house, again) == json.loads(path.read_text())
    with World(house, again) as world:
        for row in _rows(json.loads(path.read_text())):
            position, _ = world.object_pose(row["name"])
            assert np.allclose(position, row["position"], atol=2e-4)


def test_a_record_without_dressing_is_the_bare_house(houses):
    house = houses[15]
    record = _settings(house, "lived-in").model_dump(mode="json")
    del record["dressing"]
    assert type(_settings(house, "none")).model_validate(record).dressing == "none"


@pytest.fixture(scope="module")
def dressed_world(houses):
    house = houses[15]
    with World(house, _settings(house, "lived-in")) as world:
        yield world


def _quaternion(rot: np.ndarray) -> list[float]:
    yaw = math.atan2(rot[1, 0], rot[0, 0])
    return [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]


def _frame(world: World, name: str):
    (x, y, z), orn = world.object_pose(name)
    rot = np.array(pb.getMatrixFromQuaternion(orn)).reshape(3, 3)
    return np.array([x, y, z]), rot


def test_every_dressing_object_rests_on_its_support_and_clear_of_neighbours(dressed_world):
    """Rays through pybullet, each object hidden from its own rays: resting ones down through their
    footprint from just under their top (the highest hit is within TOUCH_M under the bottom, and no
    hit lies above it); hung ones from just behind their front towards the wall (the nearest hit
    lies within TOUCH_M behind the back, none in front of it). Rugs have no collider: the floor."""
    world = dressed_world
    shown = [d for d in dressing(world.house, world.state.models, "lived-in", world.state.seed)]
    assert len(shown) >= 10
    failures = []
    for d in shown:
        centre, rot = _frame(world, d.id)
        body = world.instance(d.id).body
        # out of its own rays' way (ray_mask hides at most 23 bodies): parked below the house meanwhile
        pb.resetBasePositionAndOrientation(body, [0, 0, -100], [0, 0, 0, 1], physicsClientId=world.client)
        depth, width, height = d.slot.size
        u = np.linspace(-depth / 2 + 0.003, depth / 2 - 0.003, 5)
        v = np.linspace(-width / 2 + 0.003, width / 2 - 0.003, 5)
        w = np.linspace(-height / 2 + 0.003, height / 2 - 0.003, 5)
        if d.slot.type in HUNG:          # from the front (local +x) back along -x
            grid = np.array([(depth / 2 - 0.001, b, c) for b in v for c in w])
            starts = centre + grid @ rot.T
            ends = starts - rot[:, 0] * 0.2
            _, points = world.cast_rays(starts, ends)
            gap = (points - starts) @ -rot[:, 0] - (depth - 0.001)       # distance behind the back
        else:
            grid = np.array([(a, b, height / 2 - 0.001) for a in u for b in v])
            starts = centre + grid @ rot.T
            ends = starts - np.array([0.0, 0.0, height + 0.2])
            _, points = world.cast_rays(starts, ends)
            gap = (centre[2] - height / 2) - points[:, 2]                    # distance below the bottom
        pb.resetBasePositionAndOrientation(body, list(centre), _quaternion(rot),
                                           physicsClientId=world.client)
        gap = gap[np.isfinite(gap)]
        if not len(gap) or gap.min() > TOUCH_M or gap.min() < -INSIDE_M:
            failures.append((d.id, d.slot.support, float(gap.min()) if len(gap) else None))
    assert not failures, f"floating or interpenetrating (id, support, nearest gap m): {failures}"


def test_dressing_objects_do_not_overlap_each_other(dressed_world):
    """No two dressing objects' boxes overlap (by more than INSIDE_M)."""
    from shapely.geometry import Polygon
    world = dressed_world
    boxes = []
    for d in dressing(world.house, world.state.models, "lived-in", world.state.seed):
        (x, y, z), yaw = d.position, d.yaw
        dx, dy, dz = (s / 2 - INSIDE_M for s in d.slot.size)
        c, s = math.cos(yaw), math.sin(yaw)
        corners = ((-dx, -dy), (dx, -dy), (dx, dy), (-dx, dy))
        outline = Polygon([(x + c * a - s * b, y + s * a + c * b) for a, b in corners])
        boxes.append((d.id, outline, z - dz, z + dz))
    for i, (a, pa, a0, a1) in enumerate(boxes):
        for b, pb_, b0, b1 in boxes[i + 1:]:
            assert not (a0 < b1 and b0 < a1 and pa.intersects(pb_) and pa.intersection(pb_).area > 1e-6), (a, b)


def test_big_things_collide_and_rugs_do_not(dressed_world):
    world = dressed_world
    for d in dressing(world.house, world.state.models, "lived-in", world.state.seed):
        shapes = pb.getCollisionShapeData(world.instance(d.id).body, -1, physicsClientId=world.client)
        assert bool(shapes) == (d.slot.type != "Rug"), d.id


def test_rugs_lie_under_feet_never_under_a_base(houses):
    """Rays up through each rug's band on a 1 cm grid, from just over the ground (pybullet's colliders;
    rugs have none): what stands in it are islands no wider than a foot (FOOT_SIZE and a grid cell):
    legs, not a bed's base or a cabinet's plinth. In house 2 a rug has a bed's or a nightstand's feet
    on it."""
    import cv2
    house = houses[2]
    stood_on = 0
    with World(house, _settings(house, "lived-in")) as world:
        rugs = [d for d in dressing(house, world.state.models, "lived-in", world.state.seed) if d.slot.type == "Rug"]
        assert rugs
        for d in rugs:
            (x, y, z), yaw = d.position, d.yaw
            depth, width, height = d.slot.size
            u, v = np.meshgrid(np.arange(-depth / 2, depth / 2, 0.01), np.arange(-width / 2, width / 2, 0.01))
            c, s = math.cos(yaw), math.sin(yaw)
            xy = np.stack([x + c * u - s * v, y + s * u + c * v], axis=-1).reshape(-1, 2)
            floor = house.room(d.slot.room).floor_z
            bottom = np.column_stack([xy, np.full(len(xy), floor - 0.0005)])
            up = [0.0, 0.0, z + height / 2 - floor]
            hit = np.concatenate([world.cast_rays(part, part + up)[0] for part in np.array_split(bottom, 4)])
            occupied = (hit >= 0).reshape(u.shape).astype(np.uint8)
            count, _, stats, _ = cv2.connectedComponentsWithStats(occupied, connectivity=8)
            stood_on += count > 1                                   # label 0: the free floor
            widest = stats[1:, [cv2.CC_STAT_WIDTH, cv2.CC_STAT_HEIGHT]].max(initial=0) * 0.01
            assert widest <= dressing_module.FOOT_SIZE + 0.02, (d.id, widest)
    assert stood_on >= 1


def test_masks_show_dressing_instances(dressed_world):
    world = dressed_world
    camera = SmartCamera(world, PROFILE.camera)
    dressed = {world.instance(d.id).id: d for d in dressing(world.house, world.state.models, "lived-in",
                                                            world.state.seed)}
    seen: set[int] = set()
    for d in list(dressed.values())[:12]:
        x, y, _ = d.position
        room = world.house.room(d.slot.room)
        for k in range(12):
            a = k * math.pi / 6
            px, py = x + 1.4 * math.cos(a), y + 1.4 * math.sin(a)
            if room.contains(px, py):
                capture = camera.capture(px, py, a + math.pi)
                seen |= set(np.unique(capture.instance).tolist()) & set(dressed)
                break
    camera.close()
    assert len(seen) >= 3, "the camera shows dressing objects in its instance image"


def test_ground_truth_marks_dressing_and_keeps_the_paper_counts(houses):
    house = houses[15]
    bare = GroundTruth(house, WorldState(_settings(house, "none")))
    dressed = GroundTruth(house, WorldState(_settings(house, "lived-in")))
    counts, bare_counts = dressed.answer({"query": "counts"})["result"], bare.answer({"query": "counts"})["result"]
    assert counts["objects"] == bare_counts["objects"] and counts["objects_by_type"] == bare_counts["objects_by_type"]
    assert counts["dressing"] > 0 and bare_counts["dressing"] == 0
    tagged = dressed.answer({"query": "objects_with_tag", "tag": "dressing"})["result"]
    assert len(tagged) == counts["dressing"] and all(o["dressing"] and o["support"] for o in tagged)
    one = dressed.answer({"query": "object", "id": tagged[0]["id"]})
    assert one["ok"] and one["result"]["instance_id"] == tagged[0]["instance_id"]


def test_changing_dressing_at_run_time_is_all_or_nothing(houses, monkeypatch):
    house = houses[15]
    with World(house, _settings(house, "none")) as world:
        appearance = Appearance(world)
        assert not world.visuals.keys() & {i.body for i in world.instances if i.kind == "dressing"}
        appearance.change(parse({"dressing": "lived-in"}))
        assert world.state.dressing == "lived-in"
        shown = {i.name for i in world.instances if i.kind == "dressing" and i.body in world.visuals}
        assert shown == {r["name"] for r in _rows(make_footprint(house, world.state.settings()))}
        appearance.change(parse({"dressing": "tidy"}))
        tidy = {i.name for i in world.instances if i.kind == "dressing" and i.body in world.visuals}
        assert tidy < shown
        before = world.state.settings()
        door = next(iter(before.doors))
        real = World.dress

        def broken(self, level, models):
            if level == "lived-in":
                raise RuntimeError("disk full")
            real(self, level, models)

        monkeypatch.setattr(World, "dress", broken)
        with pytest.raises(RuntimeError):
            appearance.change(parse({"dressing": "lived-in", "doors": {door: not before.doors[door]}}))
        assert world.state.settings() == before
        assert {i.name for i in world.instances if i.kind == "dressing" and i.body in world.visuals} == tidy
        monkeypatch.setattr(World, "dress", real)
        with pytest.raises(QueryError):
            appearance.change(parse({"dressing": "messy"}))


def test_slots_do_not_depend_on_models(houses):
    house = houses[23]
    settings = _settings(house, "lived-in")
    assert slots(house, 0) == slots(house, 0)
    ids = [s.id for s in slots(house, settings.seed)]
    assert len(ids) == len(set(ids))
    assert dressing_module.LEVELS == ("none", "tidy", "lived-in")


def test_every_dressing_type_has_a_semantic_class():
    from ravh_sim.dataset.coco import SEMANTIC_CLASSES
    specs = [s for group in dressing_module.SUPPORTS.values() for s in group] + [
        dressing_module.RUG, dressing_module.CURTAIN, dressing_module.BLIND, dressing_module.FLOOR_PLANT,
        dressing_module.WALL_ART, dressing_module.TOWEL]
    assert all(s.type in SEMANTIC_CLASSES for s in specs)


def test_soft_furnishings_dress_beds_and_sofas(houses):
    """Pillows and a duvet on beds, cushions and a throw on sofas (made in soft_furnishings), windows,
    rugs and dining places dressed; counts above what houses 15 and 23 gave when this was measured
    (15 + 23: 3 pillows, 3 duvets, 6 cushions, 2 throws, 15 curtains or blinds of 17 windows, 17 plates),
    each soft model inside its box and the same from its id."""
    from collections import Counter

    from ravh_sim.world import soft_furnishings
    placed: Counter[str] = Counter()
    windows = 0
    for number in (15, 23):
        house = houses[number]
        settings = _settings(house, "lived-in")
        shown = dressing(house, settings.models, "lived-in", settings.seed)
        placed += Counter(d.slot.type for d in shown)
        windows += len(house.windows)
        for d in shown:
            if soft_furnishings.is_soft(d.slot.model_id):
                mesh = d.placed().model
                assert mesh is not None and d.slot.type in ("Pillow", "Duvet", "Cushion", "Throw")
                assert np.allclose(np.ptp(mesh.vertices, axis=0), d.slot.size, atol=1e-6)
                again = soft_furnishings.model(d.slot.model_id, d.slot.size)
                assert np.array_equal(again.vertices, mesh.vertices)
    assert placed["Pillow"] >= 3 and placed["Duvet"] >= 3 and placed["Cushion"] >= 6 and placed["Throw"] >= 2
    assert placed["Curtain"] + placed["Blind"] >= 0.8 * windows
    assert placed["Plate"] >= 12 and placed["Rug"] >= 2


def test_at_most_two_bottles_a_worktop(houses):
    from collections import Counter
    house = houses[23]
    settings = _settings(house, "lived-in")
    per = Counter(d.slot.support for d in dressing(house, settings.models, "lived-in", settings.seed)
                  if d.slot.type == "Bottle")
    assert per and max(per.values()) <= 2


def _shelf_books(house, seed: int = 0):
    settings = _settings(house, "lived-in", seed)
    return [d for d in dressing(house, settings.models, "lived-in", settings.seed)
            if d.slot.type == "Book" and dressing_module._support_kind(house.object(d.slot.support)) == "Shelf"]


def test_books_stand_in_rows_on_bookcase_boards(houses):
    """House 15's bookcases hold rows of books on several boards, inside the case: each row's footprint
    on its board (dense vertical lines find the board at its bottom) and nothing of the case inside
    it (so clear of the board above); each row several books standing side by side."""
    house = houses[15]
    rows = _shelf_books(house)
    assert len(rows) >= 4
    boards = {(d.slot.support, round(d.position[2] - d.slot.size[2] / 2, 2)) for d in rows}
    assert len(boards) >= 3, "rows on several boards, not only on top"
    scene = dressing_module._Scene(house, _settings(house, "lived-in").models)
    inside = 0
    for d in rows:
        depth, width, height = d.slot.size
        bottom = d.position[2] - height / 2
        points = dressing_module.footprint_points(d.position[:2], (depth, width), d.yaw, 25, 0.003)
        z = dressing_module.crossings(scene.triangles(d.slot.support), points)
        assert not np.any((z > bottom + 0.002) & (z < bottom + height)), f"{d.id} cuts into its case"
        under = np.where(z <= bottom + 0.002, z, -np.inf).max(axis=1)
        assert np.mean(np.abs(under - bottom) < 0.003) > 0.9, f"{d.id} does not rest on its board"
        top = scene.placed[d.slot.support].position[2] + scene.placed[d.slot.support].extent()[1][2]
        inside += bottom < top - 0.05
        model = d.placed().model
        assert model is not None and model.face_attributes["piece"].max() + 1 >= 5, "a row of books"
        assert np.ptp(model.vertices[:, 2]) > np.ptp(model.vertices[:, 0]) / 2
    assert inside >= 3, "rows stand inside the case, between its boards"


def test_desks_hold_short_stacks_of_books(houses):
    """Books on desks and tables lie flat in stacks of 2-4, each book flatter than it is wide."""
    from ravh_sim.world import made_objects
    stacks = []
    for number in (15, 23):
        house = houses[number]
        settings = _settings(house, "lived-in")
        stacks += [d for d in dressing(house, settings.models, "lived-in", settings.seed)
                   if d.slot.type == "Book" and house.object(d.slot.support).type in ("Desk", "Table")]
    assert len(stacks) >= 4
    for d in stacks:
        assert made_objects.is_made(d.slot.model_id) and d.slot.size[2] < made_objects.ROW_HEIGHT
        model = d.placed().model
        assert model is not None
        pieces = model.face_attributes["piece"]
        assert 2 <= pieces.max() + 1 <= 4
        for k in range(pieces.max() + 1):
            extent = np.ptp(model.vertices[np.unique(model.faces[pieces == k])], axis=0)
            assert extent[2] < min(extent[:2]) / 2, "lying flat"


@pytest.mark.parametrize("kind", ["book", "dish_rack"])
def test_made_models_bound_their_box_and_are_seeded(kind):
    """Every made model fills exactly its box, stays small, shows two materials or more (pages and
    covers; tray, plates and cups), and rebuilds the same from its id and box."""
    from ravh_sim.world import made_objects
    sizes = {"book": [(0.2, 0.45, 0.22), (0.2, 0.26, 0.13), (0.26, 0.2, 0.1)], "dish_rack": [(0.42, 0.36, 0.24)]}
    for record in made_objects.records(f"Dressing/{kind}"):
        for size in sizes[kind]:
            model = made_objects.model(record.id, size)
            assert np.allclose(np.ptp(model.vertices, axis=0), size, atol=1e-9)
            assert np.allclose(model.vertices.min(axis=0), -np.asarray(size) / 2, atol=1e-9)
            assert len(model.faces) < 600 and model.is_winding_consistent
            materials = model.face_attributes["material"]
            assert len(np.unique(materials)) >= 2 and materials.max() < len(model.metadata["record"].materials)
            again = made_objects.model.__wrapped__(record.id, size)
            assert np.array_equal(again.vertices, model.vertices) and np.array_equal(again.faces, model.faces)


def test_a_kitchen_has_one_dish_rack_by_its_sink(houses):
    house = houses[15]
    settings = _settings(house, "lived-in")
    racks = [d for d in dressing(house, settings.models, "lived-in", settings.seed) if d.slot.type == "DishRack"]
    sinks = [o for o in house.objects if o.type == "Sink"]
    assert len(racks) == len(sinks) == 1
    assert house.object(racks[0].slot.support).room == sinks[0].room


def test_book_rows_and_stacks_are_seeded(houses):
    house = houses[15]
    first = [(d.id, d.slot.model_id, d.position, d.yaw) for d in _shelf_books(house)]
    assert first == [(d.id, d.slot.model_id, d.position, d.yaw) for d in _shelf_books(house)]
    assert first != [(d.id, d.slot.model_id, d.position, d.yaw) for d in _shelf_books(house, seed=5)]


def test_wall_art_hangs_framed_pictures_painted_here(houses):
    """Every wall art variant fills its box, shows its picture on the front (texture coordinates over
    0..1 on the face at the front, recessed behind a frame where it has one), its picture is a real
    image (not one flat colour, different between variants), painted once into the asset cache and
    rebuilt the same; houses 15 and 23 hang some, and their own pictures are wall art too, not all one."""
    import cv2

    from ravh_sim.world import made_art
    from ravh_sim.world.solids import object_parts
    size = made_art.SIZE
    pictures = []
    for record in made_art.records("Dressing/wall_art"):
        model = made_art.model.__wrapped__(record.id, size)
        assert np.allclose(np.ptp(model.vertices, axis=0), size, atol=1e-9) and model.is_winding_consistent
        materials = model.face_attributes["material"]
        picture = np.flatnonzero(materials == 2)
        texture = model.metadata["record"].materials[2].texture
        assert texture and len(picture)
        corners = model.vertices[model.faces[picture]].reshape(-1, 3)
        uv = np.asarray(model.visual.uv)[model.faces[picture]].reshape(-1, 2)
        front = corners[:, 0] == corners[:, 0].max()
        assert np.allclose(uv[front].min(axis=0), 0) and np.allclose(uv[front].max(axis=0), 1)
        assert (corners[:, 0].max() < size[0] / 2) == (made_art._presentation(int(record.id.split("/")[-1]))[0]
                                                      is not None)
        image = cv2.imread(texture)
        assert image.shape[:2] == made_art.ART_TEXELS[::-1] and image.std() > 10
        pictures.append(image)
        again = made_art.model.__wrapped__(record.id, size)
        assert np.array_equal(again.vertices, model.vertices)
    assert len({p.tobytes() for p in pictures}) == len(pictures) == made_art.VARIANTS
    painted = made_art.painting(3)
    written = painted.stat().st_mtime_ns
    assert made_art.painting(3) == painted and painted.stat().st_mtime_ns == written
    for number in (15, 23):
        house = houses[number]
        settings = _settings(house, "lived-in")
        art = [d for d in dressing(house, settings.models, "lived-in", settings.seed) if d.slot.type == "Picture"]
        assert art and all(made_art.is_made(d.slot.model_id) for d in art)
        own = [object_parts(house, o, None).model for o in house.objects if o.type == "Picture"]
        assert own and all(m is not None and made_art.is_made(m.metadata["record"].id) for m in own)
        assert len({m.metadata["record"].id for m in own}) > 1, "a house's pictures differ"
