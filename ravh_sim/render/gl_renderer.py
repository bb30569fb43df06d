"""ravh_sim's physically based OpenGL renderer (moderngl on the process's EGL context).

One forward pass shades each pixel once (the cost on a CPU rasteriser is fragments, see
shared/notes/rendering-probe.md) and writes three aligned targets from the same triangles: HDR
colour, z-depth in metres and the instance id, so depth, masks and RGB can never disagree. The
expensive light transport is computed when the scene changes, not per frame: the sun's shadow map
(orthographic over the house; the ceiling and walls shadow the rooms, so sunlight enters only
through the window openings), one cube shadow map per switched-on lamp (walls confine its light;
open doors let it through) and a top-down coverage map that gives floors their ambient occlusion.
Per frame: the pass, the procedural sky behind the windows, block metering for auto-exposure (it
also counts pixels of non-finite radiance: such a frame is refused with RenderError instead of
returned black), then either a tone map (ACES, sRGB) at the renderer's own exposure or a camera
sensor's development (shaders/sensor_*.frag: exposure, motion sweep, shot and read noise, ADC, white
balance, the same curve), so only finished 8-bit images leave the device. ``fast`` quality draws
every surface with the plain material in one pass, skips shadow look-ups and reflections, and
confines lamps to their room instead.

Light units are arbitrary but consistent (exposure adapts): the sun gives SUN_IRRADIANCE on a
surface facing it at noon, a lamp of intensity 1 gives LAMP_POWER / d^2, a window is an area light
of WINDOW_RADIANCE lighting its own room, and the outdoors seen through it is far brighter than the
room's walls (OUTDOOR_DAY), so it clips to white as in a photo taken indoors.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from importlib import resources
from typing import TYPE_CHECKING

import cv2
import numpy as np

from ravh_sim.look.geometry import ATTRIBUTES, VERTEX_FORMAT, SceneBuilder
from ravh_sim.look.materials import NOISE_TEXELS, PATTERN, TEXELS, MaterialTable, noise_volume, srgb8_to_linear
from ravh_sim.render.backend import gl_context, unlocked_gl
from ravh_sim.render.projection import look_at, orthographic, perspective, projection_from_K, view_matrix
from ravh_sim.render.views import Development, Exposure, RenderedViews, typical_depth
from ravh_sim.world.appearance import SunLight, lamps_at, sun_light
from ravh_sim.world.geometry import polygon_centroid
from ravh_sim.world.house import Light
from ravh_sim.world.scene import World
from ravh_sim.world.topology import room_index_raster, room_links

if TYPE_CHECKING:
    import moderngl

KINDS = {"floor": 0, "ceiling": 1, "walls": 2, "object": 3, "door": 4, "window": 5}
MAX_LIGHTS = 32                       # switched-on lights with a shadow map
FRAME_LIGHTS = 4                      # lights shading one frame (the nearest; at most 8: u_room_lights)
assert FRAME_LIGHTS <= 8, "u_room_lights packs light indices in 3 bits"
MAX_ROOMS = 32                        # rooms of a house (the 30 houses have at most 14)
MAX_WINDOWS = 32                      # windows of a house (the 30 houses have at most 14)
WINDOW_SPAN = 64                      # a room's windows: first + WINDOW_SPAN * count (scene.frag)
FRAME_LIGHT_REACH = 9.0               # m: lights farther from the camera are left out of a frame
SUN_SHADOW_TEXELS = 2048
LAMP_TILE = 192                       # texels per cube face of a lamp's shadow map
LAMP_SHADOW_RANGE = 64.0              # m: a lamp's shadow map stores distance / this as its depth
PROBE_TILE = 64                       # texels per cube face of a room's reflection probe
PROBE_HEIGHT = 1.3                    # m above the floor where a room's probe sits
PROBE_FAR = 30.0
FACE_AXES = (((1, 0, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1)), ((0, 1, 0), (0, 0, 1)),
             ((0, -1, 0), (0, 0, 1)), ((0, 0, 1), (0, 1, 0)), ((0, 0, -1), (0, 1, 0)))
SHADOW_FORMAT = "3f 3x4 3x4 1f 1x4 2x4"  # position and material of each vertex (geometry.VERTEX_FORMAT)
COVERAGE_TEXELS = 512
ROOM_MAP_RESOLUTION = 0.05            # m per cell of the floor-plan room map
COVERAGE_BLUR_M = 0.12                # sigma of the floor occlusion blur

SUN_IRRADIANCE = 9.0                  # noon sun on a surface facing it
SKY_AMBIENT = 0.18                    # bounced sky light filling a room with generous windows, by day
WINDOW_RADIANCE = 5.0                 # mean radiance of the outdoors seen through a window, by day
OUTDOOR_DAY = 8.0                     # the outdoors by day against a room's bounce light
MIN_OPENNESS = 0.25                   # rooms without windows still get light through their doors
WINDOW_REACH = 6.0                    # window area x this / floor area = fully open room
LAMP_POWER = 1.0                      # irradiance of an intensity-1 lamp at 1 m
AMBIENT_TINT = 0.35                   # share of the daylight colour that survives bouncing indoors
LAMP_BOUNCE = 0.35                    # share of a lamp's power that comes back as room ambient (/m^2)
FIXTURE_GLOW = 6.0                    # radiance of a switched-on lamp shade or bulb
MOONLIGHT = 0.12                      # the moon and night sky, as a share of sun_light's night gain
NIGHT_FLOOR = 0.002                  # ambient that never goes away (moon, street lights)
EXPOSURE_KEY = 0.27                   # mid-grey target of auto-exposure
EXPOSURE_REFERENCE = 0.5              # log-average luminance of a daylit room
EXPOSURE_ADAPTATION = 0.35            # how much of a dimming exposure undoes (1 = all): dusk stays dim
EXPOSURE_BRIGHT_ADAPTATION = 0.7      # how much of a brightening beyond a daylit room it undoes
EXPOSURE_RANGE = (0.08, 5.0)          # a camera's exposure limits: night stays dark
CENTRE_WEIGHT = 3.0                   # metering weight of the frame's middle against its edges
CENTRE_SPREAD = 0.25                  # sigma of the centre weight, in frame widths and heights
METER_HIGHLIGHT = math.log(4.0)       # metering counts a block at most 2 stops above the median
METER_BLOCK = 16                      # pixels per side averaged by one metering texel
# Fields of the world state (ravh_msgs_py.appearance.Looks) that _sync redraws for: geometry redoes
# everything, lighting the light state and the light maps.
GEOMETRY_FIELDS = frozenset({"doors", "models", "paint"})
LIGHTING_FIELDS = frozenset({"sun_angle", "lights", "light_temperature"})


class RenderError(RuntimeError):
    """The renderer produced radiance that is not a number: a shader fault. The frame is refused
    rather than stored, since no exposure makes such pixels right."""


def _source(name: str) -> str:
    return (resources.files("ravh_sim.render") / "shaders" / name).read_text()


def _header(pattern: int = -1) -> str:
    defines = [f"#define PATTERN_{name.upper()} {i}" for name, i in PATTERN.items()]
    defines.append(f"#define PATTERN_ID {pattern}")
    defines += [f"#define KIND_{name.upper()} {i}" for name, i in KINDS.items()]
    defines.append(f"#define MAX_LIGHTS {MAX_LIGHTS}")
    defines.append(f"#define MAX_ROOMS {MAX_ROOMS}")
    defines.append(f"#define MAX_WINDOWS {MAX_WINDOWS}")
    defines.append(f"#define WINDOW_SPAN {WINDOW_SPAN}")
    defines.append(f"#define LAMP_SHADOW_RANGE {LAMP_SHADOW_RANGE:.1f}")
    return "#version 430\n" + "\n".join(defines) + "\n" + _source("common.glsl") + "\n"


def _either(texture: moderngl.Texture | None, stand_in: moderngl.Texture) -> moderngl.Texture:
    """A texture, or a stand-in bound in its place where a quality has none (never sampled then)."""
    return texture if texture is not None else stand_in


def _uniform(program: moderngl.Program, name: str) -> moderngl.Uniform:
    """``program``'s uniform ``name`` (indexing a program finds its attributes and blocks too)."""
    import moderngl  # already loaded with the context (this module's import does not load it)
    member = program[name]
    if not isinstance(member, moderngl.Uniform):
        raise TypeError(f"{name} is not a uniform of the program")
    return member


@dataclass(frozen=True)
class _Runs:
    """The vertex buffer as runs of one body's triangles of one pattern (the buffer is sorted by
    pattern, then body), each with its box in the house frame: what frustum culling draws or skips."""
    pattern: np.ndarray               # (R,) pattern drawn with
    first: np.ndarray                 # (R,) first vertex
    count: np.ndarray                 # (R,) vertices
    corners: np.ndarray               # (R, 8, 4) homogeneous corners of each run's box

    @staticmethod
    def of(vertices: np.ndarray, triangle_pattern: np.ndarray, drawn_as: int | None) -> _Runs:
        """Runs of a pattern-sorted buffer; ``drawn_as`` replaces every pattern (fast quality)."""
        instance = vertices[::3, 10].astype(np.int64)
        key = triangle_pattern.astype(np.int64) * (int(instance.max()) + 1) + instance
        starts = np.concatenate([[0], np.flatnonzero(np.diff(key)) + 1])
        ends = np.concatenate([starts[1:], [len(key)]])
        positions = vertices[:, :3].astype(np.float64)
        lo = np.minimum.reduceat(positions, 3 * starts)
        hi = np.maximum.reduceat(positions, 3 * starts)
        pick = np.array([[(i >> axis) & 1 for axis in range(3)] for i in range(8)], bool)
        corners = np.where(pick[None], hi[:, None, :], lo[:, None, :])
        corners = np.concatenate([corners, np.ones((*corners.shape[:2], 1))], axis=2)
        pattern = triangle_pattern[starts] if drawn_as is None else np.full(len(starts), drawn_as)
        return _Runs(pattern, 3 * starts, 3 * (ends - starts), corners)

    def visible(self, view_proj: np.ndarray) -> np.ndarray:
        """Runs whose box is not wholly outside one plane of the view frustum."""
        clip = self.corners @ view_proj.T                                     # (R, 8, 4)
        w = clip[..., 3]
        outside = [(clip[..., axis] > w).all(axis=1) | (clip[..., axis] < -w).all(axis=1) for axis in range(3)]
        return ~(outside[0] | outside[1] | outside[2])

    def spans(self, chosen: np.ndarray) -> list[tuple[int, int]]:
        """(first vertex, count) of the chosen runs, neighbours in the buffer merged into one draw."""
        index = np.flatnonzero(chosen)
        if not len(index):
            return []
        first, count = self.first[index], self.count[index]
        breaks = np.flatnonzero(first[1:] != first[:-1] + count[:-1]) + 1
        heads = np.concatenate([[0], breaks])
        tails = np.concatenate([breaks, [len(index)]]) - 1
        return [(int(first[h]), int(first[t] + count[t] - first[h])) for h, t in zip(heads, tails)]


def _mat(m: np.ndarray) -> bytes:
    """A row-major numpy matrix as the column-major bytes GL wants."""
    return np.ascontiguousarray(m.T, dtype=np.float32).tobytes()


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
        self.shadows = quality == "realistic"
        self.projection = projection_from_K(K, width, height, near, far)
        self.materials = MaterialTable()
        self.builder = SceneBuilder(world, self.materials)
        header = _header()
        self._uniforms: dict[tuple[str, tuple[int, ...]], list[moderngl.Uniform]] = {}     # see _set
        self.scene_programs = {k: ctx.program(vertex_shader=header + _source("scene.vert"),
                                              fragment_shader=_header(k) + _source("scene.frag"))
                               for k in range(len(PATTERN))}
        self.depth_program = ctx.program(vertex_shader=header + _source("scene.vert"),
                                         fragment_shader=header + "void main() {}\n")
        self._patterns: list[int] = []                      # the patterns the scene has, a program each
        self._lights: list[Light] = []
        self.sky_program = ctx.program(vertex_shader=header + _source("fullscreen.vert"),
                                       fragment_shader=header + _source("sky.frag"))
        self.tonemap_program = ctx.program(vertex_shader=header + _source("fullscreen.vert"),
                                           fragment_shader=header + _source("tonemap.frag"))
        self.meter_program = ctx.program(vertex_shader=header + _source("fullscreen.vert"),
                                         fragment_shader=header + _source("meter.frag"))
        self.shadow_program = ctx.program(vertex_shader=header + _source("shadow.vert"),
                                          fragment_shader=header + _source("shadow.frag"))
        self.coverage_program = ctx.program(vertex_shader=header + _source("coverage.vert"),
                                            fragment_shader=header + _source("coverage.frag"))
        self.sensor_programs = {name: ctx.program(vertex_shader=header + _source("fullscreen.vert"),
                                                  fragment_shader=header + _source(f"sensor_{name}.frag"))
                                for name in ("expose", "balance", "develop")}
        self.empty_vao = ctx.vertex_array(self.sky_program, [])
        self.tonemap_vao = ctx.vertex_array(self.tonemap_program, [])
        self.meter_vao = ctx.vertex_array(self.meter_program, [])
        self.sensor_vaos = {name: ctx.vertex_array(program, []) for name, program in self.sensor_programs.items()}
        size = (width, height)
        self.hdr = ctx.texture(size, 4, dtype="f2")
        self.hdr.repeat_x = self.hdr.repeat_y = False      # a motion sweep repeats the edge pixels
        self.depth = ctx.texture(size, 1, dtype="f4")
        self.instance = ctx.texture(size, 1, dtype="i4")
        for texture in (self.depth, self.instance):
            texture.filter = (ctx.NEAREST, ctx.NEAREST)
        self.main_fbo = ctx.framebuffer([self.hdr, self.depth, self.instance], ctx.depth_renderbuffer(size))
        self.ldr = ctx.texture(size, 4)
        self.ldr_fbo = ctx.framebuffer([self.ldr])
        meter_size = (-(-width // METER_BLOCK), -(-height // METER_BLOCK))
        self.meter = ctx.texture(meter_size, 4, dtype="f4")
        self.meter_fbo = ctx.framebuffer([self.meter])
        self.signal = ctx.texture(size, 4, dtype="f4")         # a sensor's signal, full-scale units
        self.signal_fbo = ctx.framebuffer([self.signal])
        self.balance = ctx.texture(meter_size, 4, dtype="f4")   # its block means, for white balance
        self.balance_fbo = ctx.framebuffer([self.balance])
        rows, cols = np.meshgrid((np.arange(meter_size[1]) + 0.5) / meter_size[1] - 0.5,
                                 (np.arange(meter_size[0]) + 0.5) / meter_size[0] - 0.5, indexing="ij")
        self._meter_weights = 1.0 + (CENTRE_WEIGHT - 1.0) * np.exp(-(rows ** 2 + cols ** 2) / (2 * CENTRE_SPREAD ** 2))
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
        self._synced: dict[str, int] | None = None        # the state's field revisions at the last _sync
        self._lights_on: frozenset[str] | None = None
        self._shadowed: set[str] = set()                  # lights whose cube map is current
        self._light_row = {lt.id: row for row, lt in enumerate(world.house.lights)}
        self._room_links = room_links(world.house)    # looked up once: hashing a House to find them is slow
        self._bounds = (np.zeros(3), np.ones(3))
        self._sun_matrix = np.eye(4)
        self._windows = self._window_lights()

    def release(self) -> None:
        """Free the GPU objects (the context stays: it belongs to the process)."""
        for obj in (*self.scene_programs.values(), self.depth_program, self.sky_program, self.tonemap_program,
                    self.shadow_program, self.coverage_program, self.meter_program, self.meter, self.meter_fbo,
                    *self.sensor_programs.values(), *self.sensor_vaos.values(), self.signal, self.signal_fbo,
                    self.balance, self.balance_fbo,
                    self.hdr, self.depth, self.instance, self.main_fbo, self.ldr,
                    self.ldr_fbo, self.sun_depth, self.sun_fbo, self.coverage_raw, self.coverage_fbo,
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
        only what the fields the state says changed touch: geometry (doors, models, paint) redoes
        everything, the sun angle its shadow map and every probe, a switched light its own cube map
        and the probes of the rooms it reaches."""
        world = self.world
        changed = world.state.changed_since(self._synced)
        self._synced = world.state.revisions()
        if changed & GEOMETRY_FIELDS:
            self._upload_geometry()
            self._render_coverage()
            self._lights_on = None
            self._shadowed.clear()
            changed |= {"sun_angle"}
        if not changed & LIGHTING_FIELDS:
            return
        if "light_temperature" in changed:
            self._lights_on = None                # every light's colour moved: relight every room
        sun_changed = "sun_angle" in changed
        on = frozenset(k for k, v in world.state.lights.items() if v)
        switched = on ^ self._lights_on if self._lights_on is not None else None
        sun = sun_light(world.state.sun_angle)
        lights = lamps_at([lt for lt in world.house.lights if lt.id in on], world.state.settings().light_temperature)
        self._upload_instances(sun, lights)
        self._set_lighting(sun, lights)
        self._lights_on = on
        if not self.shadows:
            return
        if sun_changed:
            self._render_sun_shadow(sun)
        self._render_lamp_shadows([lt for lt in lights if lt.id not in self._shadowed])
        self._bind_textures()
        if sun_changed or switched is None:
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
        self._runs = _Runs.of(vertices, triangle_pattern[order], PATTERN["plain"] if not self.shadows else None)
        positions = vertices[:, :3]
        self._bounds = (positions.min(axis=0), positions.max(axis=0))
        if self.vbo is not None:
            self.vbo.release()
            for vao in self.vaos.values():
                vao.release()
            for subset in self._room_vaos.values():
                for obj in subset:
                    obj.release()
        self.vbo = self.ctx.buffer(vertices.tobytes())
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

    def _upload_instances(self, sun: SunLight, lights: list[Light]) -> None:
        """Per instance: its room, a fixture's glow and the kind, the room's floor and ceiling
        heights; per room: its sky and bounce light, and which windows are its own."""
        house, world = self.world.house, self.world
        rooms = {room.id: i for i, room in enumerate(house.rooms)}
        glow = {lt.id: np.asarray(lt.color) * FIXTURE_GLOW * max(lt.intensity, 0.3) for lt in lights}
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
            ambient[row] = (*self._room_ambient(room, sun, lights), first + WINDOW_SPAN * count)
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

    def _room_ambient(self, room, sun: SunLight, lights: list[Light]) -> np.ndarray:
        """Bounced sky light of the room (more where its windows are larger for its floor) plus the
        bounce of its own lamps: the fill that reaches every surface; the windows' direct light is
        window_light's in the shader."""
        house = self.world.house
        window_area = sum(w.width * w.height for w in house.windows if w.room == room.id)
        openness = max(MIN_OPENNESS, min(1.0, WINDOW_REACH * window_area / max(room.area, 1.0)))
        tint = self._indoor_daylight(sun)
        bounce = sum((np.asarray(lt.color) * lt.intensity for lt in lights if lt.room == room.id), np.zeros(3))
        return SKY_AMBIENT * openness * tint + LAMP_POWER * LAMP_BOUNCE * bounce / max(room.area, 4.0) \
            + NIGHT_FLOOR

    @staticmethod
    def _indoor_daylight(sun: SunLight) -> np.ndarray:
        """The daylight's (moonlight's) colour and level as it reaches a room: light that bounced
        off white ceilings and walls keeps only part of the daylight's colour (the direct sun keeps
        all of it: a sunset paints patches, not the whole room)."""
        gain = np.asarray(sun.gain) * (1.0 if sun.angle <= 180.0 else MOONLIGHT)
        return float(gain.mean()) * (1.0 - AMBIENT_TINT) + gain * AMBIENT_TINT

    def _set_lighting(self, sun: SunLight, lights: list[Light]) -> None:
        direction = np.asarray(sun.direction)
        elevation = math.degrees(math.asin(max(-1.0, min(1.0, direction[2]))))
        sun_up = min(1.0, max(0.0, elevation / 2.0 + 0.5)) if sun.angle <= 180.0 else MOONLIGHT
        irradiance = SUN_IRRADIANCE * np.asarray(sun.gain) * sun_up
        outside = OUTDOOR_DAY if sun.angle <= 180.0 else 3 * MOONLIGHT
        sky = np.asarray(srgb8_to_linear(sun.sky)) * outside
        level = float(np.mean(sun.gain)) * outside
        uniforms = {
            "u_sun_dir": tuple(direction), "u_sun_irradiance": tuple(irradiance),
            "u_sun_radiance": tuple(irradiance * 4.0),
            "u_sky_zenith": tuple(sky * 1.6), "u_sky_horizon": tuple(sky * 0.8 + 0.6 * np.asarray(sun.gain) * outside),
            "u_ground": tuple(np.array([0.09, 0.16, 0.05]) * level * 1.6),
            "u_facade": tuple(np.array([0.55, 0.5, 0.45]) * np.asarray(sun.gain) * 1.3 * outside),
        }
        for name, value in uniforms.items():
            self._set(name, value, also=(self.sky_program,))
        self._set("u_window_radiance", tuple(WINDOW_RADIANCE * self._indoor_daylight(sun)))
        self._set("u_window_centre", self._windows[0].tobytes())
        self._set("u_window_normal", self._windows[1].tobytes())
        self._set("u_shadows", int(self.shadows))
        self._lights = lights

    def _set(self, name: str, value, also: tuple = ()) -> None:
        """Set a uniform on every scene program (and ``also``) that uses it; bytes are written raw. Which
        programs use it is looked up once: ``name in program`` walks all of a program's members, and a
        frame sets a few dozen uniforms on each of the programs."""
        key = (name, tuple(id(program) for program in also))
        uniforms = self._uniforms.get(key)
        if uniforms is None:
            uniforms = self._uniforms[key] = [_uniform(program, name) for program in
                                              (*self.scene_programs.values(), *also) if name in program]
        for uniform in uniforms:
            if isinstance(value, bytes):
                uniform.write(value)
            else:
                uniform.value = value

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

    def _window_lights(self) -> tuple[np.ndarray, np.ndarray, dict[str, tuple[int, int]]]:
        """Every window as an area light, grouped by room: (centre, 0), (normal into its room, area)
        and each room's (first, count) in them, so a pixel visits only its own room's windows."""
        house = self.world.house
        windows = sorted(house.windows, key=lambda w: [r.id for r in house.rooms].index(w.room))
        if len(windows) > MAX_WINDOWS:
            raise ValueError(f"house {house.number} has {len(windows)} windows; the renderer takes {MAX_WINDOWS}")
        centres = np.zeros((MAX_WINDOWS, 4), np.float32)
        normals = np.zeros((MAX_WINDOWS, 4), np.float32)
        spans: dict[str, tuple[int, int]] = {}
        for i, w in enumerate(windows):
            room = house.room(w.room)
            at, normal = np.asarray(w.position[:2]), np.array([-math.sin(w.yaw), math.cos(w.yaw)])
            if room.contains(*(at + 0.3 * normal)) == room.contains(*(at - 0.3 * normal)):   # the outline misses it
                normal *= np.sign(normal @ (np.asarray(polygon_centroid(room.floor)) - at)) or 1.0
            elif not room.contains(*(at + 0.3 * normal)):
                normal = -normal
            centres[i, :3] = w.position
            normals[i] = (*normal, 0.0, w.width * w.height)
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
    def _render_sun_shadow(self, sun: SunLight) -> None:
        lo, hi = self._bounds
        centre = (lo + hi) / 2
        radius = float(np.linalg.norm(hi - lo)) / 2 + 0.5
        direction = np.asarray(sun.direction)
        up = np.array([0.0, 0.0, 1.0]) if abs(direction[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
        view = look_at(-direction, up)
        view[:3, 3] = -view[:3, :3] @ (centre + direction * radius * 2)
        projection = orthographic(-radius, radius, -radius, radius, 0.1, radius * 4)
        matrix = projection @ view
        bias = np.array([[0.5, 0, 0, 0.5], [0, 0.5, 0, 0.5], [0, 0, 0.5, 0.5], [0, 0, 0, 1]])
        self._sun_matrix = bias @ matrix
        self._set("u_sun_matrix", _mat(self._sun_matrix))
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
        _uniform(self.shadow_program, "u_materials").value = 0
        _uniform(self.shadow_program, "u_matrix").write(_mat(matrix))
        _uniform(self.shadow_program, "u_origin").value = tuple(float(v) for v in origin)
        _uniform(self.shadow_program, "u_radial").value = int(room is not None)
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
        self._upload_instances(sun_light(self.world.state.sun_angle), [])
        assert self.instance_texture is not None, "uploaded just above"
        self.instance_texture.use(0)
        _uniform(self.coverage_program, "u_instances").value = 0
        _uniform(self.coverage_program, "u_matrix").write(_mat(matrix))
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
        self._set("u_view_proj", _mat(view_proj))
        self._set("u_view", _mat(view))
        self._set("u_eye", tuple(float(v) for v in eye))
        ctx.enable(ctx.DEPTH_TEST)
        ctx.depth_func = "<"
        self._room_vaos[room][1].render()
        ctx.depth_func = "<="
        _uniform(self.sky_program, "u_inverse_view_proj").write(_mat(np.linalg.inv(view_proj)))
        self.empty_vao.render(vertices=3)

    def _draw_view(self, view: np.ndarray, view_proj: np.ndarray, eye: np.ndarray) -> None:
        """Depth pre-pass, one shading pass per pattern, then the outdoors where nothing was drawn,
        into the framebuffer in use."""
        ctx = self.ctx
        self._set("u_view_proj", _mat(view_proj))
        self._set("u_view", _mat(view))
        self._set("u_eye", tuple(float(v) for v in eye))
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        # Depth first, then shade only the surviving fragment of each pixel (no overdraw); only the
        # bodies whose boxes meet the view are drawn (a CPU rasteriser pays for every triangle).
        visible = self._runs.visible(view_proj)
        ctx.depth_func = "<"
        _uniform(self.depth_program, "u_view_proj").write(_mat(view_proj))
        for first, count in self._runs.spans(visible):
            self.gl.draw(self.vaos["depth"], first, count)
        ctx.depth_func = "=="
        for k in self._patterns:
            for first, count in self._runs.spans(visible & (self._runs.pattern == k)):
                self.gl.draw(self.vaos[f"scene{k}"], first, count)
        ctx.depth_func = "<="
        _uniform(self.sky_program, "u_inverse_view_proj").write(_mat(np.linalg.inv(view_proj)))
        self.gl.draw(self.empty_vao)

    def _exposure(self, blocks: np.ndarray) -> float:
        """Auto-exposure as a camera's centre-weighted metering: the log luminance of the frame,
        the middle weighted CENTRE_WEIGHT times the edges, is brought part of the way to mid-grey
        (a camera keeps a dusk room dimmer than a noon one), within the camera's range (so a dark
        room stays dark instead of turning grey). Highlights count at most METER_HIGHLIGHT above
        the median, so a bright window clips to white while the room is exposed for, as in a photo.
        ``blocks``: the meter pass's (:meth:`_meter_blocks`)."""
        weights = blocks[..., 1] * self._meter_weights + 1e-9
        log_luminance = np.minimum(blocks[..., 0], np.median(blocks[..., 0]) + METER_HIGHLIGHT)
        average = math.exp(float(np.average(log_luminance, weights=weights)))
        adaptation = EXPOSURE_ADAPTATION if average < EXPOSURE_REFERENCE else EXPOSURE_BRIGHT_ADAPTATION
        adapted = EXPOSURE_REFERENCE * (average / EXPOSURE_REFERENCE) ** adaptation
        return float(np.clip(EXPOSURE_KEY / adapted, *EXPOSURE_RANGE))

    def _meter_blocks(self) -> np.ndarray:
        """The meter pass's blocks: (rows, cols, 4) of mean log luminance, its samples, mean linear
        luminance, its pixels."""
        return np.frombuffer(self.meter.read(), np.float32).reshape(self._meter_weights.shape + (4,))

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
        return self._develop(exposure, radiance, development)

    def _develop(self, exposure: float | None, radiance: bool = False,
                 development: Development | None = None) -> RenderedViews:
        """The camera's side of a frame already drawn into the HDR target: metering, then the tone map
        at the renderer's exposure or the sensor's development, and read-back (the HDR target too,
        for ``radiance``); raises RenderError where radiance is not finite (never a silently black
        frame)."""
        self.hdr.use(0)
        self.meter_fbo.use()
        _uniform(self.meter_program, "u_hdr").value = 0
        _uniform(self.meter_program, "u_block").value = METER_BLOCK
        self.gl.draw(self.meter_vao)
        self.gl.finish()                     # waits for the frame without the GIL: read-backs then do not
        h, w = self.height, self.width
        instance = np.frombuffer(self.instance.read(), np.int32).reshape(h, w)[::-1]
        blocks = self._meter_blocks()
        if int(blocks[..., 3].sum()) < h * w:                       # pixels of finite radiance
            self._refuse_non_finite(instance)
        depth = np.frombuffer(self.depth.read(), np.float32).reshape(h, w)[::-1].copy()
        chosen = None
        if development is None:
            self.ldr_fbo.use()
            _uniform(self.tonemap_program, "u_hdr").value = 0
            chosen_exposure = self._exposure(blocks) if exposure is None else exposure
            _uniform(self.tonemap_program, "u_exposure").value = chosen_exposure
            self.gl.draw(self.tonemap_vao)
        else:
            chosen = self._develop_through(development, blocks, depth)
        self.gl.finish()
        rgb = np.frombuffer(self.ldr_fbo.read(components=3, alignment=1), np.uint8).reshape(h, w, 3)[::-1]
        background = instance == 0
        depth[background | (depth > self.far)] = np.nan
        linear = None
        if radiance:
            linear = self._radiance()[..., :3].astype(np.float32)
        return RenderedViews(np.ascontiguousarray(rgb), depth, instance.astype(np.uint16), background, linear,
                             chosen)

    def _radiance(self) -> np.ndarray:
        """The HDR target, rows top first: (H, W, 4) float16, rgb linear light, a its log luminance."""
        return np.frombuffer(self.hdr.read(), np.float16).reshape(self.height, self.width, 4)[::-1]

    def _refuse_non_finite(self, instance: np.ndarray) -> None:
        """Raise RenderError naming the pixels of non-finite radiance the meter left out."""
        faulty = ~np.isfinite(self._radiance()[..., :3].astype(np.float32)).all(axis=2)
        raise RenderError(f"{int(faulty.sum())} pixels of non-finite radiance (instances "
                          f"{sorted(set(instance[faulty].tolist()))[:8]}) in the frame: a shader fault")

    def _develop_through(self, development: Development, blocks: np.ndarray, depth: np.ndarray) -> Exposure:
        """The frame in the HDR target developed through a camera sensor into the LDR target, the
        sensor model deciding (exposure from the metered mean, the motion sweep over that exposure,
        white balance from the signal's means) and the sensor passes carrying it out per pixel;
        ``blocks``: the meter pass's (:meth:`_meter_blocks`)."""
        sensor = development.sensor
        metered = float((blocks[..., 2] * blocks[..., 3]).sum() / max(float(blocks[..., 3].sum()), 1.0))
        time, gain = sensor.exposure_for(metered)
        shift, zoom, samples = 0.0, 0.0, 1
        if any(development.velocity):
            shift, zoom, samples = sensor.sweep(self.K, development.velocity, time, typical_depth(depth, self.far))
        seed = development.rng.integers(0, 2 ** 32, size=2, dtype=np.uint64)
        expose = self.sensor_programs["expose"]
        values = {"u_hdr": 0, "u_electrons": sensor.sensitivity * time, "u_read_noise": sensor.read_noise,
                  "u_full_well": sensor.full_well, "u_gain": gain, "u_levels": sensor.levels,
                  "u_principal": (float(self.K[0, 2]), float(self.K[1, 2])), "u_shift": shift, "u_zoom": zoom,
                  "u_samples": max(samples, 1), "u_seed": (int(seed[0]), int(seed[1]))}
        for name, value in values.items():
            _uniform(expose, name).value = value
        self.signal_fbo.use()
        self.gl.draw(self.sensor_vaos["expose"])
        self.signal.use(0)
        _uniform(self.sensor_programs["balance"], "u_signal").value = 0
        _uniform(self.sensor_programs["balance"], "u_block").value = METER_BLOCK
        self.balance_fbo.use()
        self.gl.draw(self.sensor_vaos["balance"])
        self.gl.finish()
        means = np.frombuffer(self.balance.read(), np.float32).reshape(-1, 4)
        channel_means = (means[:, :3] * means[:, 3:]).sum(axis=0) / max(float(means[:, 3].sum()), 1.0)
        balance = sensor.balance_gains(channel_means)
        develop = self.sensor_programs["develop"]
        _uniform(develop, "u_signal").value = 0
        _uniform(develop, "u_balance").value = balance
        _uniform(develop, "u_output_gain").value = sensor.output_gain
        self.ldr_fbo.use()
        self.gl.draw(self.sensor_vaos["develop"])
        return Exposure(time, gain, float(channel_means.mean()), balance)
