"""Rigid dressing models made here: books and dish racks (the catalogues have none).

Like :mod:`ravh_sim.world.soft_furnishings` (same interface: :func:`records`, :func:`is_made`,
:func:`model`), each is a library-style model (a ``record`` in ``metadata``, a ``material`` and a
``piece`` per face, texture coordinates) built to the box it is placed in, front along +x, up +z,
centred on its box, touching its bottom and filling it exactly. Model ids are
``made/<kind>/<variant>``: the variant seeds every choice, so a footprint's ``asset`` and the box
rebuild the same model.

- **Book**: what a box holds depends on its shape. A box at least :data:`ROW_HEIGHT` tall is a shelf
  board's row of books standing side by side, spines to the front (+x) in seeded colours, of varied
  thickness, height and depth, some rows with a gap or a book leaning on the last one; a lower box
  is a short stack of 2-4 books lying flat, each turned a little against the one under it. Every
  book is one convex prism with a rounded spine: covers on the spine and sides, an off-white page
  block at the top, bottom and fore-edge (two materials, so the camera sees pages, not a brick).
- **Dish rack**: a low plastic or wire tray with a few plates standing on edge in a row, leaning
  back together, and a cup or two upside down beside them.
"""
from __future__ import annotations

import functools
import math
import random

import numpy as np
import trimesh

from ravh_sim.poses import rotation_y, rotation_z
from ravh_sim.world import library

KINDS = ("book", "dish_rack")
VARIANTS = {"book": 8, "dish_rack": 4}
PREFIX = "made/"
SIZES = {"book": (0.2, 0.45, 0.22), "dish_rack": (0.42, 0.36, 0.24)}
MAX_BOOKS = 15                # in a row
LEANING_WIDTH = 0.35          # m: a row this wide may end in a leaning book (a narrower one keeps room for 5 or more)
ROW_HEIGHT = 0.12             # m: a book box this tall holds a standing row, a lower one a lying stack
_NAMES = {"book": "Books", "dish_rack": "Dish rack"}

# sRGB cover colours: cloth and paper bindings, mostly dark, some cream, white and bright paperbacks
_COVERS = ((0.42, 0.07, 0.09), (0.30, 0.08, 0.10), (0.10, 0.13, 0.30), (0.16, 0.22, 0.42),
           (0.12, 0.27, 0.17), (0.34, 0.37, 0.17), (0.86, 0.82, 0.70), (0.08, 0.08, 0.09),
           (0.92, 0.92, 0.90), (0.72, 0.52, 0.16), (0.38, 0.24, 0.15), (0.12, 0.36, 0.38),
           (0.52, 0.53, 0.55), (0.80, 0.36, 0.12))
_PAGES = (0.90, 0.87, 0.78)
_COVERS_A_MODEL = 6           # cover colours one book model draws its books from
_TRAYS = (((0.93, 0.93, 0.91), "plain"), ((0.55, 0.57, 0.58), "plain"), ((0.62, 0.72, 0.62), "plain"),
          ((0.70, 0.71, 0.72), "metal"))
_CROCKERY = ((0.95, 0.95, 0.93), (0.90, 0.87, 0.80), (0.30, 0.40, 0.55), (0.75, 0.35, 0.25))


def is_made(model_id: str) -> bool:
    return model_id.startswith(PREFIX) and model_id.split("/")[1] in KINDS      # not made/art/ (made_art)


def _materials(kind: str, variant: int) -> list[library.LibraryMaterial]:
    rng = random.Random(f"made/{kind}/{variant}/materials")
    if kind == "book":
        covers = rng.sample(_COVERS, _COVERS_A_MODEL)
        return [library.LibraryMaterial(name="pages", colour=_PAGES, roughness=0.9, kind="plain")] + [
            library.LibraryMaterial(name=f"cover_{k}", colour=c, roughness=0.75, kind="plain")
            for k, c in enumerate(covers)]
    tray, tray_kind = _TRAYS[variant % len(_TRAYS)]
    cup = _CROCKERY[rng.randrange(len(_CROCKERY))]
    return [library.LibraryMaterial(name="tray", colour=tray, roughness=0.5, kind=tray_kind),  # type: ignore[arg-type]
            library.LibraryMaterial(name="plates", colour=_CROCKERY[variant % 2], roughness=0.3, kind="ceramic"),
            library.LibraryMaterial(name="cups", colour=cup, roughness=0.3, kind="ceramic")]


def _record(kind: str, variant: int, size: tuple[float, float, float]) -> library.LibraryRecord:
    return library.LibraryRecord(id=f"{PREFIX}{kind}/{variant}", kind=f"Dressing/{kind}", name=_NAMES[kind],
                                 catalogue="ravh_sim", catalogue_id=f"{kind}-{variant}", creator="ravh_sim",
                                 licence="same as ravh_sim", size=size, triangles=0,
                                 materials=_materials(kind, variant))


@functools.cache
def records(kind: str) -> tuple[library.LibraryRecord, ...]:
    """The made models of a kind (``Dressing/book`` or ``book``), one per variant."""
    kind = kind.removeprefix("Dressing/")
    if kind not in KINDS:
        return ()
    return tuple(_record(kind, v, SIZES[kind]) for v in range(VARIANTS[kind]))


# --------------------------------------------------------------------------- pieces

class Parts:
    """Convex pieces gathered into one mesh: vertices, faces, and a material and piece per face."""

    def __init__(self) -> None:
        self.vertices: list[np.ndarray] = []
        self.faces: list[np.ndarray] = []
        self.materials: list[np.ndarray] = []
        self.pieces: list[np.ndarray] = []
        self.count = 0

    def prism(self, profile: np.ndarray, z0: float, z1: float, edge_material: list[int] | int,
              centre: np.ndarray | None = None, turn: np.ndarray | None = None,
              shift: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        """A convex profile (P, 2) extruded from z0 to z1, its caps fanned from ``centre`` (a point of
        the profile; its centroid by default); each edge's side and cap fans in its material; then
        turned and shifted into the model."""
        n = len(profile)
        mats = [edge_material] * n if isinstance(edge_material, int) else edge_material
        centre = profile.mean(axis=0) if centre is None else centre
        ring = np.vstack([profile, centre[None]])
        verts = np.vstack([np.column_stack([ring, np.full(n + 1, z0)]), np.column_stack([ring, np.full(n + 1, z1)])])
        top, faces, face_mats = n + 1, [], []
        for i in range(n):
            j = (i + 1) % n
            faces += [(i, j, top + j), (i, top + j, top + i), (n, j, i), (top + n, top + i, top + j)]
            face_mats += [mats[i]] * 4
        verts = verts @ (np.eye(3) if turn is None else turn).T + np.asarray(shift)
        faces_ = np.asarray(faces, np.int64)
        tri = verts[faces_]
        normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        inward = np.einsum("ij,ij->i", normal, tri.mean(axis=1) - verts.mean(axis=0)) < 0
        faces_[inward] = faces_[inward][:, ::-1]              # outward winding (the piece is convex)
        self.vertices.append(verts)
        self.faces.append(faces_ + self.count)
        self.materials.append(np.asarray(face_mats, np.int64))
        self.pieces.append(np.full(len(faces_), len(self.faces) - 1, np.int64))
        self.count += len(verts)

    def box(self, lo: tuple[float, float, float], hi: tuple[float, float, float], material: int) -> None:
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        self.prism(np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)]), z0, z1, material)


def _turn_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


SPINE = 0.005                 # m: how far a spine's rounding bulges


def _book(parts: Parts, depth: float, thickness: float, height: float, cover: int,
          turn: np.ndarray, shift: tuple[float, float, float]) -> None:
    """One book standing on its bottom (z from 0), spine along +x, thickness along y, centred on x and y
    before ``turn`` and ``shift``: covers on the spine and sides, pages on the rest."""
    r, half = min(SPINE, 0.3 * depth), thickness / 2
    arc = [(depth / 2 - r + r * math.cos(a), half * math.sin(a)) for a in np.linspace(-math.pi / 2, math.pi / 2, 5)]
    profile = np.array([(-depth / 2, -half)] + arc + [(-depth / 2, half)])
    # edges: side, four spine arcs, side, fore-edge (pages)
    parts.prism(profile, 0.0, height, [cover] * 6 + [0], np.array([depth / 2 - r, 0.0]), turn, shift)


def _book_row(parts: Parts, size: np.ndarray, rng: random.Random) -> None:
    """Books standing side by side along y, spines at the front, filling the box's width; a gap or a
    book leaning on the last one in some rows."""
    d, w, h = size
    style = rng.choice(("tight", "gap", "leaning") if w >= LEANING_WIDTH else ("tight", "gap"))
    books: list[tuple[float, float, float, int]] = []         # (thickness, height, depth, cover)
    width = 0.0
    gap_at = rng.randrange(2, 5) if style == "gap" else -1
    lean = math.radians(rng.uniform(12.0, 24.0))
    room = w - (h * math.sin(lean) + 0.04 if style == "leaning" else 0.0)     # what the leaning book leaves
    while True:
        if books and rng.random() < 0.25:                      # a set: same binding, height and depth
            t, bh, bd, cover = books[-1]
        else:
            t, bh, bd = rng.uniform(0.02, 0.05), h * rng.uniform(0.68, 1.0), d * rng.uniform(0.7, 1.0)
            cover = 1 + rng.randrange(_COVERS_A_MODEL)
        if width + t > room or len(books) == MAX_BOOKS:
            break
        books.append((t, bh, bd, cover))
        width += t
    y = -w / 2
    for k, (t, bh, bd, cover) in enumerate(books):
        if k == gap_at:
            y += rng.uniform(0.03, 0.07)
        front = d / 2 - rng.uniform(0.0, 0.012)                # spines a little uneven, as real rows are
        _book(parts, bd, t, bh, cover, np.eye(3), (front - bd / 2, y + t / 2, -h / 2))
        y += t
    if style == "leaning":             # tipped towards the row on its near bottom edge, its top on the last book
        t = rng.uniform(0.02, 0.04)
        bh, bd = min(books[-1][1], h * rng.uniform(0.75, 1.0)), d * rng.uniform(0.75, 1.0)
        shift = (d / 2 - bd / 2, y + t / 2 * math.cos(lean) + bh * math.sin(lean), -h / 2 + t / 2 * math.sin(lean))
        _book(parts, bd, t, bh, 1 + rng.randrange(_COVERS_A_MODEL), _turn_x(lean), shift)


def _book_stack(parts: Parts, size: np.ndarray, rng: random.Random) -> None:
    """2-4 books lying flat, the biggest at the bottom, each turned a little on the one under it."""
    d, w, h = size
    n = rng.randrange(2, 5)
    shares = np.array([rng.uniform(0.7, 1.3) for _ in range(n)])
    thickness = shares / shares.sum() * h
    spans = sorted(((rng.uniform(0.72, 0.95), rng.uniform(0.72, 0.95)) for _ in range(n)), reverse=True)
    z = -h / 2
    for t, (fd, fw) in zip(thickness, spans):
        turn = rng.uniform(-0.14, 0.14) + (math.pi if rng.random() < 0.3 else 0.0)
        c, s = abs(math.cos(turn)), abs(math.sin(turn))
        bd, bw = d * fd, w * fw
        shrink = min(1.0, d / (c * bd + s * bw), w / (s * bd + c * bw))   # turned, still inside the box
        bd, bw = bd * shrink, bw * shrink
        # lying: the book's thickness (its y) up, its height (its z) across, centred, then turned
        lying = rotation_z(turn) @ _turn_x(math.pi / 2)
        middle = lying @ np.array([0.0, 0.0, bw / 2])
        _book(parts, bd, float(t), bw, 1 + rng.randrange(_COVERS_A_MODEL), lying,
              (-middle[0], -middle[1], z + float(t) / 2))
        z += float(t)


def _circle(segments: int) -> np.ndarray:
    return np.array([(math.cos(a), math.sin(a)) for a in np.linspace(0, 2 * math.pi, segments, endpoint=False)])


def _dish_rack(parts: Parts, size: np.ndarray, rng: random.Random) -> None:
    """A tray with a low rim, two rails, plates on edge leaning back together, cups upside down."""
    d, w, h = size
    base, rim, wall = 0.012, 0.05, 0.008
    bottom = -h / 2
    parts.box((-d / 2, -w / 2, bottom), (d / 2, w / 2, bottom + base), 0)
    for sign in (-1, 1):
        parts.box((-d / 2, sign * (w / 2 - wall / 2) - wall / 2, bottom), (d / 2, sign * (w / 2 - wall / 2) + wall / 2,
                                                                            bottom + rim), 0)
        parts.box((sign * (d / 2 - wall / 2) - wall / 2, -w / 2 + wall, bottom),
                  (sign * (d / 2 - wall / 2) + wall / 2, w / 2 - wall, bottom + rim), 0)
    lean = math.radians(rng.uniform(4.0, 8.0))
    plate_t = 0.014
    diameter = (h - base - plate_t * math.sin(lean)) / math.cos(lean)
    diameter = min(diameter, 0.62 * w)
    centre_y = -w / 2 + wall + diameter / 2 + 0.01
    for sign in (-1, 1):                                       # the rails the plates stand between
        y = centre_y + sign * 0.3 * diameter
        parts.box((-d / 2 + wall, y - 0.003, bottom + base), (d / 2 - wall, y + 0.003, bottom + base + 0.05), 0)
    count = rng.randrange(3, 6)
    for x in np.linspace(-d / 2 + 0.06, d / 2 - 0.07, 5)[:count]:   # a disc in the y-z plane, tipped back
        lowest = diameter / 2 * math.cos(lean) + plate_t / 2 * math.sin(lean)      # its centre above its rim
        parts.prism(_circle(14) * diameter / 2, -plate_t / 2, plate_t / 2, 1,
                    turn=rotation_y(-lean) @ rotation_y(math.pi / 2),
                    shift=(float(x), centre_y, bottom + base + lowest))
    cup_d, cup_h = min(0.085, w - diameter - 3 * wall), 0.095
    for k in range(rng.randrange(1, 3)):
        parts.prism(_circle(12) * cup_d / 2, bottom + base, bottom + base + cup_h, 2,
                    shift=(d / 2 - wall - 0.01 - cup_d / 2 - k * (cup_d + 0.02), w / 2 - wall - 0.005 - cup_d / 2, 0.0))


@functools.lru_cache(maxsize=512)
def model(model_id: str, size: tuple[float, float, float]) -> trimesh.Trimesh:
    """The made model ``made/<kind>/<variant>`` built to fill a box of ``size`` (front, across, up),
    centred on it, as :func:`ravh_sim.world.library.fit` sets a library model."""
    kind, variant = model_id.removeprefix(PREFIX).split("/")
    box = np.asarray(size, np.float64)
    rng = random.Random(f"made/{kind}/{variant}/{'row' if box[2] >= ROW_HEIGHT else 'stack'}")
    parts = Parts()
    if kind == "dish_rack":
        _dish_rack(parts, box, rng)
    elif box[2] >= ROW_HEIGHT:
        _book_row(parts, box, rng)
    else:
        _book_stack(parts, box, rng)
    fitted = library.made_to_box(np.vstack(parts.vertices), size)    # exactly its box (a few mm off)
    entry = _record(kind, int(variant), tuple(float(s) for s in box))   # type: ignore[arg-type]
    uv = np.stack([fitted[:, 1] + fitted[:, 0], fitted[:, 2] + fitted[:, 0]], axis=1)
    return library.made_model(fitted, np.vstack(parts.faces), uv, entry, np.concatenate(parts.materials),
                              np.concatenate(parts.pieces))
