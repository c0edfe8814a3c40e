#!/usr/bin/env python3
"""Writes dwab.exr and dwab-decoded.exr, the DWAB test map of tests/environment.rs.

dwab.exr is a 32x16 half-float RGB image of dark noise, DWAB-compressed by OpenEXR itself
(the reference implementation, as Blender writes it). DWAB is lossy: decoded, 94 channel
values come out slightly negative (the most negative -2.57e-5), as in Blender's own
forest.exr. dwab-decoded.exr is what OpenEXR decodes from dwab.exr, stored losslessly
(32-bit float, ZIP), so the test can check glint's decoder (the exr crate) against it.

Regenerate (from this folder):
    python3 -m venv /tmp/exr && /tmp/exr/bin/pip install openexr numpy
    /tmp/exr/bin/python make_dwab.py
Written with the openexr package 3.5.3 (OpenEXR 3.5) and numpy 2; another OpenEXR version may
compress differently, and the counts in the test would then need updating.
"""

import numpy as np
import OpenEXR

rng = np.random.default_rng(1)
texels = (rng.random((16, 32, 3)) ** 6 * 0.02).astype(np.float16)
header = {"compression": OpenEXR.DWAB_COMPRESSION, "type": OpenEXR.scanlineimage}
OpenEXR.File(header, {"RGB": texels}).write("dwab.exr")

decoded = OpenEXR.File("dwab.exr").channels()["RGB"].pixels.astype(np.float32)
header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
OpenEXR.File(header, {"RGB": decoded}).write("dwab-decoded.exr")
negative = decoded[decoded < 0]
print(f"{negative.size} negative values, the most negative {negative.min():.6g}")
