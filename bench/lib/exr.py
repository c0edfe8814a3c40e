"""What the benchmark scripts share: a linear EXR as numpy arrays (glint's, Cycles' and
Mitsuba's, packed RGB(A) or split channels, with or without a layer prefix), and glint
compare's relative MSE. Needs `pip install OpenEXR numpy` (OpenEXR >= 3.3 for `OpenEXR.File`).

Scripts elsewhere in bench/ import it with
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
"""

import numpy as np
import OpenEXR


def read_rgba(path):
    """The image's RGB, height x width x 3 in float64, and its alpha (None without one)."""
    channels = OpenEXR.File(path).channels()
    for packed in ("RGBA", "RGB"):
        if packed in channels:
            px = np.asarray(channels[packed].pixels, dtype=np.float64)
            return px[..., :3], (px[..., 3] if px.shape[-1] == 4 else None)

    def channel(name):
        for key, c in channels.items():
            if key == name or key.endswith("." + name):
                return np.asarray(c.pixels, dtype=np.float64)
        return None

    return np.stack([channel(c) for c in "RGB"], -1), channel("A")


def read_rgb(path):
    """The image's RGB, height x width x 3 in float64."""
    return read_rgba(path)[0]


def rel_mse(image, ref, box=None):
    """glint compare's relative MSE: the mean of (image - ref)^2 / (ref^2 + 0.01), over the
    image or over box = (x0, y0, x1, y1)."""
    if box:
        x0, y0, x1, y1 = box
        image, ref = image[y0:y1, x0:x1], ref[y0:y1, x0:x1]
    return float(np.mean((image - ref) ** 2 / (ref ** 2 + 0.01)))
