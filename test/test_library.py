"""The furniture library: the importer (on a catalogue the test builds), the committed asset set,
and models fitted into the houses' boxes."""
from __future__ import annotations

import re
import zipfile
from pathlib import Path

import cv2
import numpy as np
import pytest

from ravh_sim.paths import FURNITURE_DIR
from ravh_sim.world import library
from ravh_sim.world.furniture import OBJECT_TYPES
from ravh_sim.world.furniture_import import RULES, TEXTURE_TEXELS, Rule, import_furniture, read_properties
from ravh_sim.world.library import LibraryCatalog, kind_of, models_of
from ravh_sim.world.solids import model_count, object_parts

UPSTREAM_VARIANTS = {"Armchair": 4, "Bed": 5, "Cabinet": 4, "Chair": 4, "Closet": 4, "Decoration": 3, "Desk": 2,
                     "Dresser": 2, "Drying": 3, "KitchenFurniture": 4, "Lamp": 4, "Laptop": 2, "Light": 2,
                     "Nightstand": 3, "Refrigerator": 2, "Shelf": 3, "Sofa": 4, "Standard": 4, "Stool": 4,
                     "Table": 4, "Towel": 4, "Tv": 2, "Washbasin": 2}
"""Library types whose upstream objects come in several model variants (house data)."""
FEWER_THAN_THREE = {"Sink": "the catalogues hold two kitchen sinks",
                    "Standard/tv": "two TV stands within the triangle budget"}
PROCEDURAL = {"Counter": "a worktop is cut to the units under it", "Door": "a leaf in its doorway",
              "Wall": "a window frame in its wall opening", "Picture": "no framed pictures in the catalogues",
              "Mirror": "no wall mirrors in the catalogues", "Pouf": "one ottoman only in the catalogues",
              "Station": "the robot's own dock",
              "Keyboard": "the catalogues' keyboard is a piano keyboard",
              "Lighter": "no wall sconces in the catalogues",
              "Toothbrush": "no toothbrushes in the catalogues"}
"""Types drawn by ravh_sim.world.furniture, with the reason the library has no model of them."""


# --- the importer, on a catalogue built here ---------------------------------------------------

def _chair_obj(back_z: float) -> str:
    """A Sweet Home 3D-style chair in arbitrary units (y up, front towards +z): a seat box
    (material 'fabric', textured), a tall back slab at the back (-z) and a clear glass panel."""
    def cube(x0, x1, y0, y1, z0, z1):
        v = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
        quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        return v, quads
    lines, offset = ["mtllib chair.mtl"], 0
    for material, (v, quads) in (("fabric", cube(0, 40, 40, 45, 0, 40)), ("wood", cube(0, 40, 45, back_z, 0, 5)),
                                 ("glass", cube(0, 40, 0, 40, 39, 40))):
        lines += [f"v {x} {y} {z}" for x, y, z in v] + ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1", f"usemtl {material}"]
        lines += ["f " + " ".join(f"{offset + i + 1}/{k + 1}" for k, i in enumerate(q)) for q in quads]
        offset += len(v)
    return "\n".join(lines) + "\n"


MTL = """newmtl fabric
Kd 0.8 0.8 0.8
Ns 4
map_Kd weave.png
newmtl wood
Kd 0.5 0.3 0.1
Ns 30
newmtl glass
Kd 0.9 0.9 0.9
d 0.1
"""


def build_catalogue(path: Path) -> Path:
    """A two-model .sh3f: a chair (back at -z, 40 x 40 x 90 cm) and a table nobody asks for."""
    texture = cv2.imencode(".png", np.tile(np.arange(0, 250, 250 / 1024, dtype=np.uint8), (1024, 1))[..., None]
                           .repeat(3, axis=2))[1].tobytes()
    properties = "\n".join([
        "id=Test#Catalogue", "license=Creative Commons Attribution 3.0 license", "",
        "id#1=Test#chair1", "name#1=Chair", "category#1=Living room", "model#1=/chair1/chair.obj",
        "width#1=40", "depth#1=45", "height#1=90", "creator#1=Jane Modeller \\u00e9",
        "id#2=Test#table1", "name#2=Garden table", "category#2=Exterior", "model#2=/chair1/chair.obj",
        "width#2=80", "depth#2=80", "height#2=70", "creator#2=Someone"])
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("PluginFurnitureCatalog.properties", properties)
        zf.writestr("chair1/chair.obj", _chair_obj(back_z=90))
        zf.writestr("chair1/chair.mtl", MTL)
        zf.writestr("chair1/weave.png", texture)
    return path


def test_properties_parse_escapes_and_skip_comments():
    props = read_properties("# comment\nname#1=Caf\\u00e9 chair\n\nwidth#1 = 40\n")
    assert props == {"name#1": "Café chair", "width#1": "40"}


def test_importer_orients_scales_textures_and_attributes(tmp_path):
    archive = build_catalogue(tmp_path / "Test.sh3f")
    out = tmp_path / "furniture"
    written = import_furniture([archive], out, {"Chair": Rule(r"^chair$", ("Living room",)),
                                                "Table": Rule(r"table", ("Living room",))}, progress=False)
    assert list(written) == ["Chair", "Table"] and len(written["Chair"]) == 1 and written["Table"] == []
    catalog = LibraryCatalog.model_validate_json((out / "catalog.json").read_text())
    (record,) = catalog.models
    assert record.creator == "Jane Modeller é" and record.licence.startswith("Creative Commons Attribution")
    assert record.size == pytest.approx((0.45, 0.40, 0.90), abs=1e-3)   # depth, width, height in metres
    with np.load(out / "models" / f"{record.id}.npz") as data:
        vertices, faces, face_material = data["vertices"], data["faces"], data["face_material"]
    assert np.ptp(vertices, axis=0) == pytest.approx((0.45, 0.40, 0.90), abs=1e-3)
    assert vertices.min(axis=0) == pytest.approx(-np.ptp(vertices, axis=0) / 2, abs=1e-3)
    tall = vertices[:, 2] > 0.3                       # only the back rises above the seat
    assert vertices[tall, 0].max() < -0.15            # the back is at -x: the front looks along +x
    # the clear glass panel is gone; the seat and back remain with their materials
    assert [m.name for m in record.materials] == ["fabric", "wood"]
    assert len(faces) == 24 and set(face_material.tolist()) == {0, 1}
    fabric, wood = record.materials
    assert fabric.kind == "textured" and wood.kind == "wood" and wood.texture is None
    assert fabric.roughness > wood.roughness                           # Ns 4 is matter than Ns 30
    image = cv2.imread(str(out / str(fabric.texture)))
    assert image is not None and max(image.shape[:2]) == TEXTURE_TEXELS
    attribution = (out / "ATTRIBUTION.md").read_text()
    assert f"`models/{record.id}.npz`" in attribution and "Jane Modeller" in attribution


def test_import_furniture_command_writes_the_library(tmp_path, capsys):
    from ravh_sim.cli import main
    build_catalogue(tmp_path / "Test.sh3f")
    assert main(["import-furniture", str(tmp_path), "-o", str(tmp_path / "lib"), "-q"]) == 0
    assert "imported 1 models of 1 kinds" in capsys.readouterr().out       # the chair, as a Chair
    assert (tmp_path / "lib" / "catalog.json").is_file() and (tmp_path / "lib" / "ATTRIBUTION.md").is_file()
    assert main(["import-furniture", str(tmp_path / "nothing-here")]) == 2


def test_importer_simplifies_to_the_budget(tmp_path, monkeypatch):
    import ravh_sim.world.furniture_import as importer
    monkeypatch.setattr(importer, "TRIANGLE_BUDGET", 40)
    monkeypatch.setattr(importer, "MIN_TRIANGLES", 40)
    sphere = __import__("trimesh").creation.icosphere(3)                # 1280 triangles
    obj = "\n".join([f"v {x} {y} {z}" for x, y, z in sphere.vertices * 50]
                    + ["f " + " ".join(str(i + 1) for i in f) for f in sphere.faces]) + "\n"
    archive = tmp_path / "Ball.sh3f"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("PluginFurnitureCatalog.properties", "id#1=T#ball\nname#1=Ball\ncategory#1=Bedroom\n"
                    "model#1=/ball.obj\nwidth#1=50\ndepth#1=50\nheight#1=50\ncreator#1=X\nlicense#1=CC0\n")
        zf.writestr("ball.obj", obj)
    import_furniture([archive], tmp_path / "out", {"Ball": Rule(r"ball", ("Bedroom",))}, progress=False)
    record = LibraryCatalog.model_validate_json((tmp_path / "out" / "catalog.json").read_text()).models[0]
    assert 20 <= record.triangles <= 48 and record.size == pytest.approx((0.5, 0.5, 0.5), abs=0.05)


# --- the committed asset set ---------------------------------------------------------------------

def test_every_house_type_has_a_library_model_or_a_procedural_reason(houses):
    types = {(o.type, o.prefab) for house in houses.values() for o in house.objects}
    for object_type, prefab in sorted(types):
        if object_type in PROCEDURAL:
            assert object_type in OBJECT_TYPES and not models_of(kind_of(object_type, prefab))
        else:
            assert models_of(kind_of(object_type, prefab)), (object_type, prefab)
    assert set(OBJECT_TYPES) == set(PROCEDURAL)


def test_types_with_upstream_variants_have_three_library_models():
    for object_type in UPSTREAM_VARIANTS:
        kinds = [k for k in RULES if k.split("/")[0] == object_type]
        for kind in kinds:
            assert len(models_of(kind)) >= 3 or kind in FEWER_THAN_THREE, kind


def test_attribution_covers_every_shipped_model_with_an_open_licence():
    catalog = library.catalog()
    files = {p.name for p in (FURNITURE_DIR / "models").iterdir()}
    assert files == {f"{r.id}.npz" for r in catalog.models} and len(files) >= 100
    attribution = (FURNITURE_DIR / "ATTRIBUTION.md").read_text()
    for record in catalog.models:
        assert f"`models/{record.id}.npz` | {record.name} | {record.creator} | {record.licence}" in attribution
        assert re.search(r"Public domain|Creative Commons Attribution|CC-BY", record.licence), record.licence
        for material in record.materials:
            assert material.texture is None or (FURNITURE_DIR / material.texture).is_file()


def test_asset_set_stays_compact():
    size = sum(p.stat().st_size for p in FURNITURE_DIR.rglob("*") if p.is_file())
    assert size < 30e6
    assert max(r.triangles for r in library.catalog().models) <= 13000


@pytest.mark.parametrize("kind", ["Bed", "Chair", "Chair/office", "Sofa", "Armchair", "Toilet"])
def test_seats_beds_and_toilets_have_their_back_at_minus_x(kind):
    """The catalogues' front (+z, y up) became our +x: the tall part (back, headboard, cistern)
    of every model of these kinds is in the back half."""
    for record in models_of(kind):
        v = library.load_model(record.id).vertices
        top = v[v[:, 2] > v[:, 2].min() + 0.75 * np.ptp(v[:, 2])]
        assert top[:, 0].mean() < 0.05 * np.ptp(v[:, 0]), record.id


# --- fitting ---------------------------------------------------------------------------------

def test_fit_fills_the_box_within_its_proportions_and_stays_inside():
    model = library.load_model(models_of("Sofa")[0].id)
    natural = np.ptp(model.vertices, axis=0)
    for factors in ((1, 1, 1), (1.2, 1.2, 1.2), (1.6, 1, 1), (1, 1, 2), (0.5, 0.5, 0.5), (0.3, 1, 1)):
        size = natural * factors
        fitted = library.fit(model, size)
        assert (fitted >= -size / 2 - 1e-9).all() and (fitted <= size / 2 + 1e-9).all()
        extent = np.ptp(fitted, axis=0)
        assert (extent / size).max() == pytest.approx(1.0)                         # touches the box
        ratios = extent / natural
        assert ratios[:2].max() / ratios[2] <= library.MAX_STRETCH + 1e-9           # shape kept
        assert ratios[2] / ratios[:2].min() <= library.MAX_STRETCH + 1e-9
        if max(factors) / min(factors) <= library.MAX_STRETCH:
            assert extent[2] == pytest.approx(size[2])                              # full height
    fitted = library.fit(model, natural * (1.6, 1.0, 1.0))
    assert fitted[:, 0].min() == pytest.approx(-natural[0] * 0.8) and fitted[:, 2].min() == pytest.approx(
        -natural[2] / 2)                                                              # back, floor


def test_the_default_variant_is_the_best_proportioned_model(houses):
    """Variants are the kind's models ranked by how well they fit the object's box."""
    checked = 0
    for obj in [o for o in houses[15].objects if models_of(kind_of(o.type, o.prefab))]:
        default = object_parts(houses[15], obj, 0)
        quarter = round((default.front - default.yaw) / (np.pi / 2)) % 2      # the box turned to the front
        size = np.asarray(obj.box(0).size)[[1, 0, 2] if quarter else [0, 1, 2]]
        misfits = [library.misfit(np.asarray(r.size), size) for r in models_of(kind_of(obj.type, obj.prefab))]
        assert library.misfit(np.asarray(default.model.model.record.size), size) == pytest.approx(min(misfits))
        checked += 1
    assert checked > 30


def test_model_count_and_variants_choose_among_the_kind(houses):
    house = houses[15]
    chair = next(o for o in house.objects if o.type == "Chair" and "office" not in o.prefab.lower())
    count = model_count(chair)
    assert count == len(models_of("Chair"))
    ids = [object_parts(house, chair, v).model.model.id for v in range(count)]
    assert len(set(ids)) == count
    assert object_parts(house, chair, count).model.model.id == ids[0]                  # wraps


def test_placed_library_models_lie_in_their_box_and_cover_their_pieces(houses):
    checked = 0
    for house in (houses[15], houses[23]):
        for obj in house.objects:
            placed = object_parts(house, obj, None)
            if placed.model is None:
                continue
            half = np.asarray(obj.box(None).size) / 2 + 1e-6
            assert (np.abs(placed.model.vertices) <= half).all(), obj.id
            lo, hi = placed.extent()
            assert lo == pytest.approx(placed.model.vertices.min(axis=0), abs=1e-9)
            assert hi == pytest.approx(placed.model.vertices.max(axis=0), abs=1e-9)
            checked += 1
    assert checked > 100
