"""From per-capture 2-D detections to a semantic map: back-project, box, fuse across captures.

This is the API for plugging in a detector (Detectron2 or anything that gives instance masks)::

    from ravh_sim.dataset.api import Dataset
    from ravh_sim.eval.fusion import Detection, build_map

    def detect(sample):                        # one Sample -> its detections
        out = predictor(sample.rgb[:, :, ::-1])["instances"]
        return [Detection(names[c], m.numpy(), s) for c, m, s in zip(out.pred_classes, out.pred_masks, out.scores)]

    semantic_map = build_map(Dataset("raid20"), detect)

Each detection's mask pixels with depth are back-projected through the capture's camera (intrinsics
and distortion from camera.json, mount from the robot profile, ground-truth pose) into house-frame
points. Rules,
the same for every mapper:

* masks of at least :data:`ERODE_FROM` pixels are eroded by one pixel first, so edge pixels that
  fall on the background behind an object do not stretch its box;
* a detection with fewer than :data:`MIN_POINTS` points with depth is dropped;
* a detection joins a fused object of the same type when at least :data:`MERGE_SHARE` of its
  points lie in the object's box grown by :data:`MERGE_MARGIN` m, or that share of the object's
  points lie in the detection's grown box (a partial view lies on or in the full view, whichever
  came first); otherwise it starts a new object. Objects that a merge makes overlap by the same
  rule are joined too. The object's box is rebuilt from all its points (kept on a
  :data:`VOXEL` m grid) as the minimum-area yawed box, each side at least :data:`MIN_SIZE` m;
  its score is the mean of its detections' scores, ``captures`` lists where it was seen.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import cv2
import numpy as np

from ravh_msgs_py.names import DEFAULT_PROFILE
from ravh_sim.dataset.api import Dataset, Sample
from ravh_sim.eval.semantic_map import LabelledBox, SemanticMap, box_of_points
from ravh_sim.robot.profile import load_profile
from ravh_sim.sensors.mount import LINK_TO_OPTICAL, mount_position, mount_rotation

ERODE_FROM = 200            # px
MIN_POINTS = 20
MERGE_SHARE = 0.5
MERGE_MARGIN = 0.02         # m
VOXEL = 0.03                # m
MIN_SIZE = 0.05             # m
MAX_POINTS_PER_DETECTION = 4000


@dataclass(frozen=True)
class Detection:
    """One detected object in one capture: its type, (H, W) boolean mask and confidence."""
    type: str
    mask: np.ndarray
    score: float = 1.0


class CameraModel:
    """Back-projects a capture's pixels into the house frame (the camera the dataset was taken with)."""

    def __init__(self, dataset: Dataset) -> None:
        self.dataset = dataset
        profiles = {a.name: a.profile for a in dataset.settings.agents}
        self._spec = {agent: load_profile(profiles.get(agent, DEFAULT_PROFILE)).camera
                      for agent in dataset.meta["agents"]}
        self._K = {agent: np.array(cam["K"], float).reshape(3, 3) for agent, cam in dataset.camera.items()}
        self._D = {agent: np.array(cam.get("D") or [], float) for agent, cam in dataset.camera.items()}
        self._outside_floor_z = float(np.median([r.floor_z for r in dataset.house.rooms]))   # as World's

    def points(self, sample: Sample, mask: np.ndarray, at_most: int = 0) -> np.ndarray:
        """(N, 3) house-frame points of the ``mask`` pixels that have depth (``at_most``: a
        regular subsample of that many pixels; 0: all)."""
        v, u = np.nonzero(mask)
        if at_most and len(u) > at_most:
            step = math.ceil(len(u) / at_most)
            v, u = v[::step], u[::step]
        z = sample.depth[v, u]
        keep = np.isfinite(z)
        u, v, z = u[keep], v[keep], z[keep]
        if len(u) == 0:
            return np.zeros((0, 3))
        rays = np.ones((len(u), 3))
        pixels = np.column_stack((u, v)).astype(np.float64).reshape(-1, 1, 2)
        rays[:, :2] = cv2.undistortPoints(pixels, self._K[sample.agent], self._D[sample.agent]).reshape(-1, 2)
        position, rotation = self.optical_pose(sample)
        return (rays * z[:, None].astype(float)) @ rotation.T + position

    def optical_pose(self, sample: Sample) -> tuple[np.ndarray, np.ndarray]:
        spec = self._spec[sample.agent]
        x, y, yaw = sample.pose
        room = self.dataset.house.room_at(x, y)
        floor_z = room.floor_z if room is not None else self._outside_floor_z
        return (mount_position(x, y, yaw, floor_z, spec.height, spec.forward),
                mount_rotation(yaw, math.radians(spec.pitch_deg)) @ LINK_TO_OPTICAL)


@dataclass(eq=False)
class _Fused:
    type: str
    points: np.ndarray
    box: LabelledBox
    scores: list[float] = field(default_factory=list)
    captures: set[int] = field(default_factory=set)


class MapFuser:
    """Accumulates detections capture by capture into fused objects (see the module's rules)."""

    def __init__(self, dataset: Dataset) -> None:
        self.dataset = dataset
        self.camera = CameraModel(dataset)
        self._objects: list[_Fused] = []

    def add(self, sample: Sample, detections: Iterable[Detection]) -> None:
        for det in detections:
            points = self.camera.points(sample, _eroded(det.mask), MAX_POINTS_PER_DETECTION)
            if len(points) < MIN_POINTS:
                continue
            self.add_points(det.type, points, det.score, sample.index)

    def add_points(self, type_: str, points: np.ndarray, score: float, capture: int) -> None:
        """Fuse one observation, given as house-frame points, into the map."""
        points = _voxel(points)
        new = _Fused(type_, points, box_of_points(type_, points, MIN_SIZE), [score], {capture})
        target = next((o for o in self._objects if _same_object(o, new)), None)
        if target is None:
            self._objects.append(new)
            return
        _absorb(target, new)
        while (other := next((o for o in self._objects if o is not target and _same_object(o, target)),
                             None)) is not None:
            self._objects.remove(other)
            _absorb(target, other)

    def semantic_map(self) -> SemanticMap:
        boxes = [LabelledBox(o.type, o.box.center, o.box.size, o.box.yaw, float(np.mean(o.scores)),
                             tuple(sorted(o.captures))) for o in self._objects]
        return SemanticMap(int(self.dataset.meta["house"]), boxes)


def build_map(dataset: Dataset, detect: Callable[[Sample], list[Detection]]) -> SemanticMap:
    """Run ``detect`` on every capture of ``dataset`` and fuse the detections into a semantic map."""
    fuser = MapFuser(dataset)
    detections = 0
    for sample in dataset:
        found = detect(sample)
        detections += len(found)
        fuser.add(sample, found)
    semantic_map = fuser.semantic_map()
    semantic_map.detections = detections
    return semantic_map


def _same_object(a: _Fused, b: _Fused) -> bool:
    """The fusion rule: same type, and one's points mostly lie in the other's grown box."""
    if a.type != b.type or _apart(a.points, b.points):
        return False
    return (a.box.grown(MERGE_MARGIN).contains(b.points).mean() >= MERGE_SHARE
            or b.box.grown(MERGE_MARGIN).contains(a.points).mean() >= MERGE_SHARE)


def _apart(p: np.ndarray, q: np.ndarray) -> bool:
    """The point sets' axis-aligned bounds are further apart than any box could reach (a quick no)."""
    reach = MERGE_MARGIN + MIN_SIZE
    return bool(np.any(p.min(axis=0) > q.max(axis=0) + reach) or np.any(q.min(axis=0) > p.max(axis=0) + reach))


def _absorb(target: _Fused, other: _Fused) -> None:
    target.points = _voxel(np.vstack((target.points, other.points)))
    target.box = box_of_points(target.type, target.points, MIN_SIZE)
    target.scores.extend(other.scores)
    target.captures |= other.captures


def _eroded(mask: np.ndarray) -> np.ndarray:
    mask = np.asarray(mask, bool)
    if mask.sum() < ERODE_FROM:
        return mask
    return cv2.erode(mask.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)


def _voxel(points: np.ndarray) -> np.ndarray:
    """One point per occupied VOXEL cell (the first), so fused objects stay small in memory."""
    cells = np.floor(points / VOXEL).astype(np.int64) + 2 ** 20        # non-negative below 30 km
    _, first = np.unique((cells[:, 0] << 42) | (cells[:, 1] << 21) | cells[:, 2], return_index=True)
    return points[np.sort(first)]
