#!/usr/bin/env python3
"""Writes the textures of scenes/cornell-textured.toml (Python 3 standard library only).

  grid.png       256x128 sRGB colour: hue across u, eight light/dark bands up v, dark lines
                 every 1/8 in u and v, and a white cap on the top rows (v near 1), so the
                 orientation of u and v can be read off a render.
  roughness.png  64x64 8-bit greyscale, read linearly: horizontal stripes of roughness 0.08
                 and 0.55 (four of each up v).

Run from anywhere: python3 scenes/textures/make_textures.py
"""

import colorsys
import os
import struct
import zlib


def write_png(path, width, height, rows, channels):
    """An 8-bit PNG (colour type 2 for RGB, 0 for grey), rows top first, each a bytes object."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    colour_type = {1: 0, 3: 2}[channels]
    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    raw = b"".join(b"\x00" + row for row in rows)  # filter type 0 (None) on every row
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", header))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def grid(width=256, height=128):
    rows = []
    for y in range(height):
        v = 1.0 - (y + 0.5) / height  # v up: the file's top row is v near 1
        row = bytearray()
        for x in range(width):
            u = (x + 0.5) / width
            if v > 0.94:
                rgb = (1.0, 1.0, 1.0)
            elif (x % (width // 8)) == 0 or (y % (height // 8)) == 0:
                rgb = (0.08, 0.08, 0.08)
            else:
                light = 0.75 if int(v * 8) % 2 == 0 else 0.45
                rgb = colorsys.hls_to_rgb(u, light, 0.8)
            row += bytes(round(255 * c) for c in rgb)
        rows.append(bytes(row))
    return width, height, rows


def roughness(size=64):
    rows = []
    for y in range(size):
        value = 0.08 if (y * 8 // size) % 2 == 0 else 0.55
        rows.append(bytes([round(255 * value)] * size))
    return size, size, rows


def main():
    folder = os.path.dirname(os.path.abspath(__file__))
    w, h, rows = grid()
    write_png(os.path.join(folder, "grid.png"), w, h, rows, 3)
    w, h, rows = roughness()
    write_png(os.path.join(folder, "roughness.png"), w, h, rows, 1)


if __name__ == "__main__":
    main()
