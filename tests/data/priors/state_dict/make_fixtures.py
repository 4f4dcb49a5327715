#!/usr/bin/python3
"""Writes the fixtures of tests/priors/state_dict_test.cpp with PyTorch's own torch.save.

Run with a Python that has torch (Debian's python3-torch: /usr/bin/python3):
    /usr/bin/python3 tests/data/priors/state_dict/make_fixtures.py

Every tensor is a formula the test recomputes, so the test needs no expected-value files:
    mixed_<variant>.pth   the same mixed state dict in each container variant (see VARIANTS)
    wrapped.pth           {"params": ..., "params_ema": ..., "epoch": 3, "args": Namespace(...)}
    module_legacy.pth     a DataParallel-style ("module." prefixed) conv + batch-norm state dict
"""
import argparse
import collections
import io
import os
import struct
import zipfile

import torch

HERE = os.path.dirname(os.path.abspath(__file__))


def mixed_state_dict():
    base = torch.arange(12, dtype=torch.float32).reshape(3, 4) + 100
    return collections.OrderedDict([
        ("conv.weight", torch.arange(24, dtype=torch.float32).reshape(2, 3, 2, 2) - 12),
        ("half", (torch.arange(6, dtype=torch.float32) / 4).half()),
        ("double", torch.arange(5, dtype=torch.float64) / 3),
        ("bfloat16", (torch.arange(4, dtype=torch.float32) * 0.5).bfloat16()),
        ("base", base),
        ("transposed", base.t()),       # shares base's storage, strides (1, 4)
        ("strided", base[1:, ::2]),     # offset 4, strides (4, 2)
        ("bn.num_batches_tracked", torch.tensor(7)),
        ("scalar", torch.tensor(2.5)),
        ("empty", torch.zeros(0, 3)),
    ])


def save_bytes(obj, **options):
    buffer = io.BytesIO()
    torch.save(obj, buffer, **options)
    return buffer.getvalue()


def members(archive_bytes):
    with zipfile.ZipFile(io.BytesIO(archive_bytes)) as archive:
        return [(info.filename, archive.read(info)) for info in archive.infolist()]


def deflated(archive_bytes):
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members(archive_bytes):
            archive.writestr(name, data)
    return out.getvalue()


def zip64(archive_bytes):
    """Stored members whose central directory moves every size and offset to zip64 fields."""
    out, directory = bytearray(), bytearray()
    entries = members(archive_bytes)
    for name, data in entries:
        encoded, crc, offset = name.encode(), zipfile.crc32(data), len(out)
        out += struct.pack("<IHHHHHIIIHH", 0x04034B50, 45, 0, 0, 0, 0, crc, len(data), len(data),
                           len(encoded), 0) + encoded + data
        extra = struct.pack("<HHQQQ", 1, 24, len(data), len(data), offset)
        directory += struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 45, 45, 0, 0, 0, 0, crc,
                                 0xFFFFFFFF, 0xFFFFFFFF, len(encoded), len(extra), 0, 0, 0, 0,
                                 0xFFFFFFFF) + encoded + extra
    directory_offset, zip64_end = len(out), len(out) + len(directory)
    out += directory
    out += struct.pack("<IQHHIIQQQQ", 0x06064B50, 44, 45, 45, 0, 0, len(entries), len(entries),
                       len(directory), directory_offset)
    out += struct.pack("<IIQI", 0x07064B50, 0, zip64_end, 1)
    out += struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, 0xFFFF, 0xFFFF, 0xFFFFFFFF, 0xFFFFFFFF, 0)
    return bytes(out)


def conv_bn_state_dict():
    model = torch.nn.Sequential(collections.OrderedDict([
        ("conv", torch.nn.Conv2d(3, 4, 3)), ("bn", torch.nn.BatchNorm2d(4))]))
    with torch.no_grad():
        for index, tensor in enumerate(model.state_dict().values()):
            if tensor.is_floating_point():
                tensor.copy_(torch.arange(tensor.numel()).reshape(tensor.shape) * 0.25 + index)
    model.bn.num_batches_tracked.fill_(11)
    return collections.OrderedDict(("module." + k, v) for k, v in model.state_dict().items())


def main():
    mixed = mixed_state_dict()
    zip_bytes = save_bytes(mixed)
    variants = {
        "zip": zip_bytes,
        "legacy": save_bytes(mixed, _use_new_zipfile_serialization=False),
        "zip_protocol5": save_bytes(mixed, pickle_protocol=5),
        "legacy_protocol4": save_bytes(mixed, pickle_protocol=4,
                                       _use_new_zipfile_serialization=False),
        "deflated": deflated(zip_bytes),
        "zip64": zip64(zip_bytes),
    }
    files = {f"mixed_{name}.pth": data for name, data in variants.items()}
    files["wrapped.pth"] = save_bytes({
        "params": {"w": torch.zeros(2)}, "params_ema": {"w": torch.ones(2)}, "epoch": 3,
        "args": argparse.Namespace(lr=0.5)})
    files["module_legacy.pth"] = save_bytes(conv_bn_state_dict(),
                                            _use_new_zipfile_serialization=False)
    for name, data in files.items():
        with open(os.path.join(HERE, name), "wb") as f:
            f.write(data)
        assert torch.load(os.path.join(HERE, name)) is not None, name
        print(name, len(data))


if __name__ == "__main__":
    main()
