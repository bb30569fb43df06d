"""ravh_sim's physically based OpenGL renderer (moderngl on the process's EGL context).

One forward pass shades each pixel once (the cost on a CPU rasteriser is fragments, see
shared/notes/rendering-probe.md) and writes three aligned targets from the same triangles: HDR
colour, z-depth in metres and the instance id, so depth, masks and RGB can never disagree. The
expensive light transport is computed when the scene changes, not per frame: the sun's shadow map
(orthographic over the house; the ceiling and walls shadow the rooms, so sunlight enters only
through the window openings), one cube shadow map per switched-on lamp (walls confine its light;
open doors let it through) and a top-down coverage map that gives floors their ambient occlusion.
Per frame: the bodies whose boxes meet the view (gl_culling), the procedural sky behind the
windows, then the camera's side (gl_develop: metering, exposure or a sensor's development, read-back;
a frame of non-finite radiance is refused, never returned black). ``fast`` quality draws
every surface with the plain material in one pass, skips shadow look-ups and reflections, and
confines lamps to their room instead. ``dataset`` quality shades as ``realistic`` does and draws the
library's dataset level of detail (finer models and textures, :mod:`ravh_sim.world.library`).

What is lit and how brightly is decided by the scene's light model (ravh_sim.look.lighting, shared with
every renderer); which of its parts to redo by the change report (ravh_sim.look.changes).
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import cv2
import numpy as np

from ravh_sim.look.changes import ChangeWatch
from ravh_sim.look.geometry import ATTRIBUTES, VERTEX_FORMAT, SceneBuilder
from ravh_sim.look.lighting import LAMP_POWER, SceneLights, WindowLight, scene_lights, window_lights
from ravh_sim.look.materials import NOISE_TEXELS, PATTERN, TEXELS, MaterialTable, noise_volume
from ravh_sim.render import gl_programs
from ravh_sim.render.backend import gl_context, unlocked_gl
from ravh_sim.render.gl_culling import DrawRuns
from ravh_sim.render.gl_develop import FrameDeveloper
from ravh_sim.render.gl_programs import KINDS, MAX_LIGHTS, MAX_ROOMS, MAX_WINDOWS, WINDOW_SPAN, mat, source, uniform
from ravh_sim.render.projection import look_at, orthographic, perspective, projection_from_K, view_matrix
from ravh_sim.render.views import Development, RenderedViews
from ravh_sim.world.geometry import polygon_centroid
from ravh_sim.world.house import Light
from ravh_sim.world.library import Detail
from ravh_sim.world.scene import World
from ravh_sim.world.topology import room_index_raster, room_links

if TYPE_CHECKING:
    import moderngl

FRAME_LIGHTS = 4                      # lights shading one frame (the nearest; at most 8: u_room_lights)
assert FRAME_LIGHTS <= 8, "u_room_lights packs light indices in 3 bits"
FRAME_LIGHT_REACH = 9.0               # m: lights farther from the camera are left out of a frame
SUN_SHADOW_TEXELS = 2048
LAMP_TILE = 192                       # texels per cube face of a lamp's shadow map
PROBE_TILE = 64                       # texels per cube face of a room's reflection probe
PROBE_HEIGHT = 1.3                    # m above the floor where a room's probe sits
PROBE_FAR = 30.0
FACE_AXES = (((1, 0, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1)), ((0, 1, 0), (0, 0, 1)),
             ((0, -1, 0), (0, 0, 1)), ((0, 0, 1), (0, 1, 0)), ((0, 0, -1), (0, 1, 0)))
SHADOW_FORMAT = "3f 3x4 3x4 1f 1x4 2x4"  # position and material of each vertex (geometry.VERTEX_FORMAT)
COVERAGE_TEXELS = 512
ROOM_MAP_RESOLUTION = 0.05            # m per cell of the floor-plan room map
COVERAGE_BLUR_M = 0.12                # sigma of the floor occlusion blur




def _either(texture: moderngl.Texture | None, stand_in: moderngl.Texture) -> moderngl.Texture:
    """A texture, or a stand-in bound in its place where a quality has none (never sampled then)."""
    return texture if texture is not None else stand_in


class GLRenderer:
    """Renders one World for one camera model (K, size, clip planes) at one quality."""

    def __init__(self, world: World, K: np.ndarray, width: int, height: int, near: float, far: float,
                 quality: str = "realistic") -> None:
        ctx = gl_context()
        if ctx is None:
            raise RuntimeError("no OpenGL context: use the tiny renderer")
        self.ctx, self.world = ctx, world
        self.gl = unlocked_gl()
        self.width, self.height, self.near, self.far = width, height, near, far
        self.K = np.asarray(K, np.float64)
        self.shadows = quality in ("realistic", "dataset")
        self.projection = projection_from_K(K, width, height, near, far)
        detail: Detail = "dataset" if quality == "dataset" else "live"
        self.materials = MaterialTable(detail)
        self.builder = SceneBuilder(world, self.materials, detail)
        header = gl_programs.header()
        self._uniforms: dict[tuple[str, tuple[int, ...]], list[moderngl.Uniform]] = {}     # see _set
        self.scene_programs = {k: ctx.program(vertex_shader=header + source("scene.vert"),
                                              fragment_shader=gl_programs.header(k) + source("scene.frag"))
                               for k in range(len(PATTERN))}
        self.depth_program = ctx.program(vertex_shader=header + source("scene.vert"),
                                         fragment_shader=header + "void main() {}\n")
        self._patterns: list[int] = []                      # the patterns the scene has, a program each
        self._lights: list[Light] = []
        self.sky_program = ctx.program(vertex_shader=header + source("fullscreen.vert"),
                                       fragment_shader=header + source("sky.frag"))
        self.shadow_program = ctx.program(vertex_shader=header + source("shadow.vert"),
                                          fragment_shader=header + source("shadow.frag"))
        self.coverage_program = ctx.program(vertex_shader=header + source("coverage.vert"),
                                            fragment_shader=header + source("coverage.frag"))
        self.empty_vao = ctx.vertex_array(self.sky_program, [])
        size = (width, height)
        self.hdr = ctx.texture(size, 4, dtype="f2")
        self.hdr.repeat_x = self.hdr.repeat_y = False      # a motion sweep repeats the edge pixels
        self.depth = ctx.texture(size, 1, dtype="f4")
        self.instance = ctx.texture(size, 1, dtype="i4")
        for texture in (self.depth, self.instance):
            texture.filter = (ctx.NEAREST, ctx.NEAREST)
        self.main_fbo = ctx.framebuffer([self.hdr, self.depth, self.instance], ctx.depth_renderbuffer(size))
        self.developer = FrameDeveloper(ctx, self.gl, self.K, far, self.hdr, self.depth, self.instance)
        self.sun_depth = ctx.depth_texture((SUN_SHADOW_TEXELS, SUN_SHADOW_TEXELS))
        self.sun_depth.compare_func = "<="
        self.sun_depth.filter = (ctx.LINEAR, ctx.LINEAR)
        self.sun_fbo = ctx.framebuffer(depth_attachment=self.sun_depth)
        self.coverage_raw = ctx.texture((COVERAGE_TEXELS, COVERAGE_TEXELS), 1, dtype="f4")
        self.coverage_fbo = ctx.framebuffer([self.coverage_raw])
        self.coverage = ctx.texture((COVERAGE_TEXELS, COVERAGE_TEXELS), 1, dtype="f4")
        self.coverage.repeat_x = self.coverage.repeat_y = False
        self.noise = ctx.texture3d((NOISE_TEXELS,) * 3, 4, noise_volume().tobytes())
        self.noise.repeat_x = self.noise.repeat_y = self.noise.repeat_z = True

        self.atlas: moderngl.Texture | None = None
        self.atlas_fbo: moderngl.Framebuffer | None = None
        self.instance_texture: moderngl.Texture | None = None        # made by _upload_instances
        self.room_light: moderngl.Texture | None = None
        self.probes: moderngl.Texture | None = None
        self.probe_fbo: moderngl.Framebuffer | None = None
        self.probe_boxes: moderngl.Texture | None = None
        labels, origin = room_index_raster(world.house, ROOM_MAP_RESOLUTION)
        self.room_map = self._nearest_texture((labels.shape[1], labels.shape[0]), labels.astype(np.float32), 1)
        self.room_map.repeat_x = self.room_map.repeat_y = False
        height_m, width_m = np.asarray(labels.shape) * ROOM_MAP_RESOLUTION
        self._room_box = (origin[0] - ROOM_MAP_RESOLUTION / 2, origin[1] - ROOM_MAP_RESOLUTION / 2,
                          1.0 / width_m, 1.0 / height_m)
        self.vbo: moderngl.Buffer | None = None
        self.material_texture: moderngl.Texture | None = None
        self.library_textures: moderngl.TextureArray | None = None
        self._library_layers: list[str] | None = None
        self.vaos: dict[str, moderngl.VertexArray] = {}
        self._room_vaos: dict[str, tuple[moderngl.VertexArray, moderngl.VertexArray, moderngl.Buffer]] = {}
        self._changes = ChangeWatch(world.state)
        self._lights_on: frozenset[str] | None = None
        self._shadowed: set[str] = set()                  # lights whose cube map is current
        self._light_row = {lt.id: row for row, lt in enumerate(world.house.lights)}
        self._room_links = room_links(world.house)    # looked up once: hashing a House to find them is slow
        self._bounds = (np.zeros(3), np.ones(3))
        self._sun_matrix = np.eye(4)
        self._windows = self._window_table(window_lights(world.house))

    def release(self) -> None:
        """Free the GPU objects (the context stays: it belongs to the process)."""
        self.developer.release()
        for obj in (*self.scene_programs.values(), self.depth_program, self.sky_program,
                    self.shadow_program, self.coverage_program,
                    self.hdr, self.depth, self.instance, self.main_fbo, self.sun_depth, self.sun_fbo,
                    self.coverage_raw, self.coverage_fbo,
                    self.coverage, self.noise, self.room_map, self.room_light, self.instance_texture,
                    self.probes, self.probe_fbo, self.probe_boxes, self.atlas, self.atlas_fbo, self.vbo,
                    self.material_texture, self.library_textures,
                    *self.vaos.values(),
                    *(obj for subset in self._room_vaos.values() for obj in subset)):
            if obj is not None:
                obj.release()

    # ------------------------------------------------------------------ scene state
    def _sync(self) -> None:
        """Bring GPU geometry, light state and the light maps up to date with the World, redoing
        only what the change report (ravh_sim.look.changes) says moved: geometry redoes everything,
        the sun its shadow map and every probe, a switched light its own cube map and the probes of
        the rooms it reaches."""
        world = self.world
        change = self._changes.poll()
        if change.geometry:
            self._upload_geometry()
            self._render_coverage()
            self._lights_on = None
            self._shadowed.clear()
        if not change.lighting:
            return
        if change.every_lamp:
            self._lights_on = None                # every light's colour moved: relight every room
        scene = scene_lights(world.house, world.state)
        on = frozenset(lt.id for lt in scene.lamps)
        switched = on ^ self._lights_on if self._lights_on is not None else None
        self._upload_instances(scene)
        self._set_lighting(scene)
        self._lights_on = on
        if not self.shadows:
            return
        if change.sun:
            self._render_sun_shadow(scene.sun.direction)
        self._render_lamp_shadows([lt for lt in scene.lamps if lt.id not in self._shadowed])
        self._bind_textures()
        if change.sun or switched is None:
            self._render_probes([room.id for room in world.house.rooms])
        else:
            by_id = world.house.light_by_id
            self._render_probes(sorted({r for lid in switched for r in self._lit_rooms(by_id[lid].room)}))

    def _upload_geometry(self) -> None:
        vertices = self.builder.build()
        patterns = np.array([PATTERN[m.pattern] for m in self.materials.materials])
        triangle_pattern = patterns[vertices[::3, 9].astype(np.int64)]
        order = np.argsort(triangle_pattern, kind="stable")
        vertices = vertices.reshape(-1, 3, vertices.shape[1])[order].reshape(vertices.shape)
        counts = np.bincount(triangle_pattern, minlength=len(PATTERN))
        self._patterns = [k for k in range(len(PATTERN)) if counts[k]]
        if not self.shadows:                      # fast: every surface in one plain-material draw
            self._patterns = [PATTERN["plain"]]
        self._runs = DrawRuns.of(vertices, triangle_pattern[order], PATTERN["plain"] if not self.shadows else None)
        positions = vertices[:, :3]
        self._bounds = (positions.min(axis=0), positions.max(axis=0))
        if self.vbo is not None:
            self.vbo.release()
            for vao in self.vaos.values():
                vao.release()
            for subset in self._room_vaos.values():
                for obj in subset:
                    obj.release()
        self.vbo = self.ctx.buffer(vertices)
        self._room_vaos = self._room_subsets(vertices)
        self.vaos = {
            **{f"scene{k}": self._scene_vao(self.scene_programs[k]) for k in self._patterns},
            "depth": self.ctx.vertex_array(self.depth_program, [(self.vbo, "3f 40x", "in_position")]),
            "shadow": self.ctx.vertex_array(self.shadow_program, [(self.vbo, SHADOW_FORMAT, "in_position",
                                                                   "in_material")]),
            "coverage": self.ctx.vertex_array(self.coverage_program, [
                (self.vbo, "3f 3x4 3x4 1x4 1f 2x4", "in_position", "in_instance")]),
        }
        table = self.materials.pack()
        if self.material_texture is not None:
            self.material_texture.release()
        self.material_texture = self.ctx.texture((TEXELS, len(table)), 4, table.tobytes(), dtype="f4")
        self.material_texture.filter = (self.ctx.NEAREST, self.ctx.NEAREST)
        if self._library_layers != self.materials.textures:
            self._upload_library_textures()

    def _scene_vao(self, program: moderngl.Program, index_buffer: moderngl.Buffer | None = None
                   ) -> moderngl.VertexArray:
        """A shading program's view of the vertex buffer; a pattern's program that reads no texture
        coordinate has no ``in_uv`` (skipped)."""
        return self.ctx.vertex_array(program, [(self.vbo, VERTEX_FORMAT, *ATTRIBUTES)],
                                     index_buffer=index_buffer, skip_errors=True)

    def _upload_library_textures(self) -> None:
        """The library textures in use as one mipmapped, repeating texture array (layer = the
        material's ``layer``)."""
        layers = self.materials.texture_layers()
        if self.library_textures is not None:
            self.library_textures.release()
        count, height, width, _ = layers.shape
        self.library_textures = self.ctx.texture_array((width, height, count), 3, layers.tobytes())
        self.library_textures.build_mipmaps()
        self._library_layers = list(self.materials.textures)

    def _room_subsets(self, vertices: np.ndarray
                      ) -> dict[str, tuple[moderngl.VertexArray, moderngl.VertexArray, moderngl.Buffer]]:
        """Per room, (shadow VAO, probe VAO) over only the triangles of that room and the rooms open
        to it: what a lamp's shadow map or a room's probe can see (walls hide the rest), so those
        many small renders do not each process the whole house."""
        house = self.world.house
        room_of_instance = {inst.id: inst.room for inst in self.world.instances}
        vertex_room = np.array([room_of_instance.get(int(i), "") for i in vertices[::3, 10]])
        out = {}
        for room in house.rooms:
            triangles = np.flatnonzero(np.isin(vertex_room, sorted(self._lit_rooms(room.id))))
            indices = (triangles[:, None] * 3 + np.arange(3)).astype(np.int32).ravel()
            ibo = self.ctx.buffer(indices.tobytes())
            out[room.id] = (
                self.ctx.vertex_array(self.shadow_program, [(self.vbo, SHADOW_FORMAT, "in_position",
                                                             "in_material")], index_buffer=ibo),
                self._scene_vao(self.scene_programs[PATTERN["plain"]], ibo),
                ibo)
        return out

    def _upload_instances(self, scene: SceneLights) -> None:
        """Per instance: its room, a fixture's glow and the kind, the room's floor and ceiling
        heights; per room: its sky and bounce light, and which windows are its own."""
        house, world = self.world.house, self.world
        rooms = {room.id: i for i, room in enumerate(house.rooms)}
        glow = scene.glow
        size = max(inst.id for inst in world.instances) + 1
        data = np.zeros((3, size, 4), np.float32)
        for inst in world.instances:
            room = house.room(inst.room)
            data[0, inst.id, 3] = rooms[inst.room]
            data[1, inst.id] = (*glow.get(inst.name, (0.0, 0.0, 0.0)), KINDS[inst.kind])
            data[2, inst.id, :2] = (room.floor_z, room.ceiling_z)
        spans = self._windows[2]
        ambient = np.zeros((len(house.rooms), 4), np.float32)
        for row, room in enumerate(house.rooms):
            first, count = spans.get(room.id, (0, 0))
            ambient[row] = (*scene.room_ambient[room.id], first + WINDOW_SPAN * count)
        self.instance_texture = self._replace(self.instance_texture, self._nearest_texture((size, 3), data))
        self.room_light = self._replace(self.room_light, self._nearest_texture((len(house.rooms), 1), ambient))

    @staticmethod
    def _replace(old: moderngl.Texture | None, new: moderngl.Texture) -> moderngl.Texture:
        if old is not None:
            old.release()
        return new

    def _nearest_texture(self, size: tuple[int, int], data: np.ndarray, components: int = 4) -> moderngl.Texture:
        texture = self.ctx.texture(size, components, np.ascontiguousarray(data, np.float32).tobytes(), dtype="f4")
        texture.filter = (self.ctx.NEAREST, self.ctx.NEAREST)
        return texture

    def _set_lighting(self, scene: SceneLights) -> None:
        outdoors = scene.outdoors
        uniforms = {
            "u_sun_dir": outdoors.sun_direction, "u_sun_irradiance": outdoors.sun_irradiance,
            "u_sun_radiance": outdoors.sun_radiance, "u_sky_zenith": outdoors.sky_zenith,
            "u_sky_horizon": outdoors.sky_horizon, "u_outdoor_light": outdoors.light,
            "u_outdoor_fill": outdoors.fill, "u_lit_windows": outdoors.lit_windows, "u_site": outdoors.site,
            "u_ground_z": outdoors.ground_z, "u_outdoor_seed": outdoors.seed,
        }
        for name, value in uniforms.items():
            self._set(name, value, also=(self.sky_program,))
        self._set("u_window_radiance", tuple(scene.window_radiance))
        self._set("u_window_centre", self._windows[0].tobytes())
        self._set("u_window_normal", self._windows[1].tobytes())
        self._set("u_shadows", int(self.shadows))
        self._lights = list(scene.lamps)

    def _set(self, name: str, value, also: tuple = ()) -> None:
        """Set a uniform on every scene program (and ``also``) that uses it; bytes are written raw. Which
        programs use it is looked up once: ``name in program`` walks all of a program's members, and a
        frame sets a few dozen uniforms on each of the programs."""
        key = (name, tuple(id(program) for program in also))
        uniforms = self._uniforms.get(key)
        if uniforms is None:
            uniforms = self._uniforms[key] = [uniform(program, name) for program in
                                              (*self.scene_programs.values(), *also) if name in program]
        for member in uniforms:
            if isinstance(value, bytes):
                member.write(value)
            else:
                member.value = value

    def _set_frame_lights(self, position: np.ndarray) -> None:
        """The lamps that can light this view: switched-on lights reaching the camera's room or a
        room open to it, the nearest FRAME_LIGHTS of them within FRAME_LIGHT_REACH (a CPU
        rasteriser pays for every light on every pixel)."""
        index = {room.id: i for i, room in enumerate(self.world.house.rooms)}
        assert len(index) <= MAX_ROOMS, f"the renderer takes {MAX_ROOMS} rooms"
        camera_room = self.world.house.room_at(float(position[0]), float(position[1]))
        around = self._lit_rooms(camera_room.id) if camera_room is not None else set(index)
        near = sorted((float(np.linalg.norm(np.asarray(lt.position) - position)), self._light_row[lt.id], lt)
                      for lt in self._lights if self._lit_rooms(lt.room) & around)
        chosen = [(row, lt) for d, row, lt in near if d < FRAME_LIGHT_REACH][:FRAME_LIGHTS]
        positions = np.zeros((MAX_LIGHTS, 4), np.float32)
        powers = np.zeros((MAX_LIGHTS, 4), np.float32)
        reaching: dict[int, list[int]] = {}          # room index -> the chosen lights reaching it
        for i, (row, lt) in enumerate(chosen):
            positions[i] = (*lt.position, lt.range)
            powers[i] = (*(np.asarray(lt.color) * lt.intensity * LAMP_POWER), row if self.shadows else -1)
            for room in self._lit_rooms(lt.room):
                reaching.setdefault(index[room], []).append(i)
        room_lights = np.zeros(MAX_ROOMS, np.int32)   # scene.frag: count in bits 0-3, then 3 bits per light
        for room_index, lights in reaching.items():
            room_lights[room_index] = len(lights) + sum(i << (4 + 3 * k) for k, i in enumerate(lights))
        self._set("u_light_position", positions.tobytes())
        self._set("u_light_power", powers.tobytes())
        self._set("u_room_lights", room_lights.tobytes())

    def _window_table(self, windows: list[WindowLight]) -> tuple[np.ndarray, np.ndarray, dict[str, tuple[int, int]]]:
        """The windows' area lights as the shader reads them, grouped by room: (centre, 0), (normal into
        its room, area) and each room's (first, count) in them, so a pixel visits only its own room's
        windows."""
        if len(windows) > MAX_WINDOWS:
            raise ValueError(f"house {self.world.house.number} has {len(windows)} windows; "
                             f"the renderer takes {MAX_WINDOWS}")
        centres = np.zeros((MAX_WINDOWS, 4), np.float32)
        normals = np.zeros((MAX_WINDOWS, 4), np.float32)
        spans: dict[str, tuple[int, int]] = {}
        for i, w in enumerate(windows):
            centres[i, :3] = w.centre
            normals[i] = (*w.normal, 0.0, w.area)
            first, count = spans.get(w.room, (i, 0))
            spans[w.room] = (first, count + 1)
        return centres, normals, spans

    def _lit_rooms(self, room: str) -> set[str]:
        """The rooms a light in ``room`` can reach: its own and (with shadows, which keep the light
        to what it can see) those joined to it by an open door or an archway."""
        rooms = {room}
        if self.shadows:
            doors = self.world.state.doors
            for link in self._room_links:
                if room in link.rooms and (link.door is None or doors.get(link.door, True)):
                    rooms.update(link.rooms)
        return rooms

    # ------------------------------------------------------------------ precomputed light
    def _render_sun_shadow(self, sun_direction: tuple[float, float, float]) -> None:
        lo, hi = self._bounds
        centre = (lo + hi) / 2
        radius = float(np.linalg.norm(hi - lo)) / 2 + 0.5
        direction = np.asarray(sun_direction)
        up = np.array([0.0, 0.0, 1.0]) if abs(direction[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
        view = look_at(-direction, up)
        view[:3, 3] = -view[:3, :3] @ (centre + direction * radius * 2)
        projection = orthographic(-radius, radius, -radius, radius, 0.1, radius * 4)
        matrix = projection @ view
        bias = np.array([[0.5, 0, 0, 0.5], [0, 0.5, 0, 0.5], [0, 0, 0.5, 0.5], [0, 0, 0, 1]])
        self._sun_matrix = bias @ matrix
        self._set("u_sun_matrix", mat(self._sun_matrix))
        self.sun_fbo.use()
        self.sun_fbo.clear(depth=1.0)
        self._draw_casters(matrix, np.zeros(3))

    def _draw_casters(self, matrix: np.ndarray, origin: np.ndarray, room: str | None = None) -> None:
        """Shadow casters into the framebuffer in use: the whole house, or a room's subset."""
        ctx = self.ctx
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        assert self.material_texture is not None, "uploaded with geometry"
        self.material_texture.use(0)
        uniform(self.shadow_program, "u_materials").value = 0
        uniform(self.shadow_program, "u_matrix").write(mat(matrix))
        uniform(self.shadow_program, "u_origin").value = tuple(float(v) for v in origin)
        uniform(self.shadow_program, "u_radial").value = int(room is not None)
        (self.vaos["shadow"] if room is None else self._room_vaos[room][0]).render()

    def _render_lamp_shadows(self, lights: list[Light]) -> None:
        """The cube shadow maps of ``lights``, each in its own row of the atlas (one row per light
        of the house, so switching one light redraws only its row)."""
        if self.atlas_fbo is None:
            size = (6 * LAMP_TILE, max(len(self.world.house.lights), 1) * LAMP_TILE)
            self.atlas = self.ctx.depth_texture(size)
            self.atlas.compare_func = "<="                # a look-up is the share of 2 x 2 texels lit
            self.atlas.filter = (self.ctx.LINEAR, self.ctx.LINEAR)
            self.atlas_fbo = self.ctx.framebuffer(depth_attachment=self.atlas)
            self._set("u_atlas_texels", (float(size[0]), float(size[1])))
            self._set("u_tile", float(LAMP_TILE))
        self.atlas_fbo.use()
        for lt in lights:
            row = self._light_row[lt.id]
            self.atlas_fbo.clear(depth=1.0, viewport=(0, row * LAMP_TILE, 6 * LAMP_TILE, LAMP_TILE))
            for face, matrix in enumerate(self._face_matrices(lt.range)):
                self.atlas_fbo.viewport = (face * LAMP_TILE, row * LAMP_TILE, LAMP_TILE, LAMP_TILE)
                self._draw_casters(matrix, np.asarray(lt.position), lt.room)
            self._shadowed.add(lt.id)
            self.gl.finish()            # rasterise before the next light: see _render_probes

    @staticmethod
    def _face_views() -> list[np.ndarray]:
        """Views of the six cube faces (+x, -x, +y, -y, +z, -z) from the origin (scene.frag's
        cube_texel inverts them in closed form: keep the two in step)."""
        return [look_at(np.array(f, float), np.array(u, float)) for f, u in FACE_AXES]

    def _face_matrices(self, reach: float) -> list[np.ndarray]:
        projection = perspective(math.pi / 2, 1.0, 0.02, max(reach, 0.1))
        return [projection @ view for view in self._face_views()]

    def _render_probes(self, rooms: list[str]) -> None:
        """The reflection probes of ``rooms``: each room seen from its middle in six directions,
        fully lit, so mirrors and glossy surfaces reflect the room they are in."""
        house = self.world.house
        if self.probe_fbo is None:
            size = (6 * PROBE_TILE, len(house.rooms) * PROBE_TILE)
            self.probes = self.ctx.texture(size, 4, dtype="f2")
            self.probe_fbo = self.ctx.framebuffer([self.probes], self.ctx.depth_renderbuffer(size))
            self.probe_boxes = self._nearest_texture((len(house.rooms), 3), self._probe_boxes())
            self._set("u_probe_texels", (float(size[0]), float(size[1])))
            self._set("u_probe_tile", float(PROBE_TILE))
        projection = perspective(math.pi / 2, 1.0, 0.05, PROBE_FAR)
        self._set("u_probes_ready", 0)
        self.probe_fbo.use()
        for row, room in enumerate(house.rooms):
            if room.id not in rooms:
                continue
            self.probe_fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0,
                                 viewport=(0, row * PROBE_TILE, 6 * PROBE_TILE, PROBE_TILE))
            x, y = polygon_centroid(room.floor)
            centre = np.array([x, y, room.floor_z + PROBE_HEIGHT])
            self._set_frame_lights(centre)
            for face, view in enumerate(self._face_views()):
                view = view.copy()
                view[:3, 3] = -view[:3, :3] @ centre
                self.probe_fbo.viewport = (face * PROBE_TILE, row * PROBE_TILE, PROBE_TILE, PROBE_TILE)
                self._draw_probe_face(view, projection @ view, centre, room.id)
            # rasterised room by room: llvmpipe keeps binned triangles until it rasterises them,
            # and every room's six faces binned at once held ~50 MB in house 23 (a node's peak RSS)
            self.gl.finish()
        self._set("u_probes_ready", 1)

    def _render_coverage(self) -> None:
        lo, hi = self._bounds
        span = max(hi[0] - lo[0], hi[1] - lo[1]) + 1.0
        x0, y0 = (lo[0] + hi[0] - span) / 2, (lo[1] + hi[1] - span) / 2
        view = look_at(np.array([0.0, 0.0, -1.0]), np.array([0.0, 1.0, 0.0]))
        view[:3, 3] = -view[:3, :3] @ np.array([0.0, 0.0, hi[2] + 1.0])
        matrix = orthographic(x0, x0 + span, y0, y0 + span, 0.1, hi[2] - lo[2] + 2.0) @ view
        ctx = self.ctx
        self.coverage_fbo.use()
        self.coverage_fbo.clear(0.0, 0.0, 0.0, 0.0)
        ctx.disable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        self._upload_instances(scene_lights(self.world.house, self.world.state, lamps_on=False))
        assert self.instance_texture is not None, "uploaded just above"
        self.instance_texture.use(0)
        uniform(self.coverage_program, "u_instances").value = 0
        uniform(self.coverage_program, "u_matrix").write(mat(matrix))
        self.vaos["coverage"].render()
        self.gl.finish()
        raw = np.frombuffer(self.coverage_raw.read(), np.float32).reshape(COVERAGE_TEXELS, COVERAGE_TEXELS)
        sigma = COVERAGE_BLUR_M * COVERAGE_TEXELS / span
        blurred = cv2.GaussianBlur(np.ascontiguousarray(raw), (0, 0), sigma)
        self.coverage.write(np.ascontiguousarray(blurred, np.float32).tobytes())
        self._set("u_coverage_box", (x0, y0, 1.0 / span, 1.0 / span))

    # ------------------------------------------------------------------ frames
    def _bind_textures(self) -> None:
        assert self.instance_texture is not None and self.room_light is not None, "_sync uploads them first"
        assert self.material_texture is not None and self.library_textures is not None, "uploaded with geometry"
        units: tuple[tuple[str, moderngl.Texture | moderngl.Texture3D | moderngl.TextureArray], ...] = (
            ("u_materials", self.material_texture), ("u_library", self.library_textures),
            ("u_instances", self.instance_texture),
            ("u_sun_shadow", self.sun_depth), ("u_point_shadow", _either(self.atlas, self.sun_depth)),
            ("u_coverage", self.coverage), ("u_noise", self.noise), ("u_room_map", self.room_map),
            ("u_room_light", self.room_light), ("u_probes", _either(self.probes, self.hdr)),
            ("u_probe_boxes", _either(self.probe_boxes, self.room_light)))
        for unit, (name, texture) in enumerate(units):
            texture.use(unit)
            self._set(name, unit, also=(self.sky_program,))
        self._set("u_room_box", self._room_box)

    def _probe_boxes(self) -> np.ndarray:
        """(3, rooms, 4): each room's box (floor outline's bounds, floor to ceiling) and probe centre."""
        house = self.world.house
        boxes = np.zeros((3, len(house.rooms), 4), np.float32)
        for row, room in enumerate(house.rooms):
            points = np.asarray([p for poly in (room.floor, *room.extra_floors) for p in poly])
            x, y = polygon_centroid(room.floor)
            boxes[:, row, :3] = ((*points.min(axis=0), room.floor_z), (*points.max(axis=0), room.ceiling_z),
                                 (x, y, room.floor_z + PROBE_HEIGHT))
        return boxes

    def _draw_probe_face(self, view: np.ndarray, view_proj: np.ndarray, eye: np.ndarray, room: str) -> None:
        """A probe face: every surface in one draw with the plain-pattern program (a reflection
        needs the room's light and colours, not its wood grain), then the outdoors."""
        ctx = self.ctx
        self._set("u_view_proj", mat(view_proj))
        self._set("u_view", mat(view))
        self._set("u_eye", tuple(float(v) for v in eye))
        ctx.enable(ctx.DEPTH_TEST)
        ctx.depth_func = "<"
        self._room_vaos[room][1].render()
        ctx.depth_func = "<="
        uniform(self.sky_program, "u_inverse_view_proj").write(mat(np.linalg.inv(view_proj)))
        self.empty_vao.render(vertices=3)

    def _draw_view(self, view: np.ndarray, view_proj: np.ndarray, eye: np.ndarray) -> None:
        """Depth pre-pass, one shading pass per pattern, then the outdoors where nothing was drawn,
        into the framebuffer in use."""
        ctx = self.ctx
        self._set("u_view_proj", mat(view_proj))
        self._set("u_view", mat(view))
        self._set("u_eye", tuple(float(v) for v in eye))
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        # Depth first, then shade only the surviving fragment of each pixel (no overdraw); only the
        # bodies whose boxes meet the view are drawn (a CPU rasteriser pays for every triangle).
        visible = self._runs.visible(view_proj)
        ctx.depth_func = "<"
        uniform(self.depth_program, "u_view_proj").write(mat(view_proj))
        for first, count in self._runs.spans(visible):
            self.gl.draw(self.vaos["depth"], first, count)
        ctx.depth_func = "=="
        for k in self._patterns:
            for first, count in self._runs.spans(visible & (self._runs.pattern == k)):
                self.gl.draw(self.vaos[f"scene{k}"], first, count)
        ctx.depth_func = "<="
        uniform(self.sky_program, "u_inverse_view_proj").write(mat(np.linalg.inv(view_proj)))
        self.gl.draw(self.empty_vao)

    def render(self, position: np.ndarray, rotation: np.ndarray, exposure: float | None = None,
               radiance: bool = False, development: Development | None = None) -> RenderedViews:
        """RGB, depth and instance images from an optical frame (rotation columns: x right, y down,
        z forward) in the house frame; ``exposure`` fixes the exposure (None: auto-exposure);
        ``radiance``: also the HDR target (linear light, before exposure) for a sensor model;
        ``development``: the colour image developed through that sensor here (then ``exposure`` is
        not used)."""
        self._sync()
        ctx = self.ctx
        view = view_matrix(position, rotation)
        view_proj = self.projection @ view
        self._set_frame_lights(position)
        self._bind_textures()
        self.main_fbo.use()
        self.main_fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self._draw_view(view, view_proj, position)
        ctx.depth_func = "<"
        ctx.disable(ctx.DEPTH_TEST)
        return self.developer.develop(exposure, radiance, development)
