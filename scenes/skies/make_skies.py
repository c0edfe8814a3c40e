#!/usr/bin/env python3
"""Generates the environment maps shipped in scenes/skies/ (Python 3 standard library only):

  sky.hdr     256x128: a clear sky, brighter towards the horizon, over dark ground, with a small,
              very bright sun (radius 1.5 degrees, 35 degrees up): most of the light in a few texels,
              the case environment importance sampling exists for.
  studio.hdr  128x64: a soft studio light box: a large soft box overhead in front, two strip
              lights at the sides, dim grey walls and floor.

Equirectangular, top row first, in glint's (and Mitsuba 3's) convention: texel (x, y) of a WxH
map looks along the direction with u = (x + 0.5)/W, v = (y + 0.5)/H,
  phi = 2 pi u, theta = pi v, d = (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi)),
so u = 0 looks along -z and u = 0.25 along +x; +y is up. Run from anywhere:
  python3 scenes/skies/make_skies.py
"""

import math
import os


def direction(x, y, width, height):
    phi = 2.0 * math.pi * (x + 0.5) / width
    theta = math.pi * (y + 0.5) / height
    return (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))


def unit(elevation_deg, azimuth_deg):
    """Direction with the given elevation above the horizon, azimuth from -z towards +x."""
    e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
    return (math.cos(e) * math.sin(a), math.sin(e), -math.cos(e) * math.cos(a))


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def sky(d):
    sun = unit(35.0, 60.0)
    if dot(d, sun) >= math.cos(math.radians(1.5)):
        return (2500.0, 2350.0, 2150.0)
    if d[1] < 0.0:
        return (0.12, 0.10, 0.08)
    # Blue at the zenith, pale at the horizon.
    t = 1.0 - d[1]
    zenith, horizon = (0.20, 0.40, 0.90), (0.80, 0.85, 0.95)
    return tuple(z + (h - z) * t ** 3 for z, h in zip(zenith, horizon))


def studio(d):
    # A soft box overhead, tilted towards the front (-z), and two vertical strips at the sides.
    soft_box = unit(60.0, 0.0)
    if dot(d, soft_box) >= math.cos(math.radians(25.0)):
        return (6.0, 6.0, 6.0)
    for azimuth in (100.0, -100.0):
        s = unit(0.0, azimuth)
        horizontal = math.hypot(d[0], d[2])
        if horizontal > 0.0 and abs(d[1]) < 0.6:
            cos_azimuth = (d[0] * s[0] + d[2] * s[2]) / horizontal
            if cos_azimuth >= math.cos(math.radians(8.0)):
                return (3.0, 3.0, 3.0)
    return (0.04, 0.04, 0.04) if d[1] >= 0.0 else (0.02, 0.02, 0.02)


def rgbe(c):
    peak = max(c)
    if peak < 1e-32:
        return (0, 0, 0, 0)
    mantissa, exponent = math.frexp(peak)
    scale = mantissa * 256.0 / peak
    return tuple(int(v * scale) for v in c) + (exponent + 128,)


def rle_channel(values):
    """Radiance's adaptive run-length encoding of one channel of one scanline."""
    out = bytearray()
    i, n = 0, len(values)
    while i < n:
        run = 1
        while i + run < n and run < 127 and values[i + run] == values[i]:
            run += 1
        if run >= 3:
            out += bytes((128 + run, values[i]))
            i += run
            continue
        start = i
        while i < n and i - start < 128:
            if i + 2 < n and values[i] == values[i + 1] == values[i + 2]:
                break
            i += 1
        out += bytes((i - start,)) + bytes(values[start:i])
    return out


def write_hdr(path, width, height, radiance):
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(b"-Y %d +X %d\n" % (height, width))
        for y in range(height):
            row = [rgbe(radiance(direction(x, y, width, height))) for x in range(width)]
            f.write(bytes((2, 2, width >> 8, width & 255)))
            for channel in range(4):
                f.write(rle_channel([p[channel] for p in row]))


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    write_hdr(os.path.join(here, "sky.hdr"), 256, 128, sky)
    write_hdr(os.path.join(here, "studio.hdr"), 128, 64, studio)
