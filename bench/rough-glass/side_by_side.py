"""Cycles 4.5 beside glint before and after light sampling through rough glass (issue 31):
the Blender-built roughglass.glb (three clear spheres of roughness 0.3, 0.6 and 1 under the
esplanade map, 80x48, 32 bounces) as three panels, top to bottom, each scaled 3x, exposure 1,
sRGB-encoded and clipped. Prints each sphere's mean over the pixels its mask covers fully.

    python3 side_by_side.py masks.npy OUT.png cycles.exr glint-before.exr glint-after.exr

Needs `pip install OpenEXR numpy`."""

import os
import struct
import sys
import zlib

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from exr import read_rgb  # noqa: E402


def srgb(linear):
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def write_png(path, rgb8):
    height, width, _ = rgb8.shape
    rows = b"".join(b"\0" + rgb8[y].tobytes() for y in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))


def main():
    masks, out, *renders = sys.argv[1:]
    masks = np.load(masks) >= 1
    panels = []
    for path in renders:
        rgb = read_rgb(path)
        means = [rgb[m].mean(axis=0).round(4).tolist() for m in masks]
        print(path, "sphere means (roughness 0.3, 0.6, 1):", means)
        panels.append(np.repeat(np.repeat(srgb(rgb), 3, axis=0), 3, axis=1))
        panels.append(np.ones((4, panels[-1].shape[1], 3)))
    image = np.concatenate(panels[:-1], axis=0)
    write_png(out, (image * 255 + 0.5).astype(np.uint8))


if __name__ == "__main__":
    main()
