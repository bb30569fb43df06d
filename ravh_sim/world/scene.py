"""The World: one pybullet client that holds a whole house.

Like gym-pybullet-drones' BaseAviary, one class owns the physics client: it builds the house from a
:class:`House` and explicit :class:`Resolved` settings, keeps the table of instances (every labelled
object, door, window and each room's floor, ceiling and walls, each with a unique id and mask colour)
and changes the house at run time (doors, object models, paint) without rebuilding it.

The World owns the live :class:`~ravh_sim.world.state.WorldState` (:attr:`World.state`, started from
the settings) but does not write it: :class:`ravh_sim.world.appearance.Appearance` does, moving bodies
through the primitives here (:meth:`World.place_door`, :meth:`World.load_model`, :meth:`World.repaint`).

It also keeps what every body looks like (:attr:`World.visuals`: the mesh, its paint), as data: its
bodies have collision shapes only, and no renderer is known here. Renderers (ravh_sim.render) build
their own copy of the house from the visuals and redo it when the state says doors, models or paint
changed (ravh_sim.look.changes); the EGL plugin is never loaded (one GL context per process belongs to
ravh_sim.render).
"""
from __future__ import annotations

import contextlib
import math
import os
import sys
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pybullet as pb
import trimesh

from ravh_sim.files import cached_asset
from ravh_sim.poses import quaternion_from_yaw
from ravh_sim.world.dressing import dressing
from ravh_sim.world.footprint import STRUCTURE_KINDS, Instance, build_instances, dressing_instances
from ravh_sim.world.house import House, HouseObject, Wall
from ravh_sim.world.library import record
from ravh_sim.world.mesh import hulls_obj_text
from ravh_sim.world.settings import Resolved
from ravh_sim.world.solids import Placed, door_pose, object_parts
from ravh_sim.world.state import WorldState
from ravh_sim.world.structure import floor_mesh, solid_walls, wall_mesh

NON_SOLID_TYPES = frozenset({"Station"})      # drawn, but the robot starts on it
OPEN_DOOR_DROP = 50.0                          # m an open door's leaf sinks, out of every sensor's view
OWN_GROUP_BITS = range(8, 31)                  # collision group bits for bodies hidden from rays (the
                                               # lower ones are Bullet's default, static, ... groups)
ALL_GROUPS = -1
COMPOUND_LIMIT = 16
"""Shapes pybullet keeps of one ``createCollisionShapeArray`` call (its MAX_COMPOUND_COLLISION_SHAPES):
it drops every one beyond without a word, so a room's wall pieces go into compounds of at most this
many, the first on the walls body's base and the others on fixed links of it (a corridor of 26
pieces had lost 10, walls among them: the laser and the robot passed through walls the camera
drew)."""
CEILING_PAINT = "white"
GROUND_HALF_SIZE = 60.0


def connect() -> int:
    """A headless pybullet client (DIRECT: physics, ray casts and TinyRenderer images)."""
    return pb.connect(pb.DIRECT)


def disconnect(client: int) -> None:
    with _quiet_stdout():
        pb.disconnect(client)


class World:
    """A house built in its own pybullet client (DIRECT: headless)."""

    def __init__(self, house: House, settings: Resolved, physics_hz: float = 240.0) -> None:
        self.house = house
        self.state = WorldState(settings)
        self.physics_hz = physics_hz
        self.client = connect()
        self.visuals: dict[int, Visual] = {}     # pybullet body -> what it looks like
        pb.setGravity(0, 0, -9.81, physicsClientId=self.client)
        pb.setTimeStep(1.0 / physics_hz, physicsClientId=self.client)
        self._models_now: dict[str, int] = {}     # object -> model of its body, once load_model swapped it
        self._parked: dict[tuple[str, int], tuple] = {}      # (object, model) -> swapped-out body (load_model)
        self._model_shapes: dict[Path, int] = {}             # fitted library model's cached OBJ -> its shape
        self.instances: list[Instance] = []
        self._by_name: dict[str, Instance] = {}
        self.triangle_count = 0
        self._ray_groups: dict[int, int] = {}
        self.floor_z = float(np.median([r.floor_z for r in house.rooms]))
        self._build()

    # ------------------------------------------------------------------ life cycle
    def close(self) -> None:
        if self.client >= 0:
            disconnect(self.client)
            self.client = -1

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ lookups
    def instance(self, name: str) -> Instance:
        return self._by_name[name]

    def body_to_instance_lut(self) -> np.ndarray:
        """Array mapping pybullet body id -> instance id (0 for bodies that are not instances)."""
        c = self.client
        top = max(pb.getBodyUniqueId(i, physicsClientId=c) for i in range(pb.getNumBodies(physicsClientId=c)))
        lut = np.zeros(top + 1, dtype=np.int32)          # every body (robots too) has an entry
        for inst in self.instances:
            if inst.body >= 0:                           # a dressing object never shown has no body
                lut[inst.body] = inst.id
        return lut

    def ray_mask(self, hidden: Iterable[int] = ()) -> int:
        """The ``collisionFilterMask`` of a ray test that sees every body except ``hidden`` ones.

        Bullet's ray tests cannot skip bodies, only collision groups outside their mask: the first
        time a body is hidden it gets a group bit of its own on every link (its mask stays 'all',
        so its contacts do not change). A robot's laser thus never sees its own body, wherever its
        beams start, while every other robot's laser does.
        """
        mask = ALL_GROUPS
        for body in hidden:
            if body not in self._ray_groups:
                if len(self._ray_groups) == len(OWN_GROUP_BITS):
                    raise RuntimeError(f"at most {len(OWN_GROUP_BITS)} bodies can be hidden from rays")
                group = 1 << OWN_GROUP_BITS[len(self._ray_groups)]
                for link in range(-1, pb.getNumJoints(body, physicsClientId=self.client)):
                    pb.setCollisionFilterGroupMask(body, link, group, ALL_GROUPS, physicsClientId=self.client)
                self._ray_groups[body] = group
            mask &= ~self._ray_groups[body]
        return mask

    def cast_rays(self, starts: np.ndarray, ends: np.ndarray, mask: int = ALL_GROUPS
                  ) -> tuple[np.ndarray, np.ndarray]:
        """(first body hit or -1, hit point) per ray from ``starts`` (N, 3) to ``ends`` (N, 3), among
        the bodies ``mask`` sees (:meth:`ray_mask`); points of rays that hit nothing are NaN."""
        hits = pb.rayTestBatch(starts, ends, collisionFilterMask=mask, physicsClientId=self.client)
        bodies = np.fromiter((h[0] for h in hits), np.int64, len(hits))
        points = np.array([h[3] for h in hits], np.float64).reshape(-1, 3)
        points[bodies < 0] = np.nan
        return bodies, points

    # ------------------------------------------------------------------ building
    def _build(self) -> None:
        # The ground: a thin slab just under the floors (the robot drives on it; it also shows as the
        # ground outside). Not a GEOM_PLANE, which crashes pybullet's EGL plugin.
        ground = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[GROUND_HALF_SIZE, GROUND_HALF_SIZE, 0.05],
                                         physicsClientId=self.client)
        self.ground = pb.createMultiBody(0, ground, -1, basePosition=[0, 0, self.floor_z - 0.051],
                                         physicsClientId=self.client)
        self.instances = build_instances(self.house)
        self._by_name = {inst.name: inst for inst in self.instances}
        for inst in self.instances:
            if inst.kind in STRUCTURE_KINDS:
                inst.body = self._structure_body(inst)
            else:
                inst.body = self._object_body(self.house.object(inst.name), self.state.models[inst.name])
                if inst.kind == "door":
                    self.place_door(inst.name, self.state.doors[inst.name])
        self._add_dressing()

    def _structure_body(self, inst: Instance) -> int:
        room = self.house.room(inst.room)
        if inst.kind == "walls":
            walls = solid_walls(self.house, room.id)
            body = self._mesh_body(wall_mesh(walls, self.house.windows), self._wall_collision(walls), "walls")
            self._apply_paint(body, self.state.paint[room.id]["walls"])
        elif inst.kind == "floor":
            body = self._mesh_body(floor_mesh(room, room.floor_z), [-1], "floor")
            self._apply_paint(body, self.state.paint[room.id]["floor"])
        else:
            body = self._mesh_body(floor_mesh(room, room.ceiling_z, facing_up=False), [-1], "ceiling")
            self._apply_paint(body, CEILING_PAINT)
        return body

    def _wall_collision(self, walls: list[Wall]) -> list[int]:
        """The wall pieces as boxes, in compounds of at most COMPOUND_LIMIT (one body's base and links)."""
        compounds = []
        for first in range(0, len(walls), COMPOUND_LIMIT):
            half, pos, orn = [], [], []
            for w in walls[first:first + COMPOUND_LIMIT]:
                (ax, ay), (bx, by) = w.a, w.b
                half.append([max(w.length, 0.01) / 2, w.thickness / 2, (w.z1 - w.z0) / 2])
                pos.append([(ax + bx) / 2, (ay + by) / 2, (w.z0 + w.z1) / 2])
                orn.append(quaternion_from_yaw(math.atan2(by - ay, bx - ax)))
            compounds.append(pb.createCollisionShapeArray([pb.GEOM_BOX] * len(half), halfExtents=half,
                                                          collisionFramePositions=pos,
                                                          collisionFrameOrientations=orn, physicsClientId=self.client))
        return compounds

    def _object_body(self, obj: HouseObject, model: int) -> int:
        """The object's model, colliding part by part (see :mod:`ravh_sim.world.solids`); a door is
        its leaf, which :meth:`place_door` then puts in the doorway or out of the house."""
        placed = object_parts(self.house, obj, model)
        if obj.type in NON_SOLID_TYPES:
            collision = -1
        elif placed.model is not None:
            collision = self._model_collision(placed.model)
        else:
            collision = self._parts_collision(placed)
        mesh = placed.mesh() if placed.model is None else None
        shown = mesh if mesh is not None else placed.model
        assert shown is not None, "a part has a model or a mesh"
        self.triangle_count += len(shown.faces)
        body = self._new_body(collision, placed.position, placed.yaw)
        self.visuals[body] = Visual(mesh=mesh, model=placed.model)
        return body

    def _model_collision(self, fitted: trimesh.Trimesh) -> int:
        """A library model collides as its own triangles (a static concave mesh: exact for the laser,
        which then sees what the camera draws), every one of them, glass included (glass is opaque
        to every sensor, :mod:`ravh_sim.world.library`), loaded from a cached OBJ file. The same
        model fitted to the same box (a table's four plates, a row of chairs) shares one shape: a
        shape costs ~0.5 kB a triangle, and never leaves the client (see :meth:`load_model`)."""
        key = record(fitted).id.encode() + np.round(fitted.vertices, 5).tobytes()
        path = cached_asset(key, ".obj", lambda p: fitted.export(p, file_type="obj", include_normals=False,
                                                              include_texture=False))
        if path not in self._model_shapes:
            self._model_shapes[path] = pb.createCollisionShape(
                pb.GEOM_MESH, fileName=str(path), flags=pb.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=self.client)
        return self._model_shapes[path]

    def _parts_collision(self, placed: Placed) -> int:
        """A compound of one convex hull per model part, loaded from a cached OBJ file."""
        text = hulls_obj_text(placed.parts)
        path = cached_asset(text.encode(), ".obj", lambda p: p.write_text(text))
        return pb.createCollisionShape(pb.GEOM_MESH, fileName=str(path), physicsClientId=self.client)

    def _mesh_body(self, mesh: trimesh.Trimesh, collisions: list[int], surface: str) -> int:
        """A piece of structure drawn as ``mesh``, colliding as ``collisions`` (the base's shape, then
        one per fixed link; ``[-1]``: none)."""
        self.triangle_count += len(mesh.faces)
        body = self._new_body(collisions[0], (0, 0, 0), 0.0, links=collisions[1:])
        self.visuals[body] = Visual(structure=mesh, surface=surface)
        return body

    def _new_body(self, collision: int, position, yaw: float, links: list[int] | None = None) -> int:
        """A static body with no visual shape (renderers draw from :attr:`visuals`). ``links``: more
        collision shapes, each on a link fixed to the base at its origin (rays and contacts report
        the body, so it stays one instance)."""
        n = len(links or ())
        origin, identity = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]
        return pb.createMultiBody(0, collision, -1, basePosition=list(position),
                                  baseOrientation=quaternion_from_yaw(yaw), linkMasses=[0.0] * n,
                                  linkCollisionShapeIndices=list(links or ()), linkVisualShapeIndices=[-1] * n,
                                  linkPositions=[origin] * n, linkOrientations=[identity] * n,
                                  linkInertialFramePositions=[origin] * n,
                                  linkInertialFrameOrientations=[identity] * n, linkParentIndices=[0] * n,
                                  linkJointTypes=[pb.JOINT_FIXED] * n, linkJointAxis=[[0.0, 0.0, 1.0]] * n,
                                  physicsClientId=self.client)

    def _apply_paint(self, body: int, paint: str) -> None:
        self.visuals[body].paint = paint

    # ------------------------------------------------------------------ body primitives (for Appearance)
    def place_door(self, door_id: str, is_open: bool) -> None:
        """Put a door's leaf out of the house (open, as upstream hides it) or in the doorway (closed)."""
        (x, y, z), yaw = door_pose(self.house, self.house.door_by_id[door_id])
        pb.resetBasePositionAndOrientation(self._by_name[door_id].body, [x, y, z - OPEN_DOOR_DROP * is_open],
                                           quaternion_from_yaw(yaw), physicsClientId=self.client)

    def load_model(self, object_id: str, model: int) -> None:
        """Replace an object's body by model variant ``model`` (visual and collision); a door's new
        leaf goes where the state says the door is."""
        # pybullet frees neither a removed body's memory (~2 kB per hull part) nor its shapes, so the old
        # body is parked out of the house like an open door's leaf and comes back with its model.
        inst, c = self._by_name[object_id], self.client
        position, orientation = pb.getBasePositionAndOrientation(inst.body, physicsClientId=c)
        pb.resetBasePositionAndOrientation(inst.body, [*position[:2], position[2] - OPEN_DOOR_DROP], orientation,
                                           physicsClientId=c)
        old = self._models_now.get(object_id, self.state.models[object_id])
        self._parked[object_id, old] = (inst.body, self.visuals.pop(inst.body), position, orientation)
        if (object_id, model) in self._parked:
            inst.body, self.visuals[inst.body], position, orientation = self._parked.pop((object_id, model))
            pb.resetBasePositionAndOrientation(inst.body, position, orientation, physicsClientId=c)
        else:
            inst.body = self._object_body(self.house.object(object_id), model)
        self._models_now[object_id] = model
        if inst.kind == "door":
            self.place_door(object_id, self.state.doors[object_id])

    def repaint(self, room_id: str, surface: str, paint: str) -> None:
        """Paint a room's ``walls`` or ``floor`` body."""
        self._apply_paint(self._by_name[f"{room_id}/{surface}"].body, paint)

    # ------------------------------------------------------------------ dressing (ravh_sim.world.dressing)
    def _add_dressing(self) -> None:
        """The dressing objects the seed may place, as instances (body -1 until first shown), and those
        of the state's level shown."""
        self._dressing_visuals: dict[int, Visual] = {}           # parked dressing body -> its look
        self._dressing_poses: dict[str, tuple] = {}               # shown dressing object -> (position, yaw)
        extra = dressing_instances(self.house, self.state.seed)
        self.instances += extra
        self._by_name.update({inst.name: inst for inst in extra})
        self.dress(self.state.dressing, self.state.models)

    def dress(self, level: str, models: Mapping[str, int]) -> None:
        """Show the dressing of ``level`` as the layout for object ``models`` places it; every other
        dressing body is parked out of the house like an open door's leaf (a body is made when first
        shown and kept; its look leaves :attr:`visuals` while parked, so renderers skip it)."""
        shown = {d.id: d for d in dressing(self.house, models, level, self.state.seed)}
        c = self.client
        for inst in self.instances:
            if inst.kind != "dressing":
                continue
            placed = shown.get(inst.name)
            if placed is None:
                if inst.body >= 0 and inst.body in self.visuals:
                    position, orientation = pb.getBasePositionAndOrientation(inst.body, physicsClientId=c)
                    pb.resetBasePositionAndOrientation(inst.body, [*position[:2], position[2] - OPEN_DOOR_DROP],
                                                       orientation, physicsClientId=c)
                    self._dressing_visuals[inst.body] = self.visuals.pop(inst.body)
                    self._dressing_poses.pop(inst.name, None)
                continue
            pose = (placed.position, placed.yaw)
            if inst.body < 0:
                inst.body = self._dressing_body(placed.placed(), placed.slot.collides)
            elif self._dressing_poses.get(inst.name) != pose:     # (a body left as it is keeps its bits)
                pb.resetBasePositionAndOrientation(inst.body, list(placed.position), quaternion_from_yaw(placed.yaw),
                                                   physicsClientId=c)
            self._dressing_poses[inst.name] = pose
            if inst.body in self._dressing_visuals:
                self.visuals[inst.body] = self._dressing_visuals.pop(inst.body)

    def _dressing_body(self, placed: Placed, collides: bool) -> int:
        """A dressing object's body: its fitted model, colliding as its triangles unless it does not."""
        assert placed.model is not None
        collision = self._model_collision(placed.model) if collides else -1
        self.triangle_count += len(placed.model.faces)
        body = self._new_body(collision, placed.position, placed.yaw)
        self.visuals[body] = Visual(model=placed.model)
        return body

    # ------------------------------------------------------------------ poses
    def object_pose(self, name: str) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """Position and orientation (x, y, z, w) of an instance's body as the world has it now."""
        pos, orn = pb.getBasePositionAndOrientation(self._by_name[name].body, physicsClientId=self.client)
        return tuple(pos), tuple(orn)



@dataclass
class Visual:
    """What a body looks like: a palette-coloured model or a fitted library model (in its body
    frame), or a painted piece of structure (in the house frame) with its current paint."""
    mesh: trimesh.Trimesh | None = None
    model: trimesh.Trimesh | None = None
    structure: trimesh.Trimesh | None = None
    surface: str = ""                      # walls | floor | ceiling for structure
    paint: str = ""


@contextlib.contextmanager
def _quiet_stdout() -> Iterator[None]:
    """Silence C-level stdout (the EGL plugin prints its GL banner there), so CLI output stays clean."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)

