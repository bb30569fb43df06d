"""The camera's side of a GL frame: from the HDR target a scene pass drew to finished 8-bit images.

Block metering (it also counts pixels of non-finite radiance: such a frame is refused with RenderError
instead of returned black), then either the ideal camera's auto-exposure and tone map (ACES, sRGB) or
a camera sensor's development (shaders/sensor_*.frag: exposure, motion sweep, shot and read noise,
ADC, white balance, the same curve), and the read-back of colour, depth and instance ids, so only
finished images leave the device.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ravh_sim.render.gl_programs import fullscreen_program, uniform
from ravh_sim.render.views import Development, Exposure, RenderedViews, typical_depth

if TYPE_CHECKING:
    import moderngl

    from ravh_sim.render.backend import UnlockedGL

EXPOSURE_KEY = 0.27                   # mid-grey target of auto-exposure
EXPOSURE_REFERENCE = 0.5              # log-average luminance of a daylit room
EXPOSURE_ADAPTATION = 0.35            # how much of a dimming exposure undoes (1 = all): dusk stays dim
EXPOSURE_BRIGHT_ADAPTATION = 0.7      # how much of a brightening beyond a daylit room it undoes
EXPOSURE_RANGE = (0.08, 5.0)          # a camera's exposure limits: night stays dark
CENTRE_WEIGHT = 3.0                   # metering weight of the frame's middle against its edges
CENTRE_SPREAD = 0.25                  # sigma of the centre weight, in frame widths and heights
METER_HIGHLIGHT = math.log(4.0)       # metering counts a block at most 2 stops above the median
METER_BLOCK = 16                      # pixels per side averaged by one metering texel


class RenderError(RuntimeError):
    """The renderer produced radiance that is not a number: a shader fault. The frame is refused
    rather than stored, since no exposure makes such pixels right."""


class FrameDeveloper:
    """Develops the frames drawn into one set of targets (HDR colour, depth, instance ids)."""

    def __init__(self, ctx: moderngl.Context, gl: UnlockedGL, K: np.ndarray, far: float,
                 hdr: moderngl.Texture, depth: moderngl.Texture, instance: moderngl.Texture) -> None:
        self.gl, self.K, self.far = gl, K, far
        self.hdr, self.depth, self.instance = hdr, depth, instance
        self.width, self.height = size = hdr.size
        self.tonemap_program = fullscreen_program(ctx, "tonemap.frag")
        self.meter_program = fullscreen_program(ctx, "meter.frag")
        self.sensor_programs = {name: fullscreen_program(ctx, f"sensor_{name}.frag")
                                for name in ("expose", "balance", "develop")}
        self.tonemap_vao = ctx.vertex_array(self.tonemap_program, [])
        self.meter_vao = ctx.vertex_array(self.meter_program, [])
        self.sensor_vaos = {name: ctx.vertex_array(program, []) for name, program in self.sensor_programs.items()}
        self.ldr = ctx.texture(size, 4)
        self.ldr_fbo = ctx.framebuffer([self.ldr])
        meter_size = (-(-self.width // METER_BLOCK), -(-self.height // METER_BLOCK))
        self.meter = ctx.texture(meter_size, 4, dtype="f4")
        self.meter_fbo = ctx.framebuffer([self.meter])
        self.signal = ctx.texture(size, 4, dtype="f4")         # a sensor's signal, full-scale units
        self.signal_fbo = ctx.framebuffer([self.signal])
        self.balance = ctx.texture(meter_size, 4, dtype="f4")   # its block means, for white balance
        self.balance_fbo = ctx.framebuffer([self.balance])
        rows, cols = np.meshgrid((np.arange(meter_size[1]) + 0.5) / meter_size[1] - 0.5,
                                 (np.arange(meter_size[0]) + 0.5) / meter_size[0] - 0.5, indexing="ij")
        self._meter_weights = 1.0 + (CENTRE_WEIGHT - 1.0) * np.exp(-(rows ** 2 + cols ** 2) / (2 * CENTRE_SPREAD ** 2))

    def release(self) -> None:
        owned: list[moderngl.Program | moderngl.VertexArray | moderngl.Texture | moderngl.Framebuffer] = [
            self.tonemap_program, self.meter_program, *self.sensor_programs.values(), self.tonemap_vao,
            self.meter_vao, *self.sensor_vaos.values(), self.ldr, self.ldr_fbo, self.meter, self.meter_fbo,
            self.signal, self.signal_fbo, self.balance, self.balance_fbo]
        for obj in owned:
            obj.release()

    def auto_exposure(self, blocks: np.ndarray) -> float:
        """The ideal camera's auto-exposure, a centre-weighted metering: the log luminance of the frame,
        the middle weighted CENTRE_WEIGHT times the edges, is brought part of the way to mid-grey
        (a camera keeps a dusk room dimmer than a noon one), within the camera's range (so a dark
        room stays dark instead of turning grey). Highlights count at most METER_HIGHLIGHT above
        the median, so a bright window clips to white while the room is exposed for, as in a photo.
        ``blocks``: the meter pass's (:meth:`meter_blocks`)."""
        weights = blocks[..., 1] * self._meter_weights + 1e-9
        log_luminance = np.minimum(blocks[..., 0], np.median(blocks[..., 0]) + METER_HIGHLIGHT)
        average = math.exp(float(np.average(log_luminance, weights=weights)))
        adaptation = EXPOSURE_ADAPTATION if average < EXPOSURE_REFERENCE else EXPOSURE_BRIGHT_ADAPTATION
        adapted = EXPOSURE_REFERENCE * (average / EXPOSURE_REFERENCE) ** adaptation
        return float(np.clip(EXPOSURE_KEY / adapted, *EXPOSURE_RANGE))

    def meter_blocks(self) -> np.ndarray:
        """The meter pass's blocks: (rows, cols, 4) of mean log luminance, its samples, mean linear
        luminance, its pixels."""
        return np.frombuffer(self.meter.read(), np.float32).reshape(self._meter_weights.shape + (4,))

    def develop(self, exposure: float | None, radiance: bool = False,
                development: Development | None = None) -> RenderedViews:
        """The frame in the targets: metering, then the tone map at ``exposure`` (None: auto-exposure)
        or the sensor's development, and read-back (the HDR target too, for ``radiance``); raises
        RenderError where radiance is not finite (never a silently black frame)."""
        self.hdr.use(0)
        self.meter_fbo.use()
        uniform(self.meter_program, "u_hdr").value = 0
        uniform(self.meter_program, "u_block").value = METER_BLOCK
        self.gl.draw(self.meter_vao)
        self.gl.finish()                     # waits for the frame without the GIL: read-backs then do not
        h, w = self.height, self.width
        instance = np.frombuffer(self.instance.read(), np.int32).reshape(h, w)[::-1]
        blocks = self.meter_blocks()
        if int(blocks[..., 3].sum()) < h * w:                       # pixels of finite radiance
            self._refuse_non_finite(instance)
        depth = np.frombuffer(self.depth.read(), np.float32).reshape(h, w)[::-1].copy()
        chosen = None
        if development is None:
            self.ldr_fbo.use()
            uniform(self.tonemap_program, "u_hdr").value = 0
            chosen_exposure = self.auto_exposure(blocks) if exposure is None else exposure
            uniform(self.tonemap_program, "u_exposure").value = chosen_exposure
            self.gl.draw(self.tonemap_vao)
        else:
            chosen = self._develop_through(development, blocks, depth)
        self.gl.finish()
        rgb = np.frombuffer(self.ldr_fbo.read(components=3, alignment=1), np.uint8).reshape(h, w, 3)[::-1]
        background = instance == 0
        depth[background | (depth > self.far)] = np.nan
        linear = None
        if radiance:
            linear = self.radiance()[..., :3].astype(np.float32)
        return RenderedViews(np.ascontiguousarray(rgb), depth, instance.astype(np.uint16), background, linear,
                             chosen)

    def radiance(self) -> np.ndarray:
        """The HDR target, rows top first: (H, W, 4) float16, rgb linear light, a its log luminance."""
        return np.frombuffer(self.hdr.read(), np.float16).reshape(self.height, self.width, 4)[::-1]

    def _refuse_non_finite(self, instance: np.ndarray) -> None:
        """Raise RenderError naming the pixels of non-finite radiance the meter left out."""
        faulty = ~np.isfinite(self.radiance()[..., :3].astype(np.float32)).all(axis=2)
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
            uniform(expose, name).value = value
        self.signal_fbo.use()
        self.gl.draw(self.sensor_vaos["expose"])
        self.signal.use(0)
        uniform(self.sensor_programs["balance"], "u_signal").value = 0
        uniform(self.sensor_programs["balance"], "u_block").value = METER_BLOCK
        self.balance_fbo.use()
        self.gl.draw(self.sensor_vaos["balance"])
        self.gl.finish()
        means = np.frombuffer(self.balance.read(), np.float32).reshape(-1, 4)
        channel_means = (means[:, :3] * means[:, 3:]).sum(axis=0) / max(float(means[:, 3].sum()), 1.0)
        balance = sensor.balance_gains(channel_means)
        develop = self.sensor_programs["develop"]
        uniform(develop, "u_signal").value = 0
        uniform(develop, "u_balance").value = balance
        uniform(develop, "u_output_gain").value = sensor.output_gain
        self.ldr_fbo.use()
        self.gl.draw(self.sensor_vaos["develop"])
        return Exposure(time, gain, float(channel_means.mean()), balance)
