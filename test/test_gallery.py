"""The object gallery's photographer: each showcase object seen whole, framed, from free space, repeatably."""
from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest

from ravh_sim.nav.navigation import Navigation
from ravh_sim.raids.gallery import LABEL_PX, _preset, dressing_gallery, object_views
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.camera import SmartCamera
from ravh_sim.world.house import load_house
from ravh_sim.world.scene import World

TYPES = ("Sofa", "Refrigerator", "Tv", "Closet")
MAX_EDGE_SHARE = 0.05        # of the object's outline on the frame's edge: whole, not cut by the frame
MIN_FILL = 0.05              # share of the frame the object's own pixels cover


@pytest.fixture(scope="module")
def house15():
    house = load_house(15)
    profile = load_profile()
    with World(house, _preset(house, 0, 0)) as world:
        camera = SmartCamera(world, replace(profile.camera, quality="fast"))
        views = object_views(world, camera, TYPES)
        again = object_views(world, camera, TYPES)
        free = Navigation(house, world.state, profile).map()
        seen = {}
        for name, shot in views:
            capture = camera.capture(*shot.pose)
            seen[name] = capture.instance == world.instance(shot.object_id).id
        camera.close()
        yield views, again, free, seen


def test_each_type_gets_a_pose_in_free_space_repeatably(house15):
    views, again, free, _ = house15
    assert [name for name, _ in views] == list(TYPES)
    assert [shot.pose for _, shot in views] == [shot.pose for _, shot in again]
    for name, shot in views:
        assert free.is_free(shot.pose[0], shot.pose[1]), name


def test_the_object_is_whole_in_the_frame_and_fills_a_share_of_it(house15):
    views, _, _, seen = house15
    for name, shot in views:
        mask = seen[name]
        rows = mask.any(axis=1).nonzero()[0]
        cols = mask.any(axis=0).nonzero()[0]
        assert len(rows), name
        edge = mask[0].sum() + mask[-1].sum() + mask[:, 0].sum() + mask[:, -1].sum()
        outline = 2 * (rows[-1] - rows[0] + 1 + cols[-1] - cols[0] + 1)
        assert edge / outline <= MAX_EDGE_SHARE, (name, edge / outline)
        assert mask.mean() >= MIN_FILL, (name, mask.mean())
        assert shot.blocked < 0.2 and abs(shot.azimuth) <= 1.6, (name, shot)


def test_the_dressing_sheet_shows_the_dressing_beside_the_bare_house(tmp_path):
    """``ravh gallery --dressing``: a 2 x 2 sheet from one pose; the lived-in panels differ from the bare
    ones (by day and at night) where dressing is in view, and nowhere else much."""
    house = load_house(23)
    pose = (2.3, -10.4, -1.8)                   # the living room's sofa and table (the README's sheet)
    sheet = cv2.cvtColor(cv2.imread(str(dressing_gallery(23, tmp_path / "sheet.png", pose=pose))), cv2.COLOR_BGR2RGB)
    width, height = 640, 480
    assert sheet.shape[1] == 2 * width and sheet.shape[0] == 2 * (height + LABEL_PX)
    with World(house, _preset(house, 0, 0, "lived-in")) as world:
        dressing = {i.id for i in world.instances if i.kind == "dressing"}
        seen = SmartCamera(world, load_profile().camera).capture(*pose).instance
    shows_dressing = np.isin(seen, list(dressing))
    assert shows_dressing.mean() > 0.01
    day_bare, day_dressed = sheet[:height, :width], sheet[:height, width:]
    changed = np.any(np.abs(day_bare.astype(int) - day_dressed.astype(int)) > 24, axis=-1)
    assert changed[shows_dressing].mean() > 0.5 and changed[~shows_dressing].mean() < 0.1
    night = sheet[height + LABEL_PX:2 * height + LABEL_PX]
    assert np.mean(np.any(night[:, :width] != night[:, width:], axis=-1)) > 0.01
