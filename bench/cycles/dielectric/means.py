# Means of (R + G + B)/3 per object of a 3x3 grid (make_scene.py) or a row of 3 cards
# (make_card.py, --row), over the pixels Cycles covers fully (its alpha > 0.999: render with
# film transparent, as cycles_render.py does), in the Cycles image and in each other image, and
# their ratios to Cycles'.
# Usage: python3 means.py [--row] CYCLES.exr OTHER.exr ...   (needs numpy and OpenEXR)
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "lib"))
from exr import read_rgba as read  # noqa: E402


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
