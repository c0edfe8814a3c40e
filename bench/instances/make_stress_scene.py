#!/usr/bin/env python3
"""Writes the two-level structure's stress scene into OUT (default /tmp/glint-instances-stress):
the Cornell box (scenes/cornell.toml) with 10^4 instances of the 10^6-triangle stress mesh
(`glint stress-mesh OUT/mesh.ply`, see docs/src/reference/meshes.md) in a 100 x 100 grid on
its floor, placed by one [[meshes]] entry's `instances` (stress.toml): 10^10 placed triangles,
10^6 stored."""
import pathlib
import sys

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/glint-instances-stress")
out.mkdir(parents=True, exist_ok=True)
cornell = (pathlib.Path(__file__).resolve().parents[2] / "scenes" / "cornell.toml").read_text()
N = 100
scene = cornell + '\n[[meshes]]\nfile = "mesh.ply"\nmaterial = "white"\nscale = 2.0\ninstances = [\n'
scene += "".join(
    f"  {{ translate = [{27.5 + 5.0 * i}, 2.5, {27.5 + 5.0 * j}], rotate = [0.0, {(7 * i + 13 * j) % 360}.0, 0.0] }},\n"
    for i in range(N)
    for j in range(N)
) + "]\n"
(out / "stress.toml").write_text(scene)
print(out)
