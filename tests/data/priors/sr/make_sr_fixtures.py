#!/usr/bin/python3
"""Writes the fixtures of tests/priors/sr/{safmn,imdn,pan}_test.cpp by running the authors'
PyTorch modules, so the C++ networks are checked against the reference implementation.

    /usr/bin/python3 tests/data/priors/sr/make_sr_fixtures.py OFFICIAL_DIR [SHARED_DATA]

OFFICIAL_DIR holds unmodified copies of the official architecture files, importable as
    team15_SAFMN.py               SAFMN, NTIRE 2023 efficient-SR release (sunny2109/SAFMN)
    safmn_arch.py                 SAFMN, the paper's models (sunny2109/SAFMN, basicsr/archs/)
    model/architecture.py, model/block.py                               IMDN (Zheng222/IMDN)
    models/archs/PAN_arch.py, models/archs/arch_util.py     PAN (zhaohengyuan1/PAN, codes/)

Files written next to this script:
    lego_lr_crop.npy          (1, 3, 20, 24) input: a crop of lego test view 0, bicubic x1/4
    bicubic_x4_lego.npy       Pillow's float ("F" mode) bicubic x4 of that input
    <net>_x4_lego.npy         the released x4 checkpoint's output for that input
    tiny_<net>_x2.pth         a small seeded x2 configuration of the official layout
    tiny_<net>_x2_lego.npy    its output for the same input
    tiny_safmn_iccv_x2.pth, tiny_safmn_iccv_x2_lego.npy     the same for the paper's SAFMN
    safmn_<config>_names.txt  parameter names and shapes of released SAFMN configurations

The official files import modules they never use (einops, torchvision, BasicSR's registry);
where those are not installed, empty stand-ins take their place.
"""
import os
import sys
import types

import numpy as np
import torch
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "..", "..", "..", "shared", "data"))


def lego_lr_crop(shared):
    rgba = Image.open(os.path.join(shared, "nerf_synthetic", "lego", "test", "r_0.png"))
    lr = np.asarray(rgba.resize((200, 200), Image.BICUBIC), dtype=np.float32) / 255.0
    rgb = lr[..., :3] * lr[..., 3:] + (1.0 - lr[..., 3:])  # over white, as the protocol does
    crop = rgb[96:116, 84:108]
    return torch.from_numpy(np.ascontiguousarray(crop.transpose(2, 0, 1)[None]))


def pillow_bicubic(lr, scale):
    channels = []
    for plane in lr[0].numpy():
        image = Image.fromarray(plane, mode="F")
        size = (image.width * scale, image.height * scale)
        channels.append(np.asarray(image.resize(size, Image.BICUBIC), dtype=np.float32))
    return np.stack(channels)[None]


def load(path):
    return torch.load(path, map_location="cpu")


def save_output(net, lr, name):
    with torch.no_grad():
        out = net.eval()(lr)
    np.save(os.path.join(HERE, name), out.numpy().astype(np.float32))


def randomize_norms(net):
    # GRN starts as the identity (zero gamma and beta); random values make the test see it.
    gen = torch.Generator().manual_seed(1)
    for name, p in net.named_parameters():
        if name.startswith("norm."):
            p.data = torch.randn(p.shape, generator=gen) * 0.5


def stub_unused_imports():
    for name in ("einops", "torchvision", "basicsr", "basicsr.utils", "basicsr.utils.registry"):
        try:
            __import__(name)
        except ImportError:
            sys.modules[name] = types.ModuleType(name)
    sys.modules["einops"].__dict__.setdefault("rearrange", None)
    sys.modules["torchvision"].__dict__.setdefault("ops", None)
    registry = types.SimpleNamespace(register=lambda: (lambda cls: cls))
    sys.modules["basicsr.utils.registry"].__dict__.setdefault("ARCH_REGISTRY", registry)


def randomize_layer_norms(net):
    # The blocks' LayerNorms start as the identity too.
    gen = torch.Generator().manual_seed(2)
    for name, p in net.named_parameters():
        if ".norm1." in name or ".norm2." in name:
            p.data = torch.randn(p.shape, generator=gen) * 0.5 + (1.0 if name.endswith("weight") else 0.0)


def save_names(net, name):
    with open(os.path.join(HERE, name), "w") as out:
        for key, value in net.state_dict().items():
            out.write(" ".join([key] + [str(d) for d in value.shape]) + "\n")


def write_paper_safmn(safmn_arch, lr):
    # The configurations of SAFMN_DF2K_x3.pth and SAFMN_L_Real_LSDIR_x4-v2.pth.
    save_names(safmn_arch.SAFMN(dim=36, n_blocks=8, ffn_scale=2.0, upscaling_factor=3),
               "safmn_df2k_x3_names.txt")
    save_names(safmn_arch.SAFMN(dim=128, n_blocks=16, ffn_scale=2.0, upscaling_factor=4),
               "safmn_l_x4_names.txt")
    torch.manual_seed(3)
    safmn = safmn_arch.SAFMN(dim=8, n_blocks=2, ffn_scale=2.0, upscaling_factor=2)
    randomize_layer_norms(safmn)
    torch.save({"params": safmn.state_dict()}, os.path.join(HERE, "tiny_safmn_iccv_x2.pth"))
    save_output(safmn, lr, "tiny_safmn_iccv_x2_lego.npy")


def main():
    official = sys.argv[1]
    shared = sys.argv[2] if len(sys.argv) > 2 else DEFAULT_SHARED
    sys.path.insert(0, official)
    stub_unused_imports()
    import safmn_arch
    import team15_SAFMN
    from model import architecture as imdn_arch
    from models.archs import PAN_arch

    weights = os.path.join(shared, "weights", "sr")
    lr = lego_lr_crop(shared)
    np.save(os.path.join(HERE, "lego_lr_crop.npy"), lr.numpy())
    np.save(os.path.join(HERE, "bicubic_x4_lego.npy"), pillow_bicubic(lr, 4))

    safmn = team15_SAFMN.SAFMN(dim=36, n_blocks=8, ffn_scale=2.0, upscaling_factor=4)
    safmn.load_state_dict(load(os.path.join(weights, "SAFMN_x4.pth"))["params"], strict=True)
    save_output(safmn, lr, "safmn_x4_lego.npy")
    imdn = imdn_arch.IMDN(upscale=4)
    state = {k[len("module."):]: v for k, v in load(os.path.join(weights, "IMDN_x4.pth")).items()}
    imdn.load_state_dict(state, strict=True)
    save_output(imdn, lr, "imdn_x4_lego.npy")
    pan = PAN_arch.PAN(in_nc=3, out_nc=3, nf=40, unf=24, nb=16, scale=4)
    pan.load_state_dict(load(os.path.join(weights, "PAN_x4.pth")), strict=True)
    save_output(pan, lr, "pan_x4_lego.npy")

    # Tiny seeded configurations, saved in each release's own container layout.
    torch.manual_seed(0)
    safmn = team15_SAFMN.SAFMN(dim=8, n_blocks=2, ffn_scale=2.0, upscaling_factor=2)
    randomize_norms(safmn)
    torch.save({"params": safmn.state_dict()}, os.path.join(HERE, "tiny_safmn_x2.pth"))
    save_output(safmn, lr, "tiny_safmn_x2_lego.npy")
    imdn = imdn_arch.IMDN(in_nc=3, nf=16, num_modules=6, out_nc=3, upscale=2)
    state = {"module." + k: v for k, v in imdn.state_dict().items()}
    torch.save(state, os.path.join(HERE, "tiny_imdn_x2.pth"))
    save_output(imdn, lr, "tiny_imdn_x2_lego.npy")
    pan = PAN_arch.PAN(in_nc=3, out_nc=3, nf=8, unf=8, nb=2, scale=2)
    torch.save(pan.state_dict(), os.path.join(HERE, "tiny_pan_x2.pth"))
    save_output(pan, lr, "tiny_pan_x2_lego.npy")
    write_paper_safmn(safmn_arch, lr)


if __name__ == "__main__":
    main()
