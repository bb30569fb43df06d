"""Meshes of the building itself: floors, ceilings and walls of each room, UV-mapped in metres.

Unlike furniture (coloured through the palette texture), structure is painted: a plain colour or a
tiling texture, so its UVs run in world metres divided by the texture's tile size and the renderer
repeats the texture. Flat normals, one OBJ per room and surface. Walls have openings where windows
are (drawn only: the collision walls stay whole).

The wall pieces built (:func:`solid_walls`, drawn, collided with and mapped alike) close the cracks
that the upstream pieces leave at doorways: a lintel stops a few millimetres short of the wall
pieces beside it, a door leaf is narrower than its gap in the walls, and walls end exactly at the
floor and the ceiling, which let the sky or the ground show through thin slits. Lintels reach into
their neighbours and walls reach through the floor and the ceiling; :func:`doorway_ends` tells a
closed door how far its jambs must reach (see :func:`ravh_sim.world.solids.door_parts`).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np
import trimesh
from trimesh.exchange.obj import export_obj

from ravh_sim.world.geometry import triangulate
from ravh_sim.world.house import Door, House, Room, Wall, Window
from ravh_sim.world.mesh import uv_visual
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


def textured(vertices: np.ndarray, uvs: np.ndarray, normals: np.ndarray, faces: np.ndarray) -> trimesh.Trimesh:
    """A painted surface: (N, 3) vertices with (N, 2) texture coordinates (texture tiles) and
    (N, 3) normals, (M, 3) faces counter-clockwise from outside."""
    return trimesh.Trimesh(vertices, faces, process=False, vertex_normals=normals, visual=uv_visual(uvs))


def write_textured_obj(mesh: trimesh.Trimesh, path: Path) -> None:
    """The surface as an OBJ file for pybullet's renderer (trimesh's writer, 4 decimals)."""
    path.write_text(export_obj(mesh, include_normals=True, digits=4, header=None))


def merge(meshes: list[trimesh.Trimesh]) -> trimesh.Trimesh:
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return textured(np.concatenate([m.vertices for m in meshes]),
                    np.concatenate([m.visual.uv for m in meshes]),
                    np.concatenate([m.vertex_normals for m in meshes]),
                    np.concatenate([m.faces + o for m, o in zip(meshes, offsets)]))


def floor_mesh(room: Room, z: float, facing_up: bool = True) -> trimesh.Trimesh:
    """The room's floor outline(s) as a horizontal surface at height ``z``."""
    parts = []
    for poly in (room.floor, *room.extra_floors):
        pts = np.array(poly, dtype=float)
        tris = np.array(triangulate(poly), dtype=int).reshape(-1, 3)
        if not facing_up:
            tris = tris[:, ::-1]
        verts = np.column_stack([pts, np.full(len(pts), z)])
        normal = np.tile([0.0, 0.0, 1.0 if facing_up else -1.0], (len(pts), 1))
        parts.append(textured(verts, pts / TEXTURE_TILE_M, normal, tris))
    return merge(parts)


def wall_mesh(walls: list[Wall], windows: Sequence[Window] = ()) -> trimesh.Trimesh:
    """Every wall piece of a room as a box, the texture running along each wall, with a real
    opening where a window sits in it (the window model fills the opening; the outdoors shows
    through its glass)."""
    pieces: list[Wall] = []
    for w in walls:
        pieces += _cut_windows(w, [win for win in windows if _on_wall(win, w)])
    return merge([_wall_box(w) for w in pieces])


def _on_wall(window: Window, wall: Wall) -> bool:
    """Whether a window's centre lies inside a wall piece, its width along the wall."""
    if wall.kind != "wall" or wall.length < 1e-6:
        return False
    (ax, ay), (bx, by) = wall.a, wall.b
    dx, dy = (bx - ax) / wall.length, (by - ay) / wall.length
    px, py = window.position[0] - ax, window.position[1] - ay
    along, across = px * dx + py * dy, abs(-px * dy + py * dx)
    parallel = abs(math.cos(window.yaw) * dy - math.sin(window.yaw) * dx) < 0.1
    return parallel and across <= wall.thickness / 2 + 0.05 and 0.0 < along < wall.length \
        and wall.z0 < window.position[2] < wall.z1


def _cut_windows(wall: Wall, windows: list[Window]) -> list[Wall]:
    """The wall split into full-height pieces beside each window and pieces below and above it."""
    if not windows:
        return [wall]
    (ax, ay), (bx, by) = wall.a, wall.b
    dx, dy = (bx - ax) / wall.length, (by - ay) / wall.length

    def point(t: float) -> tuple[float, float]:
        return ax + dx * t, ay + dy * t

    def piece(t0: float, t1: float, z0: float, z1: float) -> Wall:
        return Wall(point(t0), point(t1), wall.thickness, z0, z1, wall.room, wall.kind)

    out, t = [], 0.0
    for win in sorted(windows, key=lambda v: (v.position[0] - ax) * dx + (v.position[1] - ay) * dy):
        centre = (win.position[0] - ax) * dx + (win.position[1] - ay) * dy
        t0, t1 = max(centre - win.width / 2, t), min(centre + win.width / 2, wall.length)
        z0 = max(win.position[2] - win.height / 2, wall.z0)
        z1 = min(win.position[2] + win.height / 2, wall.z1)
        if t1 - t0 < 1e-3 or z1 - z0 < 1e-3:
            continue
        if t0 - t > 1e-3:
            out.append(piece(t, t0, wall.z0, wall.z1))
        if z0 - wall.z0 > 1e-3:
            out.append(piece(t0, t1, wall.z0, z0))
        if wall.z1 - z1 > 1e-3:
            out.append(piece(t0, t1, z1, wall.z1))
        t = t1
    if wall.length - t > 1e-3:
        out.append(piece(t, wall.length, wall.z0, wall.z1))
    return out


def _wall_box(w: Wall) -> trimesh.Trimesh:
    (ax, ay), (bx, by) = w.a, w.b
    length = max(math.hypot(bx - ax, by - ay), 1e-3)
    d = np.array([(bx - ax) / length, (by - ay) / length])
    n = np.array([-d[1], d[0]]) * w.thickness / 2
    base = [np.array([ax, ay]) - n, np.array([bx, by]) - n, np.array([bx, by]) + n, np.array([ax, ay]) + n]
    faces: list[trimesh.Trimesh] = []
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


def _quad(corners: list[tuple], uvs_m: list[tuple], normal: tuple) -> trimesh.Trimesh:
    """Two triangles; ``uvs_m`` in metres (scaled to texture tiles here)."""
    verts = np.array(corners, dtype=float)
    uv = np.array(uvs_m, dtype=float) / TEXTURE_TILE_M
    return textured(verts, uv, np.tile(normal, (4, 1)), np.array([[0, 1, 2], [0, 2, 3]]))
