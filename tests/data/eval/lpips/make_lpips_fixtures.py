#!/usr/bin/python3
"""Writes the fixtures of tests/eval/lpips_test.cpp by running the official LPIPS v0.1 code.

Run with a Python that has torch, numpy and Pillow (the system /usr/bin/python3 here):
    /usr/bin/python3 tests/data/eval/lpips/make_lpips_fixtures.py \
        /path/to/PerceptualSimilarity [/path/to/shared/data]

The first argument is a checkout of github.com/richzhang/PerceptualSimilarity (its lpips/
package is imported unmodified); the linear heads come from <shared>/weights/lpips/v0.1.

The ImageNet backbones (10 MB AlexNet, 59 MB VGG16 features) are too big for the repository and
not available offline, so the official model runs on stand-in backbone weights that the test
recomputes bit for bit (hashed_weights in tests/eval/lpips_test.cpp): element i of the
checkpoint entry features.<L>.weight (or .bias) is

    h = lowbias32(i XOR (seed * 0x9E3779B9 mod 2^32)),  seed = 2 L (weight) or 2 L + 1 (bias)
    value = (2 * (h >> 8) / 2^24 - 1) * bound           (float32 arithmetic)

with lowbias32(x) = x ^= x >> 16; x *= 0x7feb352d; x ^= x >> 15; x *= 0x846ca68b; x ^= x >> 16
(mod 2^32), bound = sqrt(6 / fan_in) for weights (He's uniform range, which keeps every layer's
share of the distance of the same order) and 0.1 for biases.

Written files:
    pair<k>_a.png, pair<k>_b.png   RGB image pairs of different sizes
    expected.json                  {"alex": [d0, d1, d2], "vgg": [...]}: the official
                                   LPIPS(net, version="0.1")(a, b, normalize=True) per pair
"""
import json
import math
import os
import sys
import types

import numpy as np
import torch
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", "..", "..", ".."))
DEFAULT_SHARED = os.path.join(os.path.dirname(REPO), "shared", "data")
PAIR_SIZES = [(64, 64), (72, 48), (50, 66)]  # (width, height)


# torchvision's feature stacks, layer for layer (indices are the checkpoint names).
def alexnet_features():
    nn = torch.nn
    return nn.Sequential(
        nn.Conv2d(3, 64, kernel_size=11, stride=4, padding=2), nn.ReLU(inplace=True),
        nn.MaxPool2d(kernel_size=3, stride=2),
        nn.Conv2d(64, 192, kernel_size=5, padding=2), nn.ReLU(inplace=True),
        nn.MaxPool2d(kernel_size=3, stride=2),
        nn.Conv2d(192, 384, kernel_size=3, padding=1), nn.ReLU(inplace=True),
        nn.Conv2d(384, 256, kernel_size=3, padding=1), nn.ReLU(inplace=True),
        nn.Conv2d(256, 256, kernel_size=3, padding=1), nn.ReLU(inplace=True),
        nn.MaxPool2d(kernel_size=3, stride=2))


def vgg16_features():
    layers, channels = [], 3
    for v in [64, 64, "M", 128, 128, "M", 256, 256, 256, "M", 512, 512, 512, "M",
              512, 512, 512, "M"]:
        if v == "M":
            layers.append(torch.nn.MaxPool2d(kernel_size=2, stride=2))
        else:
            layers += [torch.nn.Conv2d(channels, v, kernel_size=3, padding=1),
                       torch.nn.ReLU(inplace=True)]
            channels = v
    return torch.nn.Sequential(*layers)


def install_stand_ins():
    """torchvision is not installed here: the official code gets the stacks above. scipy and tqdm
    are imported by lpips.trainer at import time but never used on the LPIPS forward path."""
    built = {}

    def model(name, make):
        def factory(pretrained=False, **_):
            built[name] = types.SimpleNamespace(features=make())
            return built[name]
        return factory

    tv = types.ModuleType("torchvision")
    tv.models = types.SimpleNamespace(alexnet=model("alex", alexnet_features),
                                      vgg16=model("vgg", vgg16_features))
    scipy = types.ModuleType("scipy")
    scipy.ndimage = types.ModuleType("scipy.ndimage")
    scipy.ndimage.zoom = None
    tqdm = types.ModuleType("tqdm")
    tqdm.tqdm = None
    sys.modules.update({"torchvision": tv, "scipy": scipy, "scipy.ndimage": scipy.ndimage,
                        "tqdm": tqdm})
    return built


MASK = 0xFFFFFFFF


def lowbias32(x):
    x ^= x >> 16
    x = (x * 0x7FEB352D) & MASK
    x ^= x >> 15
    x = (x * 0x846CA68B) & MASK
    return x ^ (x >> 16)


def hashed_weights(shape, seed, bound):
    index = np.arange(int(np.prod(shape)), dtype=np.uint64)
    h = lowbias32(index ^ np.uint64((seed * 0x9E3779B9) & MASK))
    unit = (h >> np.uint64(8)).astype(np.float32) * np.float32(2.0**-24)
    values = (np.float32(2) * unit - np.float32(1)) * np.float32(bound)
    return torch.from_numpy(values.reshape(tuple(shape)))


def stand_in_backbone(features):
    state = {}
    for name, param in features.state_dict().items():
        layer, kind = name.split(".")
        if kind == "weight":
            bound, seed = math.sqrt(6 / param[0].numel()), 2 * int(layer)
        else:
            bound, seed = 0.1, 2 * int(layer) + 1
        state[name] = hashed_weights(param.shape, seed, bound)
    return state


def pattern(rng, width, height):
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    phase = rng.uniform(0, 2 * np.pi, size=3)
    freq = rng.uniform(0.05, 0.3, size=3)
    return np.stack([0.5 + 0.4 * np.sin(freq[c] * x + phase[c]) * np.cos(freq[2 - c] * y)
                     for c in range(3)], axis=-1)


def make_pairs(rng):
    """A pattern against a noisy copy, a shifted copy and an unrelated pattern."""
    (w0, h0), (w1, h1), (w2, h2) = PAIR_SIZES
    a0, a1 = pattern(rng, w0, h0), pattern(rng, w1, h1)
    to8 = lambda img: Image.fromarray(np.clip(np.rint(img * 255), 0, 255).astype(np.uint8))
    return [(to8(a0), to8(a0 + rng.normal(0, 0.05, size=a0.shape))),
            (to8(a1), to8(np.roll(a1, shift=2, axis=1))),
            (to8(pattern(rng, w2, h2)), to8(pattern(rng, w2, h2)))]


def load_rgb(path):
    pixels = np.asarray(Image.open(path).convert("RGB"), dtype=np.float32) / np.float32(255)
    return torch.from_numpy(pixels).permute(2, 0, 1)[None].contiguous()


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    official, shared = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else DEFAULT_SHARED
    built = install_stand_ins()
    sys.path.insert(0, official)
    import lpips

    rng = np.random.default_rng(20240521)
    pairs = []
    for k, images in enumerate(make_pairs(rng)):
        for side, image in zip("ab", images):
            image.save(os.path.join(HERE, f"pair{k}_{side}.png"))
        pairs.append([load_rgb(os.path.join(HERE, f"pair{k}_{s}.png")) for s in "ab"])

    expected = {}
    for net in ["alex", "vgg"]:
        heads = os.path.join(shared, "weights", "lpips", "v0.1", f"{net}.pth")
        model = lpips.LPIPS(net=net, version="0.1", model_path=heads, verbose=False)
        assert torch.equal(model.lin0.model[1].weight,
                           torch.load(heads, map_location="cpu")["lin0.model.1.weight"])
        features = built[net].features
        features.load_state_dict(stand_in_backbone(features))
        with torch.no_grad():
            expected[net] = [float(model(a, b, normalize=True)) for a, b in pairs]
    with open(os.path.join(HERE, "expected.json"), "w") as f:
        json.dump(expected, f, indent=2)
        f.write("\n")
    print(json.dumps(expected))


if __name__ == "__main__":
    main()
