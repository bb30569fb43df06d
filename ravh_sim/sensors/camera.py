"""The smart camera: RGB, depth and instance images from one render, pinhole-exact.

A renderer (ravh_sim.render.renderers.make_renderer: our physically based GL renderer, or pybullet's
TinyRenderer where no GL context can be made) draws lit RGB, depth and instance ids from the same
triangles with a projection built from K, so a 3D point projected with K lands on the pixel where it is drawn (OpenCV
pixel convention: pixel i covers [i - 0.5, i + 0.5]). Depth is REP 118 z-depth along the optical
axis in metres (NaN where nothing is hit within ``far``); instance ids are the World's (0 = nothing).
The camera never talks GL or pybullet. Optional effects (motion blur, lens distortion, noise, JPEG)
follow in that order, seeded from the world seed, the agent and a capture counter so the same seed
and poses give identical images.
:class:`CameraSection` is the camera's section of a robot profile, :data:`PORT` the camera as a
sensor port (ravh_sim.sensors.ports).
"""
from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import cv2
import numpy as np
from pydantic import Field, model_validator

from ravh_msgs_py import names
from ravh_sim.files import atomic_write, encode_png, read_png, write_image
from ravh_sim.poses import quaternion_from_matrix
from ravh_sim.render.backend import QUALITIES, resolve_backend
from ravh_sim.render.renderers import make_renderer
from ravh_sim.render.views import Development, Exposure, Renderer, typical_depth
from ravh_sim.schema import FINITE, Length, Range, Rate, Strict
from ravh_sim.sensors import imaging
from ravh_sim.sensors.mount import (
    CAMERA_OPTICAL_FRAME,
    LINK_TO_OPTICAL,
    floor_at,
    mount_position,
    mount_rotation,
)
from ravh_sim.sensors.ports import Carrier, Mount, SensorPort, Stored, Topic, noise_rng
from ravh_sim.sensors.readings import CameraInfo

if TYPE_CHECKING:
    from ravh_sim.world.scene import World

DISTORTION_MODEL = "plumb_bob"
CAMERA_JSON = "camera.json"   # the dataset's side file: agent -> camera intrinsics
NOISE_STREAM = 1            # noise generator stream of cameras (lasers use another)
MIN_NEAR = 0.001           # m, near plane: 1e-300 made the projection matrix singular
Pixels = Annotated[int, Field(ge=16, le=8192)]
Coefficient = Annotated[float, Field(ge=-10.0, le=10.0), FINITE]     # of lens distortion


@dataclass(frozen=True)
class CameraSpec:
    """What a camera is built with (from its profile section)."""
    height: float            # m above the floor
    pitch_deg: float         # down
    forward: float           # m ahead of the base centre
    width: int               # px
    height_px: int           # px
    sensor_width: float      # mm
    sensor_height: float     # mm
    focal_length: float      # mm
    near: float              # m
    far: float               # m
    rate: float              # Hz: frames published
    quality: str = "realistic"   # realistic | fast | dataset (ravh_sim.render.backend.QUALITIES)
    effects: tuple[tuple[str, Any], ...] = ()      # CameraOptions fields set by the profile
    sensor: imaging.SensorModel | None = None      # None: the ideal camera (no sensor model)

    @property
    def fx(self) -> float:
        """The paper's formula: fx = f * rx / sx."""
        return self.focal_length * self.width / self.sensor_width

    @property
    def fy(self) -> float:
        return self.focal_length * self.height_px / self.sensor_height

    @property
    def cx(self) -> float:
        return self.width / 2.0

    @property
    def cy(self) -> float:
        return self.height_px / 2.0


class CameraEffects(Strict):
    """The bounds of the realism effects the profile sets; their defaults live in CameraOptions
    (an effect left out or null takes that default)."""
    jpeg_quality: Annotated[int, Field(ge=1, le=100)] | None = None
    jpeg_roundtrip: bool | None = None
    pixel_noise: Annotated[float, Field(ge=0.0, le=255.0), FINITE] | None = None
    distortion: Annotated[tuple[Coefficient, Coefficient, Coefficient, Coefficient, Coefficient],
                          Field(strict=False)] | None = None
    motion_blur: bool | None = None
    exposure: Annotated[float, Field(gt=0.0, le=1.0), FINITE] | None = None
    depth_noise: Annotated[float, Field(ge=0.0, le=1.0), FINITE] | None = None
    manual_exposure: Annotated[float, Field(gt=0.0, le=100.0), FINITE] | None = None


class CameraSensor(Strict):
    """The camera sensor model (imaging.SensorModel); a field left out takes its default."""
    enabled: bool = True
    exposure_min: Annotated[float, Field(gt=0.0, le=1.0), FINITE] | None = None        # s
    exposure_max: Annotated[float, Field(gt=0.0, le=1.0), FINITE] | None = None        # s
    gain_max: Annotated[float, Field(ge=1.0, le=1000.0), FINITE] | None = None
    full_well: Annotated[float, Field(gt=0.0, le=1e7), FINITE] | None = None           # e-
    read_noise: Annotated[float, Field(ge=0.0, le=1000.0), FINITE] | None = None       # e- rms
    sensitivity: Annotated[float, Field(gt=0.0, le=1e12), FINITE] | None = None       # e- / s / radiance
    target: Annotated[float, Field(gt=0.0, le=1.0), FINITE] | None = None
    adc_bits: Annotated[int, Field(ge=1, le=16)] | None = None
    white_balance: bool | None = None
    white_balance_limit: Annotated[float, Field(ge=1.0, le=100.0), FINITE] | None = None
    reference_exposure: Annotated[float, Field(gt=0.0, le=100.0), FINITE] | None = None

    @model_validator(mode="after")
    def _ordered(self) -> CameraSensor:
        model = self.model()
        if model is not None and model.exposure_min > model.exposure_max:
            raise ValueError(f"exposure_min {model.exposure_min} must not exceed exposure_max {model.exposure_max}")
        return self

    def model(self) -> imaging.SensorModel | None:
        if not self.enabled:
            return None
        return imaging.SensorModel(**self.model_dump(exclude_none=True, exclude={"enabled"}))


class CameraSection(Strict):
    """The ``camera:`` section of a robot profile."""
    height: Length
    pitch: Annotated[float, Field(ge=-90.0, le=90.0), FINITE]
    forward: Annotated[float, Field(ge=-10.0, le=10.0), FINITE]
    width: Pixels
    height_px: Pixels
    sensor_width: Annotated[float, Field(gt=0.0, le=100.0), FINITE]     # mm
    sensor_height: Annotated[float, Field(gt=0.0, le=100.0), FINITE]
    focal_length: Annotated[float, Field(gt=0.0, le=1000.0), FINITE]
    near: Annotated[float, Field(ge=MIN_NEAR, le=1000.0), FINITE]      # m
    far: Range
    rate: Rate
    quality: Literal[QUALITIES] = "realistic"         # type: ignore[valid-type]
    effects: CameraEffects = CameraEffects()
    sensor: CameraSensor = CameraSensor(enabled=False)

    @model_validator(mode="after")
    def _ordered(self) -> CameraSection:
        if self.near >= self.far:
            raise ValueError(f"near {self.near} must be below far {self.far}")
        return self



@dataclass(frozen=True)
class CameraOptions:
    """Realism effects; all off by default (the ideal pinhole camera)."""
    jpeg_quality: int = 90                 # quality of encode_jpeg and of the round trip
    jpeg_roundtrip: bool = False           # rgb shows JPEG artefacts
    pixel_noise: float = 0.0               # Gaussian sigma, 8-bit levels
    distortion: tuple[float, float, float, float, float] | None = None   # plumb-bob k1 k2 p1 p2 k3
    motion_blur: bool = False              # the ideal camera's blur (a sensor model always blurs)
    exposure: float = 0.02                 # s, the ideal camera's exposure for that blur
    depth_noise: float = 0.0               # sigma = depth_noise * z^2 (1/m)
    manual_exposure: float | None = None   # GL renderer: a fixed exposure instead of auto-exposure


@dataclass
class Frame:
    """One render, before effects."""
    rgb: np.ndarray                        # (H, W, 3) uint8
    depth: np.ndarray                      # (H, W) float32 z-depth, NaN = nothing
    instance: np.ndarray                   # (H, W) uint16
    background: np.ndarray                 # (H, W) bool, no body (sky)
    position: np.ndarray                   # optical frame origin, house frame
    rotation: np.ndarray                   # optical axes as columns, house frame
    exposure: Exposure | None = None       # rgb was developed through the camera's sensor, which chose this


@dataclass
class Capture:
    rgb: np.ndarray                        # (H, W, 3) uint8
    depth: np.ndarray                      # (H, W) float32 metres, REP 118 z-depth, NaN = no return
    instance: np.ndarray                   # (H, W) uint16 instance ids, 0 = nothing
    K: np.ndarray                          # (3, 3)
    camera_info: CameraInfo
    robot_pose: tuple[float, float, float]
    position: np.ndarray                   # optical frame origin, house frame
    orientation: tuple[float, float, float, float]   # optical frame quaternion (x, y, z, w)
    index: int                             # capture counter (noise stream)


class SmartCamera:
    """A camera mounted on a robot, rendering one World."""

    def __init__(self, world: World, spec: CameraSpec, options: CameraOptions | None = None,
                 agent: str = names.DEFAULT_AGENT, sensor: imaging.SensorModel | None = None,
                 backend: str = "auto") -> None:
        """``backend``: the renderer, auto | gl | tiny (:func:`ravh_sim.render.backend.resolve_backend`)."""
        self.world, self.spec, self.agent = world, spec, agent
        self.backend = resolve_backend(backend)
        self.options = options or CameraOptions()
        self.sensor = sensor                        # None: the ideal camera (the renderer's exposure)
        self.width, self.height = spec.width, spec.height_px
        self.K = np.array([[spec.fx, 0.0, spec.cx], [0.0, spec.fy, spec.cy], [0.0, 0.0, 1.0]])
        self.camera_info = self._camera_info()
        self._lens = (imaging.LensDistortion(self.K, self.options.distortion, self.width, self.height)
                      if self.options.distortion is not None else None)
        self.renderer: Renderer | None = make_renderer(world, self.backend, self.K, self.width, self.height,
                                                       spec.near, spec.far, spec.quality)
        self._instance_rgb = np.zeros((max(i.id for i in world.instances) + 1, 3), np.uint8)
        for inst in world.instances:
            self._instance_rgb[inst.id] = inst.mask_color
        if len(self._instance_rgb) > np.iinfo(np.uint16).max:
            raise ValueError("too many instances for 16-bit instance images")
        self.count = 0

    def close(self) -> None:
        """Free the camera's GPU objects (a World's cameras are closed with it)."""
        if self.renderer is not None:
            self.renderer.release()
            self.renderer = None

    # ------------------------------------------------------------------ geometry
    def optical_pose(self, x: float, y: float, yaw: float, floor_z: float | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
        """(position, rotation 3x3 with the optical axes as columns) in the house frame."""
        fz = floor_at(self.world, x, y) if floor_z is None else floor_z
        position = mount_position(x, y, yaw, fz, self.spec.height, self.spec.forward)
        rotation = mount_rotation(yaw, math.radians(self.spec.pitch_deg)) @ LINK_TO_OPTICAL
        return position, rotation

    def camera_pose(self, x: float, y: float, yaw: float, floor_z: float | None = None
                    ) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """Position and quaternion (x, y, z, w) of the optical frame in the house frame (for TF)."""
        position, rotation = self.optical_pose(x, y, yaw, floor_z)
        px, py, pz = (float(v) for v in position)
        return (px, py, pz), quaternion_from_matrix(rotation)

    def project(self, points: np.ndarray, x: float, y: float, yaw: float,
                floor_z: float | None = None) -> np.ndarray:
        """Pixel coordinates (N, 2) of house-frame points (N, 3) with K (NaN behind the camera)."""
        position, rotation = self.optical_pose(x, y, yaw, floor_z)
        cam = (np.atleast_2d(points) - position) @ rotation
        with np.errstate(divide="ignore", invalid="ignore"):
            uv = (cam @ self.K.T)[:, :2] / cam[:, 2:3]
        uv[cam[:, 2] <= 0] = np.nan
        return uv

    # ------------------------------------------------------------------ capture
    def render(self, x: float, y: float, yaw: float, floor_z: float | None = None,
               development: Development | None = None) -> Frame:
        """The render from robot pose (x, y, yaw), before effects; ``development``: the colour image
        developed through a sensor where the renderer can (Frame.exposure then says so)."""
        position, rotation = self.optical_pose(x, y, yaw, floor_z)
        if self.renderer is None:
            raise RuntimeError("the camera was closed")
        views = self.renderer.render(position, rotation, self.options.manual_exposure, development=development)
        return Frame(views.rgb, views.depth, views.instance, views.background, position, rotation, views.exposure)

    def take_index(self) -> int:
        """The next capture number, used up: a frame due but not rendered (nobody listening) takes
        its number too, so the noise of later frames does not depend on who listened."""
        self.count += 1
        return self.count - 1

    def capture(self, x: float, y: float, yaw: float, floor_z: float | None = None,
                velocity: tuple[float, float] = (0.0, 0.0), index: int | None = None) -> Capture:
        """Render the view from robot pose (x, y, yaw); ``velocity`` (v m/s, w rad/s) for motion blur;
        ``index``: a number taken earlier with :meth:`take_index` (None: the next one)."""
        opts = self.options
        index = self.take_index() if index is None else index
        rng = noise_rng(self.world.state.seed, NOISE_STREAM, self.agent, index)
        # a sensor always blurs over the exposure it chose; the ideal camera where the profile asks
        blur = velocity if opts.motion_blur or self.sensor is not None else (0.0, 0.0)
        # exposure, blur over it, noise, white balance, clipping: where the frame is drawn if the
        # renderer can, else here from its 8-bit image (TinyRenderer)
        development = Development(self.sensor, rng, blur) if self.sensor is not None else None
        frame = self.render(x, y, yaw, floor_z, development)
        rgb, depth, instance = frame.rgb, frame.depth, frame.instance
        if self.sensor is not None and frame.exposure is None:
            rgb, _ = self.sensor.from_rendered(rgb, rng, self.K, blur, typical_depth(depth, self.spec.far))
        elif self.sensor is None and any(blur):
            rgb = imaging.motion_blur(rgb, self.K, velocity[0], velocity[1], opts.exposure,
                                      typical_depth(depth, self.spec.far))
        if self._lens is not None:
            rgb = self._lens.apply(rgb)
            depth = self._lens.apply(depth, nearest=True, fill=np.nan)
            instance = self._lens.apply(instance, nearest=True)
        if opts.pixel_noise > 0:
            rgb = imaging.pixel_noise(rgb, opts.pixel_noise, rng)
        if opts.depth_noise > 0:
            depth = imaging.depth_noise(depth, opts.depth_noise, rng)
        if opts.jpeg_roundtrip:
            rgb = imaging.jpeg_roundtrip(rgb, opts.jpeg_quality)
        return Capture(rgb, depth, instance, self.K.copy(), self.camera_info, (x, y, yaw), frame.position,
                       quaternion_from_matrix(frame.rotation), index)

    def instance_color(self, capture: Capture) -> np.ndarray:
        """(H, W, 3) uint8 image of the instance ids in their footprint mask colours (black = nothing)."""
        return self._instance_rgb[capture.instance]

    def _camera_info(self) -> CameraInfo:
        k = self.K
        d = self.options.distortion or (0.0, 0.0, 0.0, 0.0, 0.0)
        p = np.hstack([k, np.zeros((3, 1))])
        return CameraInfo(CAMERA_OPTICAL_FRAME, self.width, self.height, DISTORTION_MODEL,
                          tuple(float(v) for v in d), tuple(float(v) for v in k.ravel()),
                          tuple(float(v) for v in np.eye(3).ravel()), tuple(float(v) for v in p.ravel()))


def write_capture(camera: SmartCamera, capture: Capture, directory: Path) -> list[Path]:
    """rgb.png, depth.png (16-bit millimetres, 0 = no depth), mask.png (instance colours) and
    info.json (K, poses, the instances in view with their pixel counts) in ``directory``."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = [directory / name for name in ("rgb.png", "depth.png", "mask.png", "info.json")]
    write_image(paths[0], cv2.cvtColor(capture.rgb, cv2.COLOR_RGB2BGR))
    write_image(paths[1], imaging.depth_to_png(capture.depth))
    write_image(paths[2], cv2.cvtColor(camera.instance_color(capture), cv2.COLOR_RGB2BGR))
    counts = np.bincount(capture.instance.ravel())
    by_id = {inst.id: inst for inst in camera.world.instances}
    visible = [{"id": int(i), "name": by_id[i].name, "kind": by_id[i].kind, "type": by_id[i].type,
                "room": by_id[i].room, "mask_color": list(by_id[i].mask_color), "pixels": int(counts[i])}
               for i in np.argsort(-counts) if i in by_id and counts[i] > 0]
    info = {"house": camera.world.house.number, "renderer": camera.backend,
            "robot_pose": list(capture.robot_pose), "frame_id": capture.camera_info.frame_id,
            "camera_position": [float(v) for v in capture.position],
            "camera_orientation": list(capture.orientation), "K": capture.K.tolist(),
            "camera_info": asdict(capture.camera_info), "sun_angle": camera.world.state.sun_angle,
            "lights_on": sorted(k for k, on in camera.world.state.lights.items() if on),
            "depth_png": "uint16 millimetres along the optical axis, 0 = no depth",
            "pixels_without_instance": int(counts[0]), "instances": visible}
    atomic_write(paths[3], (json.dumps(info, indent=1) + "\n").encode())
    return paths


# ---------------------------------------------------------------------------- the camera as a port

# camera_link (x forward, z up) -> optical frame (z forward, x right, y down), REP 103
OPTICAL_ROTATION = quaternion_from_matrix(LINK_TO_OPTICAL)


class CameraPort(SensorPort[CameraSpec, SmartCamera, Capture]):
    """The camera: colour, depth and instance images with their camera info, rendered for captures and
    stored as PNGs (colour, 16-bit mm depth, 16-bit instance ids); the intrinsics go to camera.json."""
    name = "camera"
    section = "camera"
    schema = CameraSection
    frame = names.CAMERA_OPTICAL_FRAME
    captured = True
    topics = (
        Topic("rgb", names.COLOR_IMAGE, "rgb8", dataset=True, bag=False),
        Topic("rgb_info", names.COLOR_INFO, "camera_info", dataset=True, bag=True),
        Topic("jpeg", names.COLOR_COMPRESSED, "jpeg", dataset=False, bag=True),
        Topic("depth", names.DEPTH_IMAGE, "32FC1", dataset=True, bag=True),
        Topic("depth_info", names.DEPTH_INFO, "camera_info", dataset=False, bag=True),
        Topic("instance", names.INSTANCE_IMAGE, "16UC1", dataset=True, bag=True),
    )
    files = {"rgb": ".png", "depth": ".png", "mask": ".png"}

    def spec(self, section: CameraSection) -> CameraSpec:
        return CameraSpec(section.height, section.pitch, section.forward, section.width, section.height_px,
                          section.sensor_width, section.sensor_height, section.focal_length, section.near,
                          section.far, section.rate, section.quality,
                          tuple(sorted(section.effects.model_dump(exclude_none=True).items())),
                          section.sensor.model())

    def rate(self, spec: CameraSpec) -> float:
        return spec.rate

    def mounts(self, spec: CameraSpec) -> list[Mount]:
        """camera_link on base_link from the same mount functions the camera renders with (TF and images
        agree), and the optical frame on camera_link."""
        cam = spec
        return [(names.BASE_FRAME, names.CAMERA_FRAME,
                 tuple(mount_position(0.0, 0.0, 0.0, 0.0, cam.height, cam.forward)),
                 quaternion_from_matrix(mount_rotation(0.0, math.radians(cam.pitch_deg)))),
                (names.CAMERA_FRAME, names.CAMERA_OPTICAL_FRAME, (0.0, 0.0, 0.0), OPTICAL_ROTATION)]

    def build(self, world: World, spec: CameraSpec, agent: str, backend: str = "auto") -> SmartCamera:
        return SmartCamera(world, spec, CameraOptions(**dict(spec.effects)), agent, spec.sensor, backend)

    def read(self, sensor: SmartCamera, carrier: Carrier) -> Capture:
        x, y, yaw = carrier.pose
        return sensor.capture(x, y, yaw, velocity=carrier.velocity)

    def value(self, key: str, data: Capture, sensor: SmartCamera, frame: str) -> Any:
        if key in ("rgb_info", "depth_info"):
            return replace(data.camera_info, frame_id=frame)
        if key == "jpeg":
            return imaging.encode_jpeg(data.rgb, sensor.options.jpeg_quality)
        if key == "instance":
            return data.instance.astype(np.uint16)
        return {"rgb": data.rgb, "depth": data.depth}[key]

    def encode(self, values: Mapping[str, Any]) -> Stored:
        rgb, depth, instance, info = values["rgb"], values["depth"], values["instance"], values["rgb_info"]
        h, w = rgb.shape[:2]
        if rgb.shape != (h, w, 3) or depth.shape != (h, w) or instance.shape != (h, w):
            raise ValueError(f"image shapes differ: rgb {rgb.shape}, depth {depth.shape}, instance {instance.shape}")
        if instance.size and (instance.min() < 0 or instance.max() > np.iinfo(np.uint16).max):
            raise ValueError("instance ids must fit in 16 bits")
        intrinsics = {"width": info.width, "height": info.height, "K": list(info.K), "D": list(info.D),
                      "distortion_model": info.distortion_model, "frame_id": info.frame_id}
        return Stored({"rgb": encode_png(np.ascontiguousarray(rgb, np.uint8)),
                       "depth": encode_png(imaging.depth_to_png(depth)),
                       "mask": encode_png(instance.astype(np.uint16))},
                      agent_facts={CAMERA_JSON: intrinsics})

    def decode(self, kind: str, path: Path, row: Mapping[str, Any]) -> np.ndarray:
        """rgb: (H, W, 3) uint8 RGB; depth: (H, W) float32 metres along the optical axis, NaN = no
        depth (1 mm steps); mask: (H, W) uint16 instance ids (footprint ids), 0 = nothing."""
        pixels = read_png(path)
        return imaging.depth_from_png(pixels) if kind == "depth" else pixels


PORT = CameraPort()
