#!/usr/bin/python3
"""Writes the fixtures of tests/priors/sr/swinir_test.cpp by running the authors' SwinIR code.

The official models/network_swinir.py (github.com/JingyunLiang/SwinIR) is not part of this
repository: fetch it yourself and pass its path. Run with a Python that has torch and numpy
(the system /usr/bin/python3 here); timm is optional, see `provide_timm_layers`:
    /usr/bin/python3 tests/data/priors/swinir/make_fixtures.py /path/to/network_swinir.py

Files written next to this script:
    tiny_<upsampler>_x<s>.pth        {'params': state_dict} of a small official-layout network,
                                     every weight drawn from a fixed seed
    tiny_<upsampler>_x<s>_in.npy     a (1, 3, H, W) input, H or W not a window multiple
    tiny_<upsampler>_x<s>_out.npy    the output of the official test procedure on that input
    swinir_<config>_x<s>_names.txt   "name dim0 dim1 ..." for every state-dict entry of the real
                                     configuration except the attn_mask buffers
"""
import importlib.util
import math
import os
import sys
import types

import numpy as np
import torch

HERE = os.path.dirname(os.path.abspath(__file__))
WINDOW = 8

# name -> (SwinIR keyword arguments, input height and width)
TINY = {
    "tiny_pixelshuffle_x2": (
        dict(upscale=2, embed_dim=16, depths=[2, 2], num_heads=[2, 2], upsampler="pixelshuffle"),
        (13, 21)),
    "tiny_pixelshuffledirect_x3": (
        dict(upscale=3, embed_dim=16, depths=[2, 3], num_heads=[2, 4],
             upsampler="pixelshuffledirect"),
        (16, 11)),
    "tiny_nearestconv_x2": (
        dict(upscale=2, embed_dim=16, depths=[2], num_heads=[2], upsampler="nearest+conv"),
        (9, 10)),
    "tiny_nearestconv_3conv_x4": (
        dict(upscale=4, embed_dim=16, depths=[2, 2], num_heads=[2, 4], upsampler="nearest+conv",
             resi_connection="3conv"),
        (12, 7)),
}
# The classical-SR, lightweight-SR and real-world-SR settings of the official main_test_swinir.py.
REAL = {
    "swinir_m_x4": dict(upscale=4, img_size=64, embed_dim=180, depths=[6] * 6, num_heads=[6] * 6,
                        upsampler="pixelshuffle"),
    "swinir_s_x2": dict(upscale=2, img_size=64, embed_dim=60, depths=[6] * 4, num_heads=[6] * 4,
                        upsampler="pixelshuffledirect"),
    "swinir_real_m_x4": dict(upscale=4, img_size=64, embed_dim=180, depths=[6] * 6,
                             num_heads=[6] * 6, upsampler="nearest+conv"),
    "swinir_real_l_x4": dict(upscale=4, img_size=64, embed_dim=240, depths=[6] * 9,
                             num_heads=[8] * 9, upsampler="nearest+conv", resi_connection="3conv"),
}
COMMON = dict(in_chans=3, window_size=WINDOW, img_range=1.0, mlp_ratio=2, resi_connection="1conv")


def provide_timm_layers():
    """network_swinir.py imports three helpers from timm; inference needs only trivial ones."""
    try:
        import timm.models.layers  # noqa: F401
        return
    except ImportError:
        pass
    layers = types.ModuleType("timm.models.layers")
    layers.to_2tuple = lambda x: tuple(x) if isinstance(x, (tuple, list)) else (x, x)
    layers.trunc_normal_ = lambda tensor, std=1.0: torch.nn.init.trunc_normal_(tensor, std=std)
    layers.DropPath = lambda p: torch.nn.Identity()
    for name in ("timm", "timm.models"):
        sys.modules[name] = types.ModuleType(name)
    sys.modules["timm.models.layers"] = layers


def load_official(path):
    provide_timm_layers()
    spec = importlib.util.spec_from_file_location("network_swinir", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.SwinIR


def randomize(model, generator):
    """Draws every parameter so that no LayerNorm is the identity and attention is not uniform."""
    with torch.no_grad():
        for name, p in model.named_parameters():
            noise = torch.randn(p.shape, generator=generator)
            if "norm" in name:
                p.copy_((1.0 if name.endswith("weight") else 0.0) + 0.2 * noise)
            elif name.endswith("bias"):
                p.copy_(0.1 * noise)
            elif name.endswith("relative_position_bias_table"):
                p.copy_(0.5 * noise)
            else:
                p.copy_(noise / math.sqrt(p[0].numel()))


def official_test(model, img_lq, scale):
    """main_test_swinir.py's inference: mirror-pad bottom/right by up to one window, crop back."""
    _, _, h_old, w_old = img_lq.size()
    h_pad = (h_old // WINDOW + 1) * WINDOW - h_old
    w_pad = (w_old // WINDOW + 1) * WINDOW - w_old
    img_lq = torch.cat([img_lq, torch.flip(img_lq, [2])], 2)[:, :, :h_old + h_pad, :]
    img_lq = torch.cat([img_lq, torch.flip(img_lq, [3])], 3)[:, :, :, :w_old + w_pad]
    with torch.no_grad():
        output = model(img_lq)
    return output[..., :h_old * scale, :w_old * scale]


def write_tiny(SwinIR, name, kwargs, size, seed):
    generator = torch.Generator().manual_seed(seed)
    # img_size 16 keeps the stored attn_mask buffers small while shifted windows stay enabled.
    model = SwinIR(img_size=16, **{**COMMON, **kwargs}).eval()
    randomize(model, generator)
    img = torch.rand((1, 3) + size, generator=generator)
    out = official_test(model, img, kwargs["upscale"])
    torch.save({"params": model.state_dict()}, os.path.join(HERE, name + ".pth"))
    np.save(os.path.join(HERE, name + "_in.npy"), img.numpy().astype(np.float32))
    np.save(os.path.join(HERE, name + "_out.npy"), out.numpy().astype(np.float32))


def write_names(SwinIR, name, kwargs):
    model = SwinIR(**{**COMMON, **kwargs})
    with open(os.path.join(HERE, name + "_names.txt"), "w") as f:
        for key, value in model.state_dict().items():
            if not key.endswith("attn_mask"):
                f.write(" ".join([key] + [str(d) for d in value.shape]) + "\n")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    SwinIR = load_official(sys.argv[1])
    for seed, (name, (kwargs, size)) in enumerate(TINY.items()):
        write_tiny(SwinIR, name, kwargs, size, seed)
    for name, kwargs in REAL.items():
        write_names(SwinIR, name, kwargs)


if __name__ == "__main__":
    main()
