"""The TinyRenderer fallback's lighting pass: daylight colour, switched-on lamps and the sky over
pybullet's one-light render (the GL renderer in ravh_sim.render lights its images itself).

pybullet draws one directional light with fixed shading (``albedo * (0.75 + 0.25 n.l)``), so daylight
colour and every other light are added here, per pixel, from what the render
gives: depth (3D points and normals through K), instance ids (which room a pixel belongs to) and
the rendered colour (albedo is the colour divided by pybullet's own shading). Each switched-on light
adds ``albedo * colour * intensity * max(0, n.l) * falloff(d, range)`` to the pixels of its own room
only, so light never leaks through walls. The room of a pixel is the room of the instance seen
there: exact on walls, which lie on room boundaries where a floor-plan lookup is ambiguous. Light is
computed on a half-resolution grid and upsampled (it varies smoothly), which keeps the pass at a few
milliseconds.
"""
from __future__ import annotations

import cv2
import numpy as np

from ravh_sim.look.lighting import SunLight
from ravh_sim.world.house import Light
from ravh_sim.world.scene import World

# pybullet's shading of the sun: ambient + diffuse * n.l (TinyRenderer clamps n.l at 0).
SUN_AMBIENT = 0.75
SUN_DIFFUSE = 0.25
LAMP_EXPOSURE = 2.2        # camera exposure for lamp light at night
LAMP_HALF_DISTANCE = 1.5   # m: a lamp's light halves at this distance (1 / (1 + (d / d0)^2))
DAY_ADAPTATION = 0.8       # exposure follows daylight: by day lamps add 1 - 0.8 of their night light
EMISSIVE = 1.6             # gain of a switched-on light's own fixture (lamp shades, ceiling lights)
NORMAL_BASELINE = 2        # light-map samples spanned by a surface tangent
NORMAL_BLUR = 5            # box filter (light-map samples) over normals
FAR_FILL = 1e3             # m: stands in for "no depth" so no NaN reaches the light sums
CREASE_COS = 0.7           # filtered normal over ~45 degrees off the raw one: keep the raw one
SILHOUETTE_JUMP = 0.1      # a tangent whose depth step exceeds 0.1 * z per sample bridges two surfaces
STEP = 2                   # light map: one sample per STEP x STEP pixels


class Lighting:
    """Per-camera lighting pass over one World; reusable for every frame."""

    def __init__(self, world: World, K: np.ndarray, width: int, height: int, step: int = STEP) -> None:
        self.width, self.height, self.step = width, height, step
        self.fx, self.fy, self.cx, self.cy = float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2])
        self._rx = ((np.arange(width) - self.cx) / self.fx).astype(np.float32)
        self._ry = ((np.arange(height) - self.cy) / self.fy).astype(np.float32)
        house = world.house
        self._room_index = {room.id: i for i, room in enumerate(house.rooms)}
        size = max(inst.id for inst in world.instances) + 1
        self._room_of = np.full(size, -1, np.int16)
        self._is_wall = np.zeros(size, bool)
        for inst in world.instances:
            self._room_of[inst.id] = self._room_index[inst.room]
            self._is_wall[inst.id] = inst.kind == "walls"
        self._fixture = {inst.name: inst.id for inst in world.instances if inst.name in house.light_by_id}

    # ------------------------------------------------------------------ shading
    def apply(self, rgb: np.ndarray, depth: np.ndarray, instance: np.ndarray, rotation: np.ndarray,
              position: np.ndarray, sun: SunLight, lights: list[Light]) -> np.ndarray:
        """Lit 8-bit RGB: ``rgb`` (pybullet's render) times daylight, plus every light in ``lights``.

        ``rotation``/``position``: the optical frame in the house frame (x right, y down, z forward).
        """
        gain = np.asarray(sun.gain, np.float32)
        s = self.step
        inst = instance[::s, ::s]
        room = np.take(self._room_of, inst)
        seen = np.bincount(room.ravel() + 1, minlength=len(self._room_index) + 1)[1:] > 0
        active = [lt for lt in lights if lt.intensity > 0 and seen[self._room_index[lt.room]]]
        if not active:
            return _scale(rgb, gain)
        z = depth[::s, ::s]
        px, py = self._rx[None, ::s] * z, self._ry[::s, None] * z       # camera-frame points
        nx, ny, nz = _normals(px, py, z)
        sx, sy, sz = (rotation.T @ np.asarray(sun.direction)).astype(np.float32)
        cos_sun = nx * sx + ny * sy + nz * sz
        cos_sun = np.maximum(cos_sun, 0.0)
        exposure = LAMP_EXPOSURE * (1.0 - DAY_ADAPTATION * float(gain.mean()))
        # Lamp light per unit albedo: pybullet's render is albedo * shade, so divide by the shade.
        per_albedo = exposure / (SUN_AMBIENT + SUN_DIFFUSE * cos_sun)
        px, py, z = (np.nan_to_num(a, nan=FAR_FILL) for a in (px, py, z))   # no depth: outside rooms
        channels = [np.full(room.shape, g, np.float32) for g in gain]
        for room_i in sorted({self._room_index[lt.room] for lt in active}):
            here = [lt for lt in active if self._room_index[lt.room] == room_i]
            by_colour: dict[tuple[float, float, float], np.ndarray] = {}
            for lt in here:
                lx, ly, lz = (rotation.T @ (np.asarray(lt.position) - position)).astype(np.float32)
                amount = _lamp(px, py, z, nx, ny, nz, lx, ly, lz, lt.range) * np.float32(lt.intensity)
                if lt.color in by_colour:
                    by_colour[lt.color] += amount
                else:
                    by_colour[lt.color] = amount
            mask = (room == room_i) * per_albedo
            for colour, amount in by_colour.items():
                amount *= mask
                for channel, c in zip(channels, colour):
                    cv2.scaleAdd(amount, float(c), channel, dst=channel)
            for lt in here:
                fixture = self._fixture.get(lt.id)
                if fixture is not None:
                    glow = inst == fixture
                    for channel, c in zip(channels, lt.color):
                        channel[glow] += EMISSIVE * c
        # Upsampling blends neighbouring samples: samples outside lit rooms take their lit
        # neighbours' light (no dark seam along a lit room's silhouette), and only pixels of lit
        # rooms keep the result (no light bleeds onto the rooms around).
        lit_rooms = np.zeros(len(self._room_index) + 1, np.uint8)
        lit_rooms[[self._room_index[lt.room] for lt in active]] = 1
        gain_map = cv2.merge(channels)
        filled = cv2.dilate(gain_map, np.ones((3, 3), np.uint8))
        cv2.copyTo(gain_map, np.take(lit_rooms, room), filled)
        lit = cv2.multiply(rgb, cv2.resize(filled, (self.width, self.height), interpolation=cv2.INTER_LINEAR),
                           dtype=cv2.CV_8U)
        out = _scale(rgb, gain)
        cv2.copyTo(lit, np.take(lit_rooms[self._room_of], instance), out)   # room -1 -> last entry, 0
        return out


def _lamp(px, py, pz, nx, ny, nz, lx: float, ly: float, lz: float, reach: float) -> np.ndarray:
    """max(0, n.l) * falloff(d) of a point light at (lx, ly, lz) for every sample (camera frame).

    The falloff is a soft inverse square, 1 / (1 + (d / LAMP_HALF_DISTANCE)^2), windowed by
    (1 - (d / range)^4)^2 so it reaches exactly zero at the light's range.
    """
    dx, dy, dz = lx - px, ly - py, lz - pz
    d2 = dx * dx
    d2 += dy * dy
    d2 += dz * dz
    out = nx * dx
    out += ny * dy
    out += nz * dz
    np.maximum(out, 0.0, out=out)
    out /= np.sqrt(d2)
    window = d2 * np.float32(1.0 / (reach * reach))
    window *= window
    np.subtract(1.0, window, out=window)
    np.maximum(window, 0.0, out=window)
    out *= window
    out *= window
    d2 *= np.float32(1.0 / (LAMP_HALF_DISTANCE * LAMP_HALF_DISTANCE))
    d2 += 1.0
    out /= d2
    return out


def _normals(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit normals (three (h, w) components) facing the camera, from camera-frame point grids.

    The depth buffer is 16-bit, so neighbouring points are a few millimetres off their surface:
    tangents span NORMAL_BASELINE samples, tangents that bridge a depth jump (silhouettes) are
    dropped, and the normals are box-filtered, which also fills the dropped ones from their
    neighbours. Where the filtered normal turns away from the raw one, a crease (two faces of one
    object) is near and the raw normal is kept, so edges do not glow. Rows run down and columns
    right, so (down x right) faces the camera.
    """
    k = NORMAL_BASELINE
    ux, uy, uz = (a[:-k, k:] - a[:-k, :-k] for a in (x, y, z))
    vx, vy, vz = (a[k:, :-k] - a[:-k, :-k] for a in (x, y, z))
    n = (vy * uz - vz * uy, vz * ux - vx * uz, vx * uy - vy * ux)
    limit = SILHOUETTE_JUMP * k * z[:-k, :-k]
    with np.errstate(invalid="ignore"):
        keep = (np.abs(uz) < limit) & (np.abs(vz) < limit)            # also drops NaN (no depth)
        inverse = np.where(keep, 1.0 / np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 0.0)
    border = (k // 2, k - k // 2, k // 2, k - k // 2)                   # centre each normal on its span
    raw = [cv2.copyMakeBorder(np.nan_to_num(c * inverse), *border, cv2.BORDER_REPLICATE) for c in n]
    smooth = [cv2.blur(c, (NORMAL_BLUR, NORMAL_BLUR)) for c in raw]
    length = np.sqrt(smooth[0] * smooth[0] + smooth[1] * smooth[1] + smooth[2] * smooth[2])
    inverse = 1.0 / np.maximum(length, 1e-6)
    smooth = [c * inverse for c in smooth]
    edge = (smooth[0] * raw[0] + smooth[1] * raw[1] + smooth[2] * raw[2]) < CREASE_COS
    edge &= cv2.copyMakeBorder(keep.view(np.uint8), *border, cv2.BORDER_REPLICATE).view(bool)
    nx, ny, nz = (np.where(edge, r, c) for r, c in zip(raw, smooth))
    return nx, ny, nz


def _scale(rgb: np.ndarray, gain: np.ndarray) -> np.ndarray:
    """Multiply each channel by a constant through a lookup table (the cheap no-lamp path), rounding
    as cv2.multiply does on the lamp path so both paths agree on unlit pixels."""
    table = np.rint(np.arange(256, dtype=np.float32)[:, None] * gain[None, :])
    table = np.clip(table, 0, 255).astype(np.uint8)
    return cv2.LUT(rgb, table.reshape(1, 256, 3))
