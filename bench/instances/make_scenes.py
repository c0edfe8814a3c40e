#!/usr/bin/env python3
"""Writes the instancing benchmark's scenes into OUT (default /tmp/glint-instances): the Cornell
box (scenes/cornell.toml) with a 100 x 100 grid of small bumpy spheres on its floor, placed
once by one [[meshes]] entry's `instances` (instanced.toml) and once by 10^4 [[meshes]]
entries (flattened.toml). The mesh is written by `glint stress-mesh` (see
docs/src/reference/meshes.md)."""
import pathlib
import sys

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/glint-instances")
out.mkdir(parents=True, exist_ok=True)
cornell = (pathlib.Path(__file__).resolve().parents[2] / "scenes" / "cornell.toml").read_text()
N = 100
placements = [
    f"translate = [{27.5 + 5.0 * i}, 2.5, {27.5 + 5.0 * j}]" for i in range(N) for j in range(N)
]
instanced = cornell + '\n[[meshes]]\nfile = "mesh.ply"\nmaterial = "white"\nscale = 2.0\ninstances = [\n'
instanced += "".join(f"  {{ {p} }},\n" for p in placements) + "]\n"
flattened = cornell + "".join(
    f'\n[[meshes]]\nfile = "mesh.ply"\nmaterial = "white"\nscale = 2.0\n{p}\n' for p in placements
)
(out / "instanced.toml").write_text(instanced)
(out / "flattened.toml").write_text(flattened)
print(out)
