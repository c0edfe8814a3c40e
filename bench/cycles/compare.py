# Side by side of two linear EXRs (glint left, Cycles right) as sRGB PNG (clamped, no tone
# curve), with the image means, the means outside the 32x32 block of the visor's brightest
# highlights (rows 64-96, columns 112-144 at 256x256: a few pixels of a lamp's reflection
# reach hundreds there and dominate both images' means), and the means of given regions.
# Usage: compare.py GLINT.exr CYCLES.exr SIDE.png [x0,y0,x1,y1 ...]
import os, sys, numpy as np
import imageio.v3 as iio
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from exr import read_rgb as read
def srgb(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
a, b = read(sys.argv[1]), read(sys.argv[2])
print("glint mean", a.mean(axis=(0, 1)), "cycles mean", b.mean(axis=(0, 1)))
print("relative difference of means", (a.mean(axis=(0, 1)) - b.mean(axis=(0, 1))) / b.mean(axis=(0, 1)))
print("mean |difference| per pixel / mean", np.abs(a - b).mean() / b.mean())
if a.shape == (256, 256, 3):
    mask = np.ones(a.shape[:2], bool)
    mask[64:96, 112:144] = False
    ma, mb = a[mask].mean(axis=0), b[mask].mean(axis=0)
    print("outside the highlight block: glint", ma.round(4), "cycles", mb.round(4), "ratio", (ma / mb).round(4))
out = np.concatenate([srgb(a), np.ones((a.shape[0], 4, 3)), srgb(b)], axis=1)
iio.imwrite(sys.argv[3], (out * 255 + 0.5).astype(np.uint8))
if len(sys.argv) > 4:
    # Regions given as x0,y0,x1,y1 (pixels): their means in both images.
    for region in sys.argv[4:]:
        x0, y0, x1, y1 = map(int, region.split(","))
        ma, mb = a[y0:y1, x0:x1].mean(axis=(0, 1)), b[y0:y1, x0:x1].mean(axis=(0, 1))
        print(region, "glint", ma.round(4), "cycles", mb.round(4), "ratio", (ma / mb).round(3))
