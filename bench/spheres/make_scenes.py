#!/usr/bin/env python3
"""Writes the sphere-count benchmark's scenes into OUT (default /tmp/glint-spheres): the Cornell
box (scenes/cornell.toml) with its two spheres replaced by N small white spheres (radius 8) at
random, overlapping places in the lower half of the box, for N = 10, 10^3 and 10^5
(spheres-N.toml). Issue 22 asks that the box with 10^5 keep >= 20% of the paths/s of the box
with 10. The places come from a fixed seed, so every run renders the same scenes."""
import pathlib
import random
import sys

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/glint-spheres")
out.mkdir(parents=True, exist_ok=True)
cornell = (pathlib.Path(__file__).resolve().parents[2] / "scenes" / "cornell.toml").read_text()
# The box without its own two spheres: everything before the first [[spheres]].
box = cornell[: cornell.index("[[spheres]]")]
for n in (10, 1000, 100000):
    rng = random.Random(22)
    spheres = "".join(
        f"[[spheres]]\ncenter = [{rng.uniform(50, 505):.3f}, {rng.uniform(8, 300):.3f}, "
        f"{rng.uniform(50, 505):.3f}]\nradius = 8.0\nmaterial = \"white\"\n\n"
        for _ in range(n)
    )
    (out / f"spheres-{n}.toml").write_text(box + spheres)
print(out)
