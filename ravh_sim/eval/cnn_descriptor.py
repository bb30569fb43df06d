"""A learned global descriptor for Table 4: EfficientNet-Lite0's ImageNet features, pooled.

The paper localized with NetVLAD; a CNN trained on ImageNet, its last feature map pooled, is the usual
learned baseline that needs no training of our own. The network ships as an ONNX file beside this module
(``weights/``, Apache-2.0, see its ATTRIBUTION.md; exported once from PyTorch by
``tools/export_cnn_onnx.py``) and runs on onnxruntime, the optional extra ``pip install 'ravh_sim[cnn]'``:
nothing is downloaded at run time, and onnxruntime is a tenth of torch's size and about three times
faster per image on one core. Use it with
``ravh eval localization --descriptor ravh_sim.eval.cnn_descriptor:efficientnet_lite0``.

The image is resized to :data:`INPUT` (the camera's 4:3 aspect), scaled to [-1, 1] as the Lite models
were trained, and its 1280-channel last feature map is GeM-pooled (p = 3: between average and max
pooling, the usual choice for retrieval) over a 2 x 2 grid of cells, so the descriptor keeps where
things are in the view; each cell's vector is L2-normalised.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ravh_sim.errors import UserError

INPUT = (224, 168)                 # px (w, h)
GRID = 2                           # pooling cells across and down
GEM_P = 3.0
WEIGHTS = Path(__file__).parent / "weights"
MODEL = WEIGHTS / "efficientnet_lite0.onnx"
REFERENCE = WEIGHTS / "efficientnet_lite0_check.npz"      # an input and PyTorch's descriptor of it


@lru_cache(maxsize=1)
def _session() -> Any:
    try:
        import onnxruntime
    except ImportError:
        raise UserError("the CNN descriptor needs the optional extra: pip install 'ravh_sim[cnn]'") from None
    options = onnxruntime.SessionOptions()
    options.intra_op_num_threads = options.inter_op_num_threads = 1     # one raid or evaluation per core
    return onnxruntime.InferenceSession(str(MODEL), options, providers=["CPUExecutionProvider"])


def normalised_input(image: np.ndarray) -> np.ndarray:
    """The network's (1, 3, h, w) float32 input of an (H, W, 3) uint8 RGB image."""
    small = cv2.resize(np.ascontiguousarray(image, np.uint8), INPUT, interpolation=cv2.INTER_AREA)
    return np.ascontiguousarray(((small.astype(np.float32) - 127.0) / 128.0).transpose(2, 0, 1)[None])


def _cell_bounds(size: int) -> list[tuple[int, int]]:
    """Adaptive average pooling's cells along one axis: overlapping where ``size`` does not divide."""
    return [(i * size // GRID, -(-(i + 1) * size // GRID)) for i in range(GRID)]


def efficientnet_lite0(image: np.ndarray) -> np.ndarray:
    """GRID * GRID * 1280 values (see the module) of an (H, W, 3) uint8 RGB image."""
    session = _session()
    features = session.run(None, {session.get_inputs()[0].name: normalised_input(image)})[0][0]
    cubed = np.maximum(features, 1e-6) ** GEM_P                     # (1280, h, w)
    rows, cols = _cell_bounds(cubed.shape[1]), _cell_bounds(cubed.shape[2])
    cells = np.array([cubed[:, r0:r1, c0:c1].mean(axis=(1, 2)) for r0, r1 in rows for c0, c1 in cols])
    cells **= 1.0 / GEM_P
    cells /= np.linalg.norm(cells, axis=1, keepdims=True) + 1e-12
    return cells.ravel().astype(np.float32)
