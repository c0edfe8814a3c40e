#!/usr/bin/env python3
"""Writes a glTF file that places one mesh 10^3 times into OUT (default
/tmp/glint-instances-gltf): reuse.gltf, a UV sphere of 2,000 triangles (positions, normals,
u32 indices) used by 1,000 nodes in a 10 x 10 x 10 grid, and reuse.toml, the Cornell box
(scenes/cornell.toml) with the grid in it (2*10^6 placed triangles, 2*10^3 unique). glTF
reuse is stored once (docs/src/reference/meshes.md, "Instances"); before, it was flattened."""
import base64
import json
import math
import pathlib
import struct
import sys

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/glint-instances-gltf")
out.mkdir(parents=True, exist_ok=True)
SEGMENTS, RINGS = 50, 21  # 50 * 2 * (21 - 1) = 2000 triangles, the poles' rings included
positions, normals, indices = [], [], []
for r in range(RINGS + 1):
    theta = math.pi * r / RINGS
    for s in range(SEGMENTS):
        phi = 2 * math.pi * s / SEGMENTS
        n = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
        positions += n
        normals += n
for r in range(RINGS):
    for s in range(SEGMENTS):
        a, b = r * SEGMENTS + s, r * SEGMENTS + (s + 1) % SEGMENTS
        c, d = a + SEGMENTS, b + SEGMENTS
        if r > 0:
            indices += [a, b, c]
        if r < RINGS - 1:
            indices += [b, d, c]
data = struct.pack(f"<{len(positions)}f", *positions) + struct.pack(f"<{len(normals)}f", *normals)
data += struct.pack(f"<{len(indices)}I", *indices)
count = len(positions) // 3
nodes = [{"children": list(range(1, 1001))}]
nodes += [
    {"mesh": 0, "translation": [4.0 * (i % 10), 4.0 * (i // 10 % 10), 4.0 * (i // 100)]}
    for i in range(1000)
]
gltf = {
    "asset": {"version": "2.0"},
    "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                 + base64.b64encode(data).decode()}],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 12 * count},
        {"buffer": 0, "byteOffset": 12 * count, "byteLength": 12 * count},
        {"buffer": 0, "byteOffset": 24 * count, "byteLength": 4 * len(indices)},
    ],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3"},
        {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5125, "count": len(indices), "type": "SCALAR"},
    ],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
    "nodes": nodes,
    "scenes": [{"nodes": [0]}],
    "scene": 0,
}
(out / "reuse.gltf").write_text(json.dumps(gltf))
cornell = (pathlib.Path(__file__).resolve().parents[2] / "scenes" / "cornell.toml").read_text()
scene = cornell + (
    '\n[[meshes]]\nfile = "reuse.gltf"\nmaterial = "white"\nscale = 8.0\n'
    "translate = [138.0, 40.0, 138.0]\n"
)
(out / "reuse.toml").write_text(scene)
print(out, len(indices) // 3, "triangles,", len(nodes) - 1, "nodes")
