"""``ravh import-home``: a tiny Sweet Home 3D home built here (two rooms, walls, a door, a window, a bed and
a lamp with a tiny OBJ), its geometry checked against the XML, loaded and built into a world, found by
name and number, and every kind of bad file refused in one line naming the file and the element."""
from __future__ import annotations

import io
import json
import math
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest
from conftest import resolved

from ravh_sim.errors import UserError
from ravh_sim.importers import home as home_module
from ravh_sim.importers import sh3d_archive
from ravh_sim.importers.home import import_home
from ravh_sim.world.house import load_house, resolve_house
from ravh_sim.world.scene import World
from ravh_sim.world.solids import model_count, object_parts

CUBE_VERTICES = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
CUBE_FACES = "f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"
CUBE_OBJ = "# a unit cube, material from Java 3D's defaults\n" + CUBE_VERTICES + "usemtl iris\n" + CUBE_FACES

WALLS = [(0, 0, 800, 0), (800, 0, 800, 300), (800, 300, 0, 300), (0, 300, 0, 0), (400, 0, 400, 300)]


def home_xml(extra: str = "", walls: list = WALLS, prologue: str = "<?xml version='1.0'?>\n") -> str:
    wall_xml = "".join(f"<wall id='w{i}' xStart='{a}' yStart='{b}' xEnd='{c}' yEnd='{d}' height='250' "
                       f"thickness='20' leftSideColor='FF336699'/>\n" for i, (a, b, c, d) in enumerate(walls))
    return prologue + f"""<home version='6500' name='tiny.sh3d' wallHeight='250.0'>
  <property name='Author' value='Test Author'/>
  <property name='License' value='CC0'/>
  <observerCamera attribute='storedCamera' name='Living' x='200' y='150' z='150' yaw='0' pitch='0'/>
  <pieceOfFurniture id='bed' catalogId='eTeks#bed' name='Double bed' creator='t' model='1' x='100' y='120'
    width='140' depth='200' height='60'/>
  <light id='lamp' name='Work lamp' model='1' x='300' y='50' elevation='70' width='20' depth='20' height='40'
    power='0.5'><lightSource x='0.5' y='0.5' z='0.8' color='FFFFFFE0'/></light>
  <doorOrWindow id='door' name='Door' model='1' x='400' y='150' angle='1.5707964' width='90' depth='20'
    height='210'/>
  <doorOrWindow id='window' name='Window' model='1' x='200' y='0' elevation='100' width='100' depth='20'
    height='120'/>
  {wall_xml}
  <room id='r1' name='Chambre' floorColor='FF808080'><point x='0' y='0'/><point x='400' y='0'/>
    <point x='400' y='300'/><point x='0' y='300'/></room>
  <room id='r2' name='Cuisine'><point x='400' y='0'/><point x='800' y='0'/><point x='800' y='300'/>
    <point x='400' y='300'/></room>
  {extra}
</home>
"""


def write_sh3d(path: Path, xml: str | None = None, entries: dict[str, bytes] | None = None) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("Home.xml", home_xml() if xml is None else xml)
        zf.writestr("1", CUBE_OBJ)
        for name, data in (entries or {}).items():
            zf.writestr(name, data)
    return path


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("home")
    done = import_home(write_sh3d(folder / "tiny.sh3d"), folder / "out")
    return done, json.loads(done.path.read_text())


def test_geometry_follows_the_xml(imported):
    done, data = imported
    assert done.name == "tiny" and done.number == home_module.FIRST_NUMBER
    outer = next(w for w in data["walls"] if w["a"] == [0.0, 0.0] and w["b"] == [8.0, 0.0])
    assert math.dist(outer["a"], outer["b"]) == pytest.approx(8.0)        # 800 cm, y flipped
    assert (outer["z0"], outer["z1"], outer["thickness"]) == (0.0, 2.5, 0.2)
    middle = sorted((w for w in data["walls"] if w["a"][0] == 4.0 and w["b"][0] == 4.0), key=lambda w: w["z0"])
    assert [w["kind"] for w in middle] == ["wall", "wall", "lintel"]       # split at the door, a lintel above
    assert middle[2]["z0"] == pytest.approx(2.1)
    house = load_house(done.path)
    assert sorted(r.type for r in house.rooms) == ["Bedroom", "Kitchen"]  # French names
    assert all(r.area == pytest.approx(12.0) for r in house.rooms)
    bedroom = next(r for r in house.rooms if r.type == "Bedroom")
    assert bedroom.own_paint("floor") == "#808080"
    bed = next(o for o in house.objects if o.type == "Bed")
    assert bed.room == bedroom.id
    assert bed.size == pytest.approx((2.0, 1.4, 0.6))                     # depth, width, height
    assert bed.position == pytest.approx((1.0, -1.2, 0.3))
    assert bed.yaw == pytest.approx(-math.pi / 2, abs=1e-4)                        # its front faces down the plan
    assert bed.own_model is not None and bed.own_model.is_file()
    (door,), (window,) = house.doors, house.windows
    assert len(door.rooms) == 2 and door.default_open
    assert door.position[:2] == pytest.approx((4.0, -1.5))
    assert window.position == pytest.approx((2.0, 0.0, 1.6))
    (lamp,) = house.lights
    assert lamp.kind == "lamp" and lamp.intensity == pytest.approx(0.3)
    assert "Test Author" in house.attribution and house.source["license"] == "CC0"
    assert done.views == [("Living", 2.0, -1.5, pytest.approx(-math.pi / 2, abs=1e-4))]


def test_the_world_builds_with_the_homes_own_models(imported):
    done, _ = imported
    house = load_house(done.path)
    bed = next(o for o in house.objects if o.type == "Bed")
    placed = object_parts(house, bed, None)
    assert placed.model is not None                                      # variant 0: the home's model
    lo, hi = placed.extent()
    assert hi - lo == pytest.approx(bed.size, abs=1e-6)                  # stretched to its box
    assert model_count(bed) >= 2                                         # and the library's beds after it
    with World(house, resolved(house)) as world:
        assert world.house.name == "tiny"


def test_found_by_name_and_number(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    from ravh_sim.paths import user_houses_dir
    done = import_home(write_sh3d(tmp_path / "My Flat.sh3d"), user_houses_dir())
    assert done.name == "my-flat"
    assert resolve_house("my-flat") == done.path == resolve_house(str(done.number))
    assert load_house(str(done.path)).name == "my-flat"
    with pytest.raises(UserError, match="my-flat"):
        resolve_house("no-such-home")


def _one_line_error(path: Path, *needles: str) -> None:
    with pytest.raises(UserError) as error:
        import_home(path, path.parent / "out")
    message = str(error.value)
    assert "\n" not in message and str(path) in message
    for needle in needles:
        assert needle in message
    assert not (path.parent / "out").exists() or not any((path.parent / "out").glob("*.json"))


@pytest.mark.parametrize("prologue", [
    "<?xml version='1.0'?>\n<!DOCTYPE home [<!ENTITY big 'x'>]>\n",
    "<?xml version='1.0'?>\n<!ENTITY lol 'lol'>\n"])
def test_refuses_dtd_and_entities(tmp_path, prologue):
    _one_line_error(write_sh3d(tmp_path / "dtd.sh3d", home_xml(prologue=prologue)), "Home.xml")


def test_refuses_a_zip_bomb(tmp_path):
    _one_line_error(write_sh3d(tmp_path / "bomb.sh3d", entries={"2": b"\0" * (4 << 20)}), "bomb")


def test_refuses_names_outside_the_archive(tmp_path):
    _one_line_error(write_sh3d(tmp_path / "escape.sh3d", entries={"../evil.obj": b"v 0 0 0"}), "outside")


def test_refuses_a_model_outside_the_archive(tmp_path):
    xml = home_xml().replace("model='1' x='100'", "model='/etc/passwd' x='100'")
    _one_line_error(write_sh3d(tmp_path / "abs.sh3d", xml), "<pieceOfFurniture id='bed'>", "outside")


def test_refuses_too_many_entries(tmp_path, monkeypatch):
    monkeypatch.setattr(sh3d_archive, "MAX_ENTRIES", 2)
    _one_line_error(write_sh3d(tmp_path / "many.sh3d", entries={"2": b"x"}), "3 entries")


def test_refuses_too_many_walls(tmp_path, monkeypatch):
    monkeypatch.setattr(home_module, "MAX_ITEMS", {**home_module.MAX_ITEMS, "walls": 3})
    _one_line_error(write_sh3d(tmp_path / "walls.sh3d"), "<wall>", "limit")


def test_refuses_a_bad_number_naming_the_element(tmp_path):
    xml = home_xml(walls=[*WALLS[:4], ("abc", 0, 400, 300)])
    _one_line_error(write_sh3d(tmp_path / "nan.sh3d", xml), "<wall id='w4'>", "xStart")


@pytest.mark.parametrize("data", [b"not a zip", None])
def test_refuses_what_is_not_a_home(tmp_path, data):
    path = tmp_path / "bad.sh3d"
    if data is None:                                             # a zip without Home.xml
        buffer = io.BytesIO()
        with zipfile.ZipFile(buffer, "w") as zf:
            zf.writestr("Home", b"java serialisation")
        data = buffer.getvalue()
    path.write_bytes(data)
    _one_line_error(path)


def test_unknown_level_lists_none_for_a_single_level_home(tmp_path):
    with pytest.raises(UserError, match="single level"):
        import_home(write_sh3d(tmp_path / "one.sh3d"), tmp_path / "out", level="Attic")


def test_levels_import_one_at_a_time(tmp_path):
    levels = ("<level id='l0' name='Ground' elevation='0' height='250' elevationIndex='0'/>"
              "<level id='l1' name='Upper' elevation='262' height='250' elevationIndex='0'/>")
    xml = home_xml().replace("<wall ", "<wall level='l0' ").replace("<room ", "<room level='l0' ")
    xml = xml.replace("<pieceOfFurniture ", "<pieceOfFurniture level='l0' ").replace(
        "<doorOrWindow ", "<doorOrWindow level='l0' ").replace("<light ", "<light level='l0' ")
    upstairs = ("<observerCamera attribute='storedCamera' name='Attic view' x='150' y='150' z='400' yaw='0'/>"
                "<observerCamera attribute='storedCamera' name='Garden' x='-500' y='150' z='150' yaw='0'/>"
                "<observerCamera attribute='storedCamera' name='Wall' x='-20' y='150' z='150' yaw='0'/>")
    xml = xml.replace("<observerCamera", levels + upstairs + "<observerCamera")
    upper = ("<room id='u' level='l1' name='Attic'><point x='0' y='0'/><point x='300' y='0'/>"
             "<point x='300' y='300'/><point x='0' y='300'/></room>"
             "<wall id='uw' level='l1' xStart='0' yStart='0' xEnd='300' yEnd='0' height='200' thickness='10'/>")
    path = write_sh3d(tmp_path / "two.sh3d", xml.replace("</home>", upper + "</home>"))
    ground = import_home(path, tmp_path / "out")
    assert (ground.level, ground.levels, ground.counts["rooms"]) == ("Ground", ["Ground", "Upper"], 2)
    assert [v[0] for v in ground.views] == ["Wall", "Living"]       # not upstairs, not in the garden
    assert ground.views[0][1:3] == pytest.approx((0.25, -1.5))        # backed into the wall: moved in
    attic = import_home(path, tmp_path / "out", level="upper")
    assert (attic.name, attic.counts["rooms"], attic.counts["walls"]) == ("two-upper", 1, 1)
    assert [v[0] for v in attic.views] == ["Attic view"]
    assert attic.number != ground.number
    with pytest.raises(UserError, match="Ground, Upper"):
        import_home(path, tmp_path / "out", level="cellar")


def test_own_model_file_stays_beside_the_house(imported, tmp_path):
    done, data = imported
    bad = dict(data)
    bad["objects"] = [dict(o) for o in data["objects"]]
    first = next(o for o in bad["objects"] if "model_file" in o)
    first["model_file"] = "../elsewhere/x.npz"
    path = done.path.parent / "escaping.json"
    path.write_text(json.dumps(bad))
    with pytest.raises(UserError, match="model_file"):
        load_house(path)


WINDOW_OBJ = ("# a window: a white frame (a box) and a half see-through pane (Sweet Home 3D's flltgrey)\n"
              + CUBE_VERTICES + "v 0.1 0.5 0.1\nv 0.9 0.5 0.1\nv 0.9 0.5 0.9\nv 0.1 0.5 0.9\n"
              + "usemtl white\n" + CUBE_FACES + "usemtl flltgrey\nf 9 10 11 12\n")


def test_a_window_pane_is_clear_glass_whatever_its_colour(tmp_path):
    xml = home_xml().replace("<doorOrWindow id='window' name='Window' model='1'",
                             "<doorOrWindow id='window' name='Window' model='2' color='FF87D6DF'")
    done = import_home(write_sh3d(tmp_path / "w.sh3d", xml, {"2": WINDOW_OBJ.encode()}), tmp_path / "out")
    house = load_house(done.path)
    window = next(o for o in house.objects if o.id == house.windows[0].id)
    assert window.own_model is not None
    with np.load(window.own_model) as npz:
        materials = [m["name"] for m in json.loads(str(npz["record"]))["materials"]]
    assert materials == ["white"]                        # the pane left out: every sensor sees through it


def _import_into_user_folder(tmp_path, monkeypatch, name: str = "tiny"):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    from ravh_sim.paths import user_houses_dir
    return import_home(write_sh3d(tmp_path / f"{name}.sh3d"), user_houses_dir())


def test_dataset_build_houses_take_names_numbers_and_ranges(tmp_path, monkeypatch):
    from ravh_sim.raids.build import parse_houses
    done = _import_into_user_folder(tmp_path, monkeypatch)
    assert parse_houses(f"2,tiny,{done.number}") == [2, done.number]
    assert parse_houses("1-3") == [1, 2, 3]
    with pytest.raises(UserError, match="tiny"):        # the valid names are listed
        parse_houses("1,no-such-home")
    with pytest.raises(UserError, match="import-home"):   # a house file elsewhere has no number to find it by
        parse_houses(str(_copy(done.path, tmp_path / "copy")))


def _copy(path: Path, folder: Path) -> Path:
    """A copy of a house file, and its models, in another folder."""
    shutil.copytree(path.parent, folder)
    return folder / path.name


def test_bench_and_localization_take_a_name(tmp_path, monkeypatch, capsys):
    from ravh_sim import bench
    from ravh_sim.cli import main
    from ravh_sim.eval import table4
    done = _import_into_user_folder(tmp_path, monkeypatch)
    asked: list = []
    monkeypatch.setattr(bench, "run", lambda what, houses: asked.append((what, houses)) or {})
    assert main(["bench", "load", "--houses", "tiny", "20"]) == 0
    assert asked == [("load", [done.number, 20])]
    monkeypatch.setattr(table4, "run_table4", lambda house, *a, **k: asked.append(house) or {})
    assert main(["eval", "localization", "--house", "tiny", "--out", str(tmp_path / "t4"), "--json"]) == 0
    assert asked[-1] == done.number


def test_a_direct_raid_records_the_homes_name_and_attribution(tmp_path, monkeypatch):
    from ravh_sim.raids.direct import PosesSpec, record
    done = _import_into_user_folder(tmp_path, monkeypatch)
    house = load_house("tiny")
    x, y, _ = house.station.position
    summary = record(tmp_path / "raid", "tiny", PosesSpec(((x, y, 0.0),)), seed=1, renderer="tiny")
    assert summary["captures"] == 1
    meta = json.loads((tmp_path / "raid" / "dataset.json").read_text())
    assert meta["house"] == done.number and meta["raid"]["house_name"] == "tiny"
    assert "Test Author" in meta["raid"]["attribution"]
