"""Meshes of the building itself: floors, ceilings and walls of each room, UV-mapped in metres.

Unlike furniture (coloured through the palette texture), structure is painted: a plain colour or a
tiling texture, so its UVs run in world metres divided by the texture's tile size and the renderer
repeats the texture. Flat normals, one OBJ per room and surface.

The wall pieces built (:func:`solid_walls`, drawn, collided with and mapped alike) close the cracks
that the upstream pieces leave at doorways: a lintel stops a few millimetres short of the wall
pieces beside it, a door leaf is narrower than its gap in the walls, and walls end exactly at the
floor and the ceiling, which let the sky or the ground show through thin slits. Lintels reach into
their neighbours and walls reach through the floor and the ceiling; :func:`doorway_ends` tells a
closed door how far its jambs must reach (see :func:`ravh_sim.world.solids.door_parts`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ravh_sim.world.geometry import triangulate
from ravh_sim.world.house import Door, House, Room, Wall
from ravh_sim.world.paints import TEXTURE_TILE_M


LINTEL_OVERLAP = 0.05      # m a lintel reaches into the wall pieces at each of its ends
SEAM_OVERLAP = 0.05        # m a wall piece reaching the floor (ceiling) goes below (above) it: no seam
JAMB_REACH = 0.1           # m beyond a doorway's frame where the wall ends beside it are looked for


def solid_walls(house: House, room_id: str) -> list[Wall]:
    """The wall pieces built for a room: its walls, reaching through the floor and the ceiling where
    they meet them, and its lintels lengthened into their neighbours."""
    room = house.room(room_id)
    walls = []
    for w in house.walls:
        if w.room != room_id:
            continue
        if w.kind == "lintel":
            w = _lengthened(w, LINTEL_OVERLAP)
        if w.z0 <= room.floor_z + 1e-3:
            w = replace(w, z0=room.floor_z - SEAM_OVERLAP)
        if w.z1 >= room.ceiling_z - 1e-3:
            w = replace(w, z1=room.ceiling_z + SEAM_OVERLAP)
        walls.append(w)
    return walls


def doorway_ends(house: House, door: Door) -> tuple[float, float]:
    """Where the wall pieces beside a doorway end, along the door's ``yaw`` from its centre (at most
    -leaf/2 and at least +leaf/2: where walls reach into the leaf, its edges)."""
    ux, uy = math.cos(door.yaw), math.sin(door.yaw)
    cx, cy = door.position[:2]
    floor = min(house.room(r).floor_z for r in door.rooms)
    half_leaf, half_frame = door.leaf[0] / 2, door.width / 2
    left, right = -half_leaf, half_leaf
    for w in house.walls:
        if w.kind == "lintel" or w.room not in door.rooms or w.z0 > floor + door.leaf[2]:
            continue
        ends = [((x - cx) * ux + (y - cy) * uy, (x - cx) * -uy + (y - cy) * ux) for x, y in (w.a, w.b)]
        if any(abs(across) > (door.thickness + w.thickness) / 2 for _, across in ends):
            continue                                    # not a wall of this doorway
        lo, hi = sorted(along for along, _ in ends)
        if -half_frame - JAMB_REACH <= hi <= -half_leaf:
            left = min(left, hi)
        if half_leaf <= lo <= half_frame + JAMB_REACH:
            right = max(right, lo)
    return left, right


def _lengthened(w: Wall, by: float) -> Wall:
    (ax, ay), (bx, by_) = w.a, w.b
    length = max(w.length, 1e-9)
    dx, dy = (bx - ax) / length * by, (by_ - ay) / length * by
    return replace(w, a=(ax - dx, ay - dy), b=(bx + dx, by_ + dy))


@dataclass
class TexturedMesh:
    vertices: np.ndarray     # (N, 3)
    uvs: np.ndarray          # (N, 2)
    normals: np.ndarray      # (N, 3)
    faces: np.ndarray        # (M, 3) int, counter-clockwise from outside

    @property
    def triangle_count(self) -> int:
        return len(self.faces)

    def write_obj(self, path: Path) -> None:
        lines = [f"v {x:.4f} {y:.4f} {z:.4f}" for x, y, z in self.vertices]
        lines += [f"vt {u:.4f} {v:.4f}" for u, v in self.uvs]
        lines += [f"vn {x:.4f} {y:.4f} {z:.4f}" for x, y, z in self.normals]
        lines += [f"f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}" for a, b, c in self.faces + 1]
        path.write_text("\n".join(lines) + "\n")


def merge(meshes: list[TexturedMesh]) -> TexturedMesh:
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return TexturedMesh(np.concatenate([m.vertices for m in meshes]),
                        np.concatenate([m.uvs for m in meshes]),
                        np.concatenate([m.normals for m in meshes]),
                        np.concatenate([m.faces + o for m, o in zip(meshes, offsets)]))


def floor_mesh(room: Room, z: float, facing_up: bool = True) -> TexturedMesh:
    """The room's floor outline(s) as a horizontal surface at height ``z``."""
    parts = []
    for poly in (room.floor, *room.extra_floors):
        pts = np.array(poly, dtype=float)
        tris = np.array(triangulate(poly), dtype=int).reshape(-1, 3)
        if not facing_up:
            tris = tris[:, ::-1]
        verts = np.column_stack([pts, np.full(len(pts), z)])
        normal = np.tile([0.0, 0.0, 1.0 if facing_up else -1.0], (len(pts), 1))
        parts.append(TexturedMesh(verts, pts / TEXTURE_TILE_M, normal, tris))
    return merge(parts)


def wall_mesh(walls: list[Wall]) -> TexturedMesh:
    """Every wall piece of a room as a box, the texture running along each wall."""
    return merge([_wall_box(w) for w in walls])


def _wall_box(w: Wall) -> TexturedMesh:
    (ax, ay), (bx, by) = w.a, w.b
    length = max(math.hypot(bx - ax, by - ay), 1e-3)
    d = np.array([(bx - ax) / length, (by - ay) / length])
    n = np.array([-d[1], d[0]]) * w.thickness / 2
    base = [np.array([ax, ay]) - n, np.array([bx, by]) - n, np.array([bx, by]) + n, np.array([ax, ay]) + n]
    faces: list[TexturedMesh] = []
    for k in range(4):                                   # the four vertical sides
        p, q = base[k], base[(k + 1) % 4]
        edge = q - p
        out = np.array([edge[1], -edge[0]]) / max(np.linalg.norm(edge), 1e-9)
        u0 = float(np.dot(p, d))
        u1 = u0 + float(np.linalg.norm(edge))
        faces.append(_quad([(*p, w.z0), (*q, w.z0), (*q, w.z1), (*p, w.z1)],
                           [(u0, w.z0), (u1, w.z0), (u1, w.z1), (u0, w.z1)], (*out, 0.0)))
    for z, up in ((w.z1, 1.0), (w.z0, -1.0)):           # top and bottom caps
        ring = base if up > 0 else base[::-1]
        faces.append(_quad([(*p, z) for p in ring], [tuple(p) for p in ring], (0.0, 0.0, up)))
    return merge(faces)


def _quad(corners: list[tuple], uvs_m: list[tuple], normal: tuple) -> TexturedMesh:
    """Two triangles; ``uvs_m`` in metres (scaled to texture tiles here)."""
    verts = np.array(corners, dtype=float)
    uv = np.array(uvs_m, dtype=float) / TEXTURE_TILE_M
    return TexturedMesh(verts, uv, np.tile(normal, (4, 1)), np.array([[0, 1, 2], [0, 2, 3]]))
