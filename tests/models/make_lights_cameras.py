#!/usr/bin/env python3
"""Writes, next to this script, for tests/suite/model.rs:
  lights-cameras.gltf  a glTF 2.0 file with two perspective cameras and three
                       KHR_lights_punctual lights placed by nodes, over a floor and a box;
  bare-box.glb         a binary glTF with the box alone (turned 30 degrees about +y, raised
                       by 2 and scaled by 3), no camera, no light, no material. Python 3 standard library only; run from anywhere:

  python3 tests/models/make_lights_cameras.py

What the tests check against (the file's own numbers):
  camera 0  node 2 at (0, 1.5, 6), no rotation: looks down -z; yfov 0.6 rad, aspectRatio 1.5
  camera 1  node 4, a child of node 3: node 3 translates by (4, 0, 0), node 4 by (1, 2, 0)
            and turns +90 degrees about +y, so the eye is at (5, 2, 0) looking along -x;
            yfov 0.8 rad, no aspectRatio
  light 0   point at (1, 3, 1), 6830 cd, colour (1, 0.9, 0.8): 10 W/sr in glint
  light 1   spot at (-1, 4, 0) turned -90 degrees about +x (shines down, -y), 1366 cd (2 W/sr),
            innerConeAngle 0.3, outerConeAngle 0.5
  light 2   directional, turned -60 degrees about +x: travels along (0, -sin 60, -cos 60);
            683 lux (1 W/m^2)
"""

import base64
import json
import math
import os
import struct

# A 10 x 10 floor at y = 0 and a unit box standing on it.
positions = [(-5, 0, -5), (5, 0, -5), (5, 0, 5), (-5, 0, 5)]
indices = [0, 2, 1, 0, 3, 2]
box = [(x, y, z) for x in (-0.5, 0.5) for y in (0.0, 1.0) for z in (-0.5, 0.5)]
base = len(positions)
positions += box
# Corner k = 4x + 2y + z (0/1 each). Faces, counter-clockwise seen from outside.
faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
for a, b, c, d in faces:
    indices += [base + a, base + b, base + c, base + a, base + c, base + d]

index_bytes = struct.pack("<%dH" % len(indices), *indices)
index_bytes += b"\0" * (-len(index_bytes) % 4)
position_bytes = b"".join(struct.pack("<3f", *p) for p in positions)
data = index_bytes + position_bytes


def quaternion(axis, degrees):
    half = math.radians(degrees) / 2
    s = math.sin(half)
    return [axis[0] * s, axis[1] * s, axis[2] * s, math.cos(half)]


gltf = {
    "asset": {"version": "2.0", "generator": "glint tests/models/make_lights_cameras.py"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 2, 3, 5, 6, 7]}],
    "nodes": [
        {"name": "floor", "mesh": 0},
        {"name": "unused", "translation": [0, 0, 0]},
        {"name": "front camera", "translation": [0, 1.5, 6], "camera": 0},
        {"name": "rig", "translation": [4, 0, 0], "children": [4]},
        {"name": "side camera", "translation": [1, 2, 0],
         "rotation": quaternion((0, 1, 0), 90), "camera": 1},
        {"name": "point", "translation": [1, 3, 1],
         "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "spot", "translation": [-1, 4, 0], "rotation": quaternion((1, 0, 0), -90),
         "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"name": "sun", "rotation": quaternion((1, 0, 0), -60),
         "extensions": {"KHR_lights_punctual": {"light": 2}}},
    ],
    "cameras": [
        {"type": "perspective",
         "perspective": {"yfov": 0.6, "aspectRatio": 1.5, "znear": 0.1, "zfar": 100}},
        {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05}},
    ],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1.0, 0.9, 0.8], "intensity": 6830},
        {"type": "spot", "intensity": 1366,
         "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}},
        {"type": "directional", "intensity": 683},
    ]}},
    "materials": [{"name": "grey", "pbrMetallicRoughness": {
        "baseColorFactor": [0.7, 0.7, 0.7, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0, "material": 0}]}],
    "buffers": [{"byteLength": len(data),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": len(indices) * 2, "target": 34963},
        {"buffer": 0, "byteOffset": len(index_bytes), "byteLength": len(position_bytes),
         "target": 34962},
    ],
    "accessors": [
        {"bufferView": 0, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        {"bufferView": 1, "componentType": 5126, "count": len(positions), "type": "VEC3",
         "min": [-5, 0, -5], "max": [5, 1, 5]},
    ],
}

# The floor node places the floor and the box (one mesh); node 1 is an empty node.
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "lights-cameras.gltf")
with open(out, "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
print("wrote", out)

# bare-box.glb: the box's 36 indices and 8 corners in one binary chunk.
box_indices = [i - base for i in indices[6:]]
box_index_bytes = struct.pack("<%dH" % len(box_indices), *box_indices)
box_index_bytes += b"\0" * (-len(box_index_bytes) % 4)
box_position_bytes = b"".join(struct.pack("<3f", *p) for p in box)
blob = box_index_bytes + box_position_bytes
bare = {
    "asset": {"version": "2.0", "generator": "glint tests/models/make_lights_cameras.py"},
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0, "translation": [0, 2, 0], "scale": [3, 3, 3],
               "rotation": quaternion((0, 1, 0), 30)}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0}]}],
    "buffers": [{"byteLength": len(blob)}],
    "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": len(box_indices) * 2},
        {"buffer": 0, "byteOffset": len(box_index_bytes), "byteLength": len(box_position_bytes)},
    ],
    "accessors": [
        {"bufferView": 0, "componentType": 5123, "count": len(box_indices), "type": "SCALAR"},
        {"bufferView": 1, "componentType": 5126, "count": len(box), "type": "VEC3",
         "min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5]},
    ],
}
text = json.dumps(bare).encode()
text += b" " * (-len(text) % 4)
chunks = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(blob), b"BIN\0") + blob
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bare-box.glb")
with open(out, "wb") as f:
    f.write(struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks)
print("wrote", out)
