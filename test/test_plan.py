"""Tests of the plan picture: size, room colours, door states, overlays, determinism."""
from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from ravh_sim.nav.grid import Grid
from ravh_sim.viz.plan import (
    DOOR_CLOSED_RGB,
    FREE_ALPHA,
    FREE_RGB,
    MARGIN,
    MAX_SIDE,
    PATH_RGB,
    PLAN_PAD_M,
    ROOM_COLORS,
    draw_plan,
    render_plan,
    room_color,
    write_plan,
)
from ravh_sim.world.house import available_houses, load_house


def bgr(rgb: tuple[int, int, int]) -> np.ndarray:
    return np.array(rgb[::-1], np.uint8)


@pytest.fixture(scope="module")
def house15():
    return load_house(15)


@pytest.fixture(scope="module")
def plan15(house15):
    return render_plan(house15)


def test_image_size_follows_bounds_and_scale(house15):
    xmin, ymin, xmax, ymax = house15.bounds
    wm, hm = xmax - xmin + 2 * PLAN_PAD_M, ymax - ymin + 2 * PLAN_PAD_M
    sizes = {}
    for scale in (40, 80):
        plan = render_plan(house15, px_per_m=scale)
        f = plan.frame
        assert f.scale == scale
        assert (f.plan_w, f.plan_h) == (math.ceil(wm * scale), math.ceil(hm * scale))
        assert plan.image.shape == (f.height, f.width, 3) and plan.image.dtype == np.uint8
        assert f.to_px(xmin - PLAN_PAD_M, ymax + PLAN_PAD_M) == (MARGIN, f.top)
        sizes[scale] = plan.image.shape[1]
    # the margins and the legend beside the plan do not depend on the scale
    assert sizes[80] - sizes[40] == math.ceil(wm * 80) - math.ceil(wm * 40)


def test_scale_is_capped_on_the_long_side(house15):
    plan = render_plan(house15, px_per_m=400)
    assert max(plan.image.shape[:2]) <= MAX_SIDE
    assert plan.frame.scale < 400


def test_room_types_have_distinct_colours():
    assert len(set(ROOM_COLORS.values())) == len(ROOM_COLORS)


@pytest.mark.parametrize("number", [15, 20, 23])   # houses whose room labels all sit clear
def test_room_label_sits_on_its_room_colour(number):
    house = load_house(number)
    plan = render_plan(house)
    for room in house.rooms:
        u, v = plan.room_labels[room.id]
        assert room.contains(*plan.frame.to_world(u, v)), room.id
        window = plan.image[v - 12:v + 13, u - 25:u + 26].reshape(-1, 3)
        share = (window == bgr(room_color(room.type))).all(axis=1).mean()
        # the text covers part of the window, and in small rooms a little furniture
        assert share > 0.3, (room.id, share)


def door_patch(plan, door, half: int = 1) -> np.ndarray:
    u, v = (int(round(c)) for c in plan.frame.to_px(*door.position[:2]))
    return plan.image[v - half:v + half + 1, u - half:u + half + 1].reshape(-1, 3)


def test_closed_door_shows_closed_colour_and_open_does_not(house15):
    door = house15.door_by_id["Door_0"]
    assert door.default_open
    closed = bgr(DOOR_CLOSED_RGB)
    shut = render_plan(house15, door_open={"Door_0": False})
    assert (door_patch(shut, door) == closed).all(axis=1).all()
    opened = render_plan(house15)
    assert not (door_patch(opened, door, half=6) == closed).all(axis=1).any()


def test_default_door_state_is_used(house15):
    entrance = house15.door_by_id["Door_4"]
    assert not entrance.default_open
    plan = render_plan(house15)
    assert (door_patch(plan, entrance) == bgr(DOOR_CLOSED_RGB)).all(axis=1).all()
    plan = render_plan(house15, door_open={"Door_4": True})
    assert not (door_patch(plan, entrance) == bgr(DOOR_CLOSED_RGB)).all(axis=1).any()


def test_path_overlay_changes_pixels_along_the_path(house15, plan15):
    path = [(8.41, -4.75), (6.0, -4.0), (3.2, -2.3), (1.7, -2.3), (1.7, -5.0)]
    with_path = render_plan(house15, path=path)
    for (x0, y0), (x1, y1) in zip(path, path[1:]):
        u, v = (int(round(c)) for c in with_path.frame.to_px((x0 + x1) / 2, (y0 + y1) / 2))
        assert not np.array_equal(with_path.image[v, u], plan15.image[v, u])
        assert np.array_equal(with_path.image[v, u], bgr(PATH_RGB))


def test_free_space_tints_only_free_cells(house15, plan15):
    data = np.full((20, 20), -1, np.int8)
    data[:, :10] = 0                                    # x in [6, 6.5): free; [6.5, 7): unknown
    grid = Grid(data, (6.0, -5.0), 0.05)
    plan = render_plan(house15, free_space=grid)
    f = plan.frame
    u_free, v = (int(round(c)) for c in f.to_px(6.25, -4.5))
    u_unknown = int(round(f.to_px(6.75, -4.5)[0]))
    tinted = plan15.image[v, u_free] * (1 - FREE_ALPHA) + bgr(FREE_RGB) * FREE_ALPHA
    assert np.abs(plan.image[v, u_free] - tinted).max() <= 2
    assert not np.array_equal(plan.image[v, u_free], plan15.image[v, u_free])
    assert np.array_equal(plan.image[v, u_unknown], plan15.image[v, u_unknown])


def test_model_variant_changes_the_box(house15, plan15):
    obj = next(o for o in house15.objects if len({m.size for m in o.models}) > 1)
    variant = next(i for i, m in enumerate(obj.models) if m.size != obj.box(None).size)
    assert not np.array_equal(draw_plan(house15, models={obj.id: variant}), plan15.image)


def test_poses_are_drawn(house15, plan15):
    image = draw_plan(house15, poses=[(-1.0, -3.0, 0.0)])
    assert not np.array_equal(image, plan15.image)


def test_deterministic(house15):
    kwargs = dict(path=[(8.4, -4.7), (1.7, -2.3)], poses=[(0.0, -6.0, 1.0)], door_open={"Door_2": False})
    assert np.array_equal(draw_plan(house15, **kwargs), draw_plan(house15, **kwargs))


def test_every_house_draws():
    for number in available_houses():
        house = load_house(number)
        plan = render_plan(house)
        assert plan.image.dtype == np.uint8 and plan.image.ndim == 3
        assert max(plan.image.shape[:2]) <= MAX_SIDE
        assert set(plan.room_labels) == {r.id for r in house.rooms}


def test_write_plan_round_trips(tmp_path, plan15):
    target = tmp_path / "nested" / "house15.png"
    write_plan(target, plan15.image)
    assert np.array_equal(cv2.imread(str(target)), plan15.image)
