#!/usr/bin/env python3
"""Helpers for media.sh, on linear EXRs (read and written with Mitsuba's Bitmap).

    channels.py compose OUT.exr R.exr G.exr B.exr
        OUT takes its red from R's red, its green from G's green and its blue from B's blue
        (the per-channel reference of a medium whose σt differs per channel: compare.py
        --medium-channel renders each channel with a grey medium).

    channels.py test NAME A.exr VA.exr B.exr VB.exr
        One line: per channel, the pass rate of the per-pixel Z-test (|z| <= 2.576, as
        `glint compare`) and the z of the image means, for A (variance VA) against B (VB).
"""

import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def load(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def main():
    if sys.argv[1] == "compose":
        out, *parts = sys.argv[2:]
        image = np.stack([load(p)[..., c] for c, p in enumerate(parts)], axis=-1)
        mi.Bitmap(image.astype(np.float32)).write(out)
    elif sys.argv[1] == "test":
        name, a, va, b, vb = sys.argv[2], *(load(p) for p in sys.argv[3:7])
        variance = va + vb
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(variance > 0, (a - b) / np.sqrt(variance), 0.0)
        n = a.shape[0] * a.shape[1]
        fields = []
        for c in range(3):
            z_mean = (a[..., c].mean() - b[..., c].mean()) / (np.sqrt(variance[..., c].sum()) / n)
            fields.append(f"{100 * np.mean(np.abs(z[..., c]) <= 2.576):6.2f}% {z_mean:+6.2f}")
        print(f"  {name:<20} per channel (R, G, B), pass and z of the mean: " + "   ".join(fields))
    else:
        sys.exit(f"channels.py: unknown command {sys.argv[1]!r}")


if __name__ == "__main__":
    main()
