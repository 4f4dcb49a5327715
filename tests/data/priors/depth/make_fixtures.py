#!/usr/bin/python3
"""Writes the fixtures of tests/priors/depth/*_test.cpp by running the authors' Depth Anything V2
code.

The official repository (github.com/DepthAnything/Depth-Anything-V2) is not part of this one:
fetch it yourself and pass the folder that holds its depth_anything_v2 package. Run with a Python
that has torch, numpy and OpenCV (the system /usr/bin/python3 plus python3-opencv here);
torchvision is optional, see `provide_compose`:
    /usr/bin/python3 tests/data/priors/depth/make_fixtures.py /path/to/Depth-Anything-V2

Files written next to this script:
    tiny.pth                 state dict of a small official-layout DepthAnythingV2 (the official
                             DinoVisionTransformer and DPTHead classes with small sizes), every
                             weight drawn from a fixed seed
    net_<H>x<W>_in.npy       a (1, 3, H, W) pre-normalized network input
    net_<H>x<W>_out.npy      the official forward() of the tiny model on it, (1, H, W)
    image.png                a small 8-bit picture, written by cv2 as run.py reads it
    image_<S>_in.npy         the official image2tensor(image, S): resized and normalized input
    image_depth.npy          the official infer_image(image) of the tiny model, (h, w)
    vits_names.txt           "name dim0 dim1 ..." for every state-dict entry of the real vits
                             configuration
"""
import functools
import math
import os
import sys
import types

import cv2
import numpy as np
import torch

HERE = os.path.dirname(os.path.abspath(__file__))

# Small sizes on the same code paths as the real models: several heads, LayerScale, an
# interpolated 4x4 positional grid and four taken blocks out of five.
TINY_VIT = dict(img_size=56, patch_size=14, embed_dim=24, depth=5, num_heads=2, mlp_ratio=4,
                init_values=1.0, ffn_layer="mlp", block_chunks=0, num_register_tokens=0,
                interpolate_antialias=False, interpolate_offset=0.1)
TINY_LAYERS = [1, 2, 3, 4]
TINY_HEAD = dict(features=8, use_bn=False, out_channels=[6, 12, 16, 24])
# 56x56 takes the official shortcut that skips interpolating the positional embedding.
NET_INPUTS = [(56, 56), (42, 70)]
# Upscaled to a 70 short side, downscaled to a 28 one (multiples of 14).
PREPROCESS_SIZES = [70, 28]
IMAGE_SIZE = (27, 40)
VITS = dict(encoder="vits", features=64, out_channels=[48, 96, 192, 384])


def provide_compose():
    """dpt.py imports Compose from torchvision, which image2tensor uses only to chain calls."""
    try:
        import torchvision.transforms  # noqa: F401
        return
    except ImportError:
        pass

    class Compose:
        def __init__(self, transforms):
            self.transforms = transforms

        def __call__(self, sample):
            for transform in self.transforms:
                sample = transform(sample)
            return sample

    transforms = types.ModuleType("torchvision.transforms")
    transforms.Compose = Compose
    sys.modules["torchvision"] = types.ModuleType("torchvision")
    sys.modules["torchvision.transforms"] = transforms


def load_official(root):
    provide_compose()
    sys.path.insert(0, root)
    from depth_anything_v2 import dinov2, dpt
    from depth_anything_v2.dinov2_layers import MemEffAttention, NestedTensorBlock
    return dinov2, dpt, MemEffAttention, NestedTensorBlock


def tiny_model(official):
    """The official DepthAnythingV2 with its encoder and head swapped for smaller instances."""
    dinov2, dpt, attention, block = official
    model = dpt.DepthAnythingV2(**VITS)
    model.pretrained = dinov2.DinoVisionTransformer(
        block_fn=functools.partial(block, attn_class=attention), **TINY_VIT)
    model.depth_head = dpt.DPTHead(TINY_VIT["embed_dim"], **TINY_HEAD)
    model.intermediate_layer_idx = {"vits": TINY_LAYERS}
    return model.eval()


def randomize(model, generator):
    """Draws every parameter so that no LayerNorm or LayerScale is the identity, the class token
    and positional embedding matter, and the final ReLU keeps most pixels positive."""
    with torch.no_grad():
        for name, p in model.named_parameters():
            noise = torch.randn(p.shape, generator=generator)
            if "norm" in name or name.endswith("gamma"):
                p.copy_((1.0 if not name.endswith("bias") else 0.0) + 0.2 * noise)
            elif name.endswith("output_conv2.2.bias"):
                p.copy_(0.3 + 0.1 * noise)
            elif name.endswith("bias") or p.dim() == 3 or name.endswith("mask_token"):
                p.copy_(0.1 * noise)
            else:
                p.copy_(noise / math.sqrt(p[0].numel()))


def check_informative(name, values):
    positive = float((values > 0).float().mean())
    if positive < 0.5 or float(values.std()) < 1e-3:
        sys.exit(f"{name}: output too flat to test anything ({positive:.0%} positive)")


def write_network_fixtures(model, generator):
    for h, w in NET_INPUTS:
        x = torch.randn((1, 3, h, w), generator=generator)
        with torch.no_grad():
            out = model(x)
        check_informative(f"net_{h}x{w}", out)
        np.save(os.path.join(HERE, f"net_{h}x{w}_in.npy"), x.numpy().astype(np.float32))
        np.save(os.path.join(HERE, f"net_{h}x{w}_out.npy"), out.numpy().astype(np.float32))


def synthetic_image(rng):
    """A color gradient with noise and a sharp block, so resampling both smooths and overshoots."""
    h, w = IMAGE_SIZE
    y, x = np.mgrid[0:h, 0:w]
    image = np.stack([x * 255 / (w - 1), y * 255 / (h - 1), (x + y) * 128 / (w + h)], axis=-1)
    image[h // 3:2 * h // 3, w // 4:w // 2] = (255, 0, 255)
    image += rng.integers(-30, 31, size=image.shape)
    return np.clip(image, 0, 255).astype(np.uint8)


def write_image_fixtures(model, rng):
    path = os.path.join(HERE, "image.png")
    cv2.imwrite(path, synthetic_image(rng))
    raw = cv2.imread(path)
    for size in PREPROCESS_SIZES:
        tensor, _ = model.image2tensor(raw, size)
        np.save(os.path.join(HERE, f"image_{size}_in.npy"), tensor.numpy().astype(np.float32))
    depth = model.infer_image(raw)
    check_informative("image_depth", torch.from_numpy(depth))
    np.save(os.path.join(HERE, "image_depth.npy"), depth.astype(np.float32))


def write_names(official):
    model = official[1].DepthAnythingV2(**VITS)
    with open(os.path.join(HERE, "vits_names.txt"), "w") as f:
        for key, value in model.state_dict().items():
            f.write(" ".join([key] + [str(d) for d in value.shape]) + "\n")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    official = load_official(sys.argv[1])
    generator = torch.Generator().manual_seed(0)
    model = tiny_model(official)
    randomize(model, generator)
    torch.save(model.state_dict(), os.path.join(HERE, "tiny.pth"))
    write_network_fixtures(model, generator)
    write_image_fixtures(model, np.random.default_rng(0))
    write_names(official)


if __name__ == "__main__":
    main()
