"""Tests for the procedural models (what the furniture library has no model of): meshes, palette,
models and facing."""
from __future__ import annotations

import itertools

import cv2
import numpy as np
import pytest
import trimesh

from ravh_sim.world.facing import choose_facing, front_axis, side_distances, suits_box
from ravh_sim.world.furniture import OBJECT_TYPES, build_model, variant_count
from ravh_sim.world.mesh import (
    box,
    colours,
    cylinder,
    ellipsoid,
    frustum,
    merged,
    rounded_box,
    transformed,
    write_palette_obj,
)
from ravh_sim.world.palette import PALETTE, Palette

# Upstream Robot@VirtualHome model counts per type (from the house data).
UPSTREAM_MODELS = {
    'Counter': 4, 'Door': 3, 'Keyboard': 1, 'Lighter': 1, 'Mirror': 2, 'Pouf': 4, 'Station': 1,
    'Toothbrush': 1, 'Wall': 3, 'Shelf': 3, 'Brush': 1,
}

# Typical upstream box sizes (sx, sy, sz) in metres; other types use a generic 0.6 m box.
TYPICAL = {
    'Counter': (0.6, 0.58, 0.04), 'Door': (0.26, 0.94, 2.5), 'Mirror': (0.68, 0.04, 1.05),
    'Wall': (1.36, 0.17, 1.36), 'Station': (0.5, 0.5, 0.02),
    'Keyboard': (0.44, 0.14, 0.03), 'Toothbrush': (0.06, 0.11, 0.2), 'Pouf': (0.5, 0.5, 0.4),
    'Shelf': (0.67, 0.24, 0.04), 'Brush': (0.17, 0.17, 0.44),
}


ALL_TYPES = list(OBJECT_TYPES) + ['SomethingUnknown']


def typical(object_type: str) -> tuple[float, float, float]:
    return TYPICAL.get(object_type, (0.6, 0.5, 0.7))


def sizes_for(object_type: str) -> list[tuple[float, float, float]]:
    sx, sy, sz = typical(object_type)
    return [(sx, sy, sz), (sy, sx, sz), (0.01, 0.01, 0.01), (0.01, 2.0, 0.5), (2.5, 0.3, 0.02)]


def check_model(mesh: trimesh.Trimesh, size: tuple[float, float, float]) -> None:
    half = np.asarray(size) / 2
    assert np.isfinite(mesh.vertices).all()
    assert (np.abs(mesh.vertices) <= half + 1e-6).all(), 'model leaves its box'
    lo, hi = mesh.bounds
    assert ((hi - lo) >= 0.9 * np.asarray(size)).all(), 'model does not fill its box'
    assert mesh.area_faces.min() > 1e-12 * max(size) ** 2, 'degenerate triangle'
    assert colours(mesh).min() >= 0 and colours(mesh).max() < len(PALETTE)
    assert mesh.faces.min() >= 0 and mesh.faces.max() < len(mesh.vertices)
    assert mesh.volume > 0, 'faces wind inwards'


# --- models ------------------------------------------------------------------------------

@pytest.mark.parametrize('object_type', ALL_TYPES)
def test_models_fit_their_box_for_every_variant_size_and_facing(object_type):
    variants = range(variant_count(object_type))
    for variant, size, facing in itertools.product(variants, sizes_for(object_type), range(4)):
        mesh = build_model(object_type, size, variant, facing)
        check_model(mesh, size)
        assert len(mesh.faces) <= 500


@pytest.mark.parametrize('object_type', ALL_TYPES)
def test_typical_models_stay_within_triangle_budget(object_type):
    for variant in range(variant_count(object_type)):
        assert len(build_model(object_type, typical(object_type), variant, 0).faces) <= 400


def test_average_model_is_cheap():
    counts = [len(build_model(t, typical(t), v).faces)
              for t in OBJECT_TYPES for v in range(variant_count(t))]
    assert np.mean(counts) <= 250


def test_variant_counts_follow_upstream_model_counts():
    assert set(OBJECT_TYPES) == set(UPSTREAM_MODELS)
    for object_type, upstream in UPSTREAM_MODELS.items():
        assert variant_count(object_type) == (max(3, upstream) if upstream > 1 else 1), object_type
    assert variant_count('SomethingUnknown') == 1


def same_mesh(a: trimesh.Trimesh, b: trimesh.Trimesh) -> bool:
    return (a.vertices.shape == b.vertices.shape and a.faces.shape == b.faces.shape
            and np.allclose(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
            and np.array_equal(colours(a), colours(b)))


@pytest.mark.parametrize('object_type', [t for t in OBJECT_TYPES if variant_count(t) > 1])
def test_variants_differ(object_type):
    meshes = [build_model(object_type, typical(object_type), v, 0) for v in range(variant_count(object_type))]
    for a, b in itertools.combinations(range(len(meshes)), 2):
        assert not same_mesh(meshes[a], meshes[b]), f'{object_type}: {a} and {b} look alike'


def test_variant_index_wraps_and_facing_wraps():
    assert same_mesh(build_model('Pouf', (0.5, 0.5, 0.4), 5), build_model('Pouf', (0.5, 0.5, 0.4), 1))
    assert same_mesh(build_model('Pouf', (0.5, 0.5, 0.4), 0, 6), build_model('Pouf', (0.5, 0.5, 0.4), 0, 2))


@pytest.mark.parametrize('object_type', ['Door', 'Counter', 'Mirror', 'Wall'])
def test_models_are_deterministic(object_type, tmp_path):
    a = build_model(object_type, typical(object_type), 1, 3)
    b = build_model(object_type, typical(object_type), 1, 3)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
    assert np.array_equal(colours(a), colours(b))
    write_palette_obj(a, tmp_path / 'a.obj', PALETTE)
    write_palette_obj(b, tmp_path / 'b.obj', PALETTE)
    assert (tmp_path / 'a.obj').read_bytes() == (tmp_path / 'b.obj').read_bytes()


def test_bad_sizes_still_give_a_model():
    for size in [(0.0, 0.5, 0.5), (-0.4, 0.5, 0.5), (float('nan'), 0.5, 0.5)]:
        mesh = build_model('Mirror', size, 0)
        assert np.isfinite(mesh.vertices).all() and mesh.area_faces.min() > 0


@pytest.mark.parametrize('object_type', OBJECT_TYPES)
def test_unsuitable_facings_turn_a_quarter(object_type):
    size = (2.0, 0.5, 1.0)
    for facing in range(4):
        mesh = build_model(object_type, size, 0, facing)
        if suits_box(front_axis(object_type), size, facing):
            assert not same_mesh(mesh, build_model(object_type, size, 0, (facing + 1) % 4))
        else:
            assert same_mesh(mesh, build_model(object_type, size, 0, (facing + 1) % 4))


def test_front_axes_of_typical_furniture():
    assert front_axis('Bed') == front_axis('Toilet') == 'long'
    assert front_axis('Closet') == front_axis('Picture') == front_axis('Sofa') == 'short'
    assert front_axis('Chair') == front_axis('SomethingUnknown') == 'any'
    assert suits_box('short', (2.0, 0.6, 1.0), 1) and not suits_box('short', (2.0, 0.6, 1.0), 0)
    assert suits_box('long', (2.0, 0.6, 1.0), 2) and not suits_box('long', (2.0, 0.6, 1.0), 3)
    assert all(suits_box(front, (1.0, 1.05, 1.0), f) for front in ('short', 'long', 'any') for f in range(4))


def test_flat_wall_items_face_across_their_thin_axis():
    mesh = build_model('Mirror', (0.68, 0.04, 1.05), 0, facing=0)  # facing contradicts the thin axis
    glass = colours(mesh) == PALETTE.index('mirror')
    cross = mesh.triangles_cross[glass]
    normal = cross[np.argmax(np.linalg.norm(cross, axis=1))]
    assert abs(normal[1]) / np.linalg.norm(normal) > 0.99


# --- mesh --------------------------------------------------------------------------------

PRIMITIVES = {
    'box': lambda: box((1.0, 2.0, 3.0), (0.4, 0.6, 0.8), 3),
    'cylinder_z': lambda: cylinder((1.0, 2.0, 3.0), 0.3, 0.8, 3),
    'cylinder_x': lambda: cylinder((1.0, 2.0, 3.0), 0.3, 0.8, 3, segments=12, axis='x'),
    'cylinder_y': lambda: cylinder((1.0, 2.0, 3.0), 0.3, 0.8, 3, axis='y'),
    'frustum': lambda: frustum((1.0, 2.0, 3.0), 0.3, 0.1, 0.8, 3),
    'cone': lambda: frustum((1.0, 2.0, 3.0), 0.3, 0.0, 0.8, 3),
    'rounded_box': lambda: rounded_box((1.0, 2.0, 3.0), (0.4, 0.6, 0.8), 3, 0.05),
    'ellipsoid': lambda: ellipsoid((1.0, 2.0, 3.0), (0.4, 0.6, 0.8), 3),
}


@pytest.mark.parametrize('name', PRIMITIVES)
def test_primitives_are_closed_outward_and_centred(name):
    mesh = PRIMITIVES[name]()
    lo, hi = mesh.bounds
    assert np.allclose((lo + hi) / 2, (1.0, 2.0, 3.0))
    centroids = mesh.vertices[mesh.faces].mean(axis=1) - (1.0, 2.0, 3.0)
    assert (np.einsum('ij,ij->i', mesh.triangles_cross, centroids) > 0).all(), 'a face points inwards'
    edges = np.sort(mesh.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, uses = np.unique(edges, axis=0, return_counts=True)
    assert (uses == 2).all(), 'mesh is not closed'
    assert mesh.area_faces.min() > 0 and (colours(mesh) == 3).all()


def extent(mesh: trimesh.Trimesh) -> np.ndarray:
    return mesh.extents


def test_primitive_extents_and_triangle_counts():
    assert np.allclose(extent(box((0, 0, 0), (0.4, 0.6, 0.8), 0)), (0.4, 0.6, 0.8))
    assert np.allclose(extent(cylinder((0, 0, 0), 0.3, 0.8, 0)), (0.6, 0.6, 0.8))
    assert np.allclose(extent(cylinder((0, 0, 0), 0.3, 0.8, 0, axis='x')), (0.8, 0.6, 0.6))
    assert np.allclose(extent(rounded_box((0, 0, 0), (0.4, 0.6, 0.8), 0, 0.1)), (0.4, 0.6, 0.8))
    assert np.allclose(extent(ellipsoid((0, 0, 0), (0.4, 0.6, 0.8), 0)), (0.4, 0.6, 0.8))
    assert len(box((0, 0, 0), (1, 1, 1), 0).faces) == 12
    assert len(cylinder((0, 0, 0), 1, 1, 0, segments=10).faces) == 36
    assert len(rounded_box((0, 0, 0), (1, 1, 1), 0, 0.1).faces) == 44


def test_merge_offsets_faces_and_keeps_colours():
    a, b = box((0, 0, 0), (1, 1, 1), 1), cylinder((5, 0, 0), 1, 1, 2)
    both = merged([a, b])
    assert len(both.faces) == len(a.faces) + len(b.faces)
    assert np.allclose(both.vertices[both.faces[len(a.faces):]], b.vertices[b.faces])
    assert list(np.unique(colours(both))) == [1, 2]


def test_transform_rotates_translates_and_keeps_winding_under_mirroring():
    mesh = box((1.0, 0.0, 0.0), (0.2, 0.4, 0.6), 0)
    turned = transformed(mesh, np.pi / 2, (0.0, 0.0, 1.0))
    assert np.allclose(turned.vertices.mean(axis=0), (0.0, 1.0, 1.0))
    assert np.allclose(extent(turned), (0.4, 0.2, 0.6))
    mirrored = transformed(mesh, np.diag([-1.0, 1.0, 1.0]))
    assert mirrored.volume == pytest.approx(mesh.volume) and mesh.volume > 0


def parse_obj(text: str) -> dict[str, list[list[str]]]:
    records: dict[str, list[list[str]]] = {}
    for line in text.splitlines():
        if line and not line.startswith('#'):
            key, *values = line.split()
            records.setdefault(key, []).append(values)
    return records


def test_obj_export_round_trips_geometry_uvs_and_normals(tmp_path):
    mesh = merged([box((0, 0, 0), (1, 2, 3), PALETTE.index('wood_dark')),
                   frustum((0, 0, 2), 0.5, 0.2, 1.0, PALETTE.index('chrome'), axis='y')])
    path = tmp_path / 'm.obj'
    write_palette_obj(mesh, path, PALETTE)
    obj = parse_obj(path.read_text())
    vertices = np.array(obj['v'], float)
    uvs, normals = np.array(obj['vt'], float), np.array(obj['vn'], float)
    assert len(obj['f']) == len(mesh.faces)
    for face, corners, colour, normal in zip(mesh.faces, obj['f'], colours(mesh), mesh.face_normals):
        v, t, n = np.array([c.split('/') for c in corners], int).T - 1
        assert np.allclose(vertices[v], mesh.vertices[face], atol=1e-5)
        assert np.allclose(uvs[t], PALETTE.uv(int(colour)), atol=1e-6)
        assert np.allclose(normals[n], normal, atol=1e-3)


# --- palette -----------------------------------------------------------------------------

def test_palette_names_are_unique_and_fit_the_texture():
    assert len(set(PALETTE.names)) == len(PALETTE) <= PALETTE.cell_count
    assert len(PALETTE) >= 40
    for i, name in enumerate(PALETTE.names):
        assert PALETTE.index(name) == i
    with pytest.raises(KeyError):
        PALETTE.index('no_such_colour')


def test_palette_uv_samples_its_colour_from_the_written_texture(tmp_path):
    path = tmp_path / 'palette.png'
    PALETTE.write_texture(path)
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    height, width = image.shape[:2]
    assert min(width // PALETTE.cell_count, height) >= 8
    for i in range(len(PALETTE)):
        u, v = PALETTE.uv(i)
        expected = np.round(PALETTE.rgb[i] * 255)[::-1]  # BGR on disk
        for row in (int((1.0 - v) * height), int(v * height)):  # either image row order
            for du in (-3, 0, 3):  # and a few texels around the centre, as filtering would
                texel = image[min(row, height - 1), int(u * width) + du]
                assert np.array_equal(texel, expected), PALETTE.names[i]


def test_palette_rejects_too_many_colours():
    with pytest.raises(ValueError):
        Palette(tuple((f'c{i}', (0.0, 0.0, 0.0)) for i in range(5)), cell_count=4)


# --- facing ------------------------------------------------------------------------------

def wall_beside(center: np.ndarray, yaw: float, side: int, gap: float, size: tuple[float, float]) -> tuple:
    """A 3 m wall parallel to the box side ``side`` (0..3 = local +x, +y, -x, -y), ``gap`` metres away."""
    angle = yaw + side * np.pi / 2
    normal = np.array([np.cos(angle), np.sin(angle)])
    tangent = np.array([-normal[1], normal[0]])
    mid = center + normal * (size[side % 2] / 2 + gap)
    return tuple(mid - 1.5 * tangent), tuple(mid + 1.5 * tangent)


@pytest.mark.parametrize('yaw', [0.0, 0.3, np.pi / 2, 2.5, -np.pi])
@pytest.mark.parametrize('back_side', range(4))
def test_front_points_away_from_the_nearest_wall(yaw, back_side):
    center, size = np.array([1.0, -2.0]), (0.8, 0.5, 1.0)
    walls = [wall_beside(center, yaw, back_side, 0.05, size),
             wall_beside(center, yaw, (back_side + 1) % 4, 0.6, size)]
    assert choose_facing(center, yaw, size, walls) == (back_side + 2) % 4


@pytest.mark.parametrize('yaw', [0.0, 0.4, -np.pi / 2])
def test_front_axis_keeps_corner_furniture_backed_onto_the_right_wall(yaw):
    center, size = np.array([0.5, 0.5]), (2.0, 0.6, 2.0)  # a wardrobe, long along local x
    walls = [wall_beside(center, yaw, 0, 0.02, size), wall_beside(center, yaw, 1, 0.05, size)]
    assert choose_facing(center, yaw, size, walls) == 2  # nearest wall is at the +x end
    assert choose_facing(center, yaw, size, walls, front='short') == 3  # but doors face away from +y
    assert choose_facing(center, yaw, size, walls, front='long') == 2
    assert choose_facing(center, yaw, size, [], front='short') == 1


def test_facing_ignores_walls_beside_the_sweep_and_parallel_to_it():
    size = (0.6, 0.6, 1.0)
    beside = [((0.5, 2.0), (0.5, 5.0))]  # off to the side, not in front of the +x face
    assert np.isinf(side_distances((0.0, 0.0), 0.0, size, beside)).all()
    along = [((-3.0, 0.1), (3.0, 0.1))]  # runs through the box along x: cannot be behind the +-x faces
    distances = side_distances((0.0, 0.0), 0.0, size, along)
    assert np.isinf(distances[[0, 2]]).all() and distances[1] < 0


def test_facing_defaults_and_ties_are_deterministic():
    assert choose_facing((0.0, 0.0), 0.0, (1.0, 1.0, 1.0), []) == 0
    walls = [((-0.7, -3.0), (-0.7, 3.0)), ((0.7, -3.0), (0.7, 3.0))]  # equally near on -x and +x
    size = (1.0, 1.0, 1.0)
    assert choose_facing((0.0, 0.0), 0.0, size, walls) == 2
    assert choose_facing((0.0, 0.0), 0.0, size, walls[::-1]) == 2


def test_facing_distance_is_measured_from_the_box_side():
    walls = [((2.0, -1.0), (2.0, 1.0))]
    assert side_distances((0.0, 0.0), 0.0, (1.0, 0.5, 1.0), walls)[0] == pytest.approx(1.5)
    assert side_distances((0.0, 0.0), np.pi / 2, (1.0, 0.5, 1.0), walls)[3] == pytest.approx(1.75)


@pytest.mark.parametrize('yaw', [0.0, 1.2, -np.pi / 2])
def test_an_appliance_in_a_corner_opens_into_the_room_not_into_its_neighbour(yaw):
    """A washing machine with walls 5 cm behind it (-x) and 4 cm at its end (-y), a sink unit touching
    its other end (+y): the nearest wall alone puts its back to -y and its door towards the unit; the
    blockers turn the door to +x, the open side."""
    center, size = np.array([0.0, 0.0]), (0.6, 0.6, 0.85)
    walls = [wall_beside(center, yaw, 2, 0.05, size), wall_beside(center, yaw, 3, 0.04, size)]
    unit = [wall_beside(center, yaw, 1, 0.0, size)]
    assert front_axis('WashingMachine') == front_axis('Refrigerator') == 'door'
    assert choose_facing(center, yaw, size, walls, front='door') == 1
    assert choose_facing(center, yaw, size, walls, front='door', blockers=unit) == 0
    enclosed = unit + [wall_beside(center, yaw, 0, 0.1, size)]          # no side open: the walls decide
    assert choose_facing(center, yaw, size, walls, front='door', blockers=enclosed) == 1


def test_an_appliance_keeps_its_front_where_a_turned_model_would_fit_better(houses):
    """Its box's proportions never turn an appliance's door away from the side chosen for it (house
    3's washing machine was turned a quarter, its door to the wall 9 cm away)."""
    from ravh_sim.world.solids import object_parts
    house = houses[3]
    washer = house.object_by_id["WashingMachine_0"]
    placed = object_parts(house, washer, None)
    walls = [(w.a, w.b) for w in house.walls if w.room == washer.room and w.kind != "lintel"]
    side = round((placed.front - washer.yaw) / (np.pi / 2)) % 4
    assert side_distances(washer.position[:2], washer.yaw, washer.size, walls)[side] > 0.3


def test_an_appliance_takes_a_model_of_its_width_before_a_squeezed_one():
    """A 71 cm fridge box takes the 59 cm combi (stretched), not the 93 cm side-by-side squeezed to
    30 cm doors, though the side-by-side's proportions fit better; with no model of its width it
    takes the best proportions."""
    from ravh_sim.world import library
    from ravh_sim.world.solids import APPLIANCE_LEAST_WIDTH_SCALE, _library_choice
    fridges = library.models_of("Refrigerator")
    box = np.array([0.63, 0.71, 1.98])                              # depth, front width, height at facing 0
    record, facing = _library_choice(fridges, 0, box, 0, "door")
    assert facing == 0 and record.size[1] * APPLIANCE_LEAST_WIDTH_SCALE <= box[1]
    assert min(fridges, key=lambda r: library.misfit(np.asarray(r.size), box)) is not record
    tiny = np.array([0.3, 0.3, 1.0])                                 # narrower than every model
    best = min(fridges, key=lambda r: library.misfit(np.asarray(r.size), tiny))
    assert _library_choice(fridges, 0, tiny, 0, "door")[0] is best
