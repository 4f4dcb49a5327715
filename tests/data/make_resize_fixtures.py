#!/usr/bin/python3
"""Writes the fixtures of tests/io/resize_test.cpp: small synthetic images and their resizes by
Pillow's Image.resize(size, Image.BICUBIC), the reference that resize_bicubic must reproduce.

Run with a Python that has Pillow (the system /usr/bin/python3 here):
    /usr/bin/python3 tests/data/make_resize_fixtures.py [/path/to/shared/data]

File names carry the sizes, so the test needs no manifest:
    resize/<mode>_<W>x<H>.png              a source image
    resize/<mode>_<W>x<H>_to_<w>x<h>.png   Pillow's resize of that source to w x h
    resize/lego_r_0_to_<w>x<h>.png         Pillow's resize of nerf_synthetic/lego/test/r_0.png
"""
import os
import random
import sys

from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
OUT_DIR = os.path.join(HERE, "resize")
DEFAULT_SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "..", "shared", "data"))

MODES = ("L", "LA", "RGB", "RGBA")
# Per source size: halvings, quarterings and eighths (exact for 64x48, rounded for 37x29),
# non-integer ratios both ways, passes skipped when one side keeps its size, and x4 upscaling.
TARGETS = {
    (37, 29): [(18, 14), (9, 7), (4, 3), (23, 17), (50, 40), (37, 11), (13, 29), (1, 1)],
    (64, 48): [(32, 24), (16, 12), (8, 6), (27, 35)],
    (12, 10): [(48, 40), (31, 10)],
}
LEGO_TARGETS = [(200, 200), (100, 100)]


def channel_value(rng, x, y, c, w, h):
    """A gradient with noise and a hard-edged block, so resizes both stay smooth and overshoot."""
    base = (x * 255 // max(w - 1, 1) + y * 97 // max(h - 1, 1) + c * 60) % 256
    if w // 4 <= x < w // 2 and h // 3 <= y < 2 * h // 3:
        base = 255 if (c % 2 == 0) else 0
    return max(0, min(255, base + rng.randint(-40, 40)))


def alpha_value(rng, x, y, w, h):
    """Opaque, fully transparent and partially transparent regions, with sharp borders between."""
    if x < w // 3:
        return 255
    if y < h // 3:
        return 0
    return rng.choice((0, 255, rng.randint(1, 254)))


def synthetic_image(mode, w, h, seed):
    rng = random.Random(seed)
    colors = 1 if mode in ("L", "LA") else 3
    has_alpha = mode in ("LA", "RGBA")
    pixels = []
    for y in range(h):
        for x in range(w):
            px = [channel_value(rng, x, y, c, w, h) for c in range(colors)]
            if has_alpha:
                px.append(alpha_value(rng, x, y, w, h))
            pixels.append(tuple(px) if len(px) > 1 else px[0])
    image = Image.new(mode, (w, h))
    image.putdata(pixels)
    return image


def write_synthetic_fixtures():
    for seed, mode in enumerate(MODES):
        for (w, h), targets in TARGETS.items():
            source = synthetic_image(mode, w, h, seed * 100 + w)
            stem = f"{mode}_{w}x{h}"
            source.save(os.path.join(OUT_DIR, stem + ".png"))
            for tw, th in targets:
                resized = source.resize((tw, th), Image.BICUBIC)
                resized.save(os.path.join(OUT_DIR, f"{stem}_to_{tw}x{th}.png"))


def write_lego_fixtures(shared):
    path = os.path.join(shared, "nerf_synthetic", "lego", "test", "r_0.png")
    if not os.path.exists(path):
        sys.exit(f"{path}: not found (pass the shared data folder as the first argument)")
    lego = Image.open(path)
    lego.load()
    for tw, th in LEGO_TARGETS:
        lego.resize((tw, th), Image.BICUBIC).save(
            os.path.join(OUT_DIR, f"lego_r_0_to_{tw}x{th}.png"), optimize=True)


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    write_synthetic_fixtures()
    write_lego_fixtures(sys.argv[1] if len(sys.argv) > 1 else DEFAULT_SHARED)


if __name__ == "__main__":
    main()
