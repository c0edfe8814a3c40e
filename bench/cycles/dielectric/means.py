# Means of (R + G + B)/3 per object of a 3x3 grid (make_scene.py) or a row of 3 cards
# (make_card.py, --row), over the pixels Cycles covers fully (its alpha > 0.999: render with
# film transparent, as cycles_render.py does), in the Cycles image and in each other image, and
# their ratios to Cycles'.
# Usage: python3 means.py [--row] CYCLES.exr OTHER.exr ...   (needs numpy and OpenEXR)
import sys

import numpy as np
import OpenEXR


def read(path):
    ch = OpenEXR.File(path).channels()
    for name in ("RGBA", "RGB"):
        if name in ch:
            px = np.asarray(ch[name].pixels, dtype=np.float64)
            return px[..., :3], (px[..., 3] if px.shape[-1] == 4 else None)
    get = lambda c: np.asarray(ch[c].pixels, dtype=np.float64) if c in ch else None
    return np.stack([get(c) for c in "RGB"], -1), get("A")


args = sys.argv[1:]
row = "--row" in args
args = [a for a in args if a != "--row"]
rgb0, alpha = read(args[0])
covered = alpha > 0.999
h, w = covered.shape
rows = 1 if row else 3


def cells(rgb):
    out = np.zeros((rows, 3))
    for r in range(rows):
        for c in range(3):
            m = np.zeros_like(covered)
            m[r * h // rows:(r + 1) * h // rows, c * w // 3:(c + 1) * w // 3] = True
            out[r, c] = rgb[m & covered].mean()
    return out


np.set_printoptions(precision=4, suppress=True)
m0 = cells(rgb0)
print(args[0])
print(m0)
for path in args[1:]:
    m = cells(read(path)[0])
    print(path)
    print(m)
    print("ratio to", args[0])
    print(m / m0)
