"""Writes scenes/smoke.vdb, the smoke plume scenes/smoke.toml renders: a procedural plume
(a rising column that widens, thins and curls, with fractal value noise for the puffs) in an
OpenVDB file of one float grid, "density", saved as half floats with zlib compression as
OpenVDB 11 writes them. Python's standard library only:

    python3 scenes/tools/make_smoke.py [--size 48] [--out scenes/smoke.vdb] [--blosc] [--active-mask]

The file (a few hundred KB) is not kept in the repository; this script is. A real Blender
smoke bake is scenes/tools/bake_blender_smoke.py's (it needs Blender's executable: the `bpy`
module's headless bake fails, "'LevelsetGrid' object has no attribute 'setConst'"); this
plume is larger and needs nothing but Python. The writer follows the format as
tests/suite/common/vdb.rs does (see there for the layout).
"""

import argparse
import math
import os
import struct
import zlib


def lattice(x, y, z, seed):
    h = (x * 374761393 + y * 668265263 + z * 2147483647 + seed * 144665) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    return ((h ^ (h >> 16)) & 0xFFFF) / 65535.0


def value_noise(x, y, z, seed):
    xi, yi, zi = math.floor(x), math.floor(y), math.floor(z)
    fx, fy, fz = x - xi, y - yi, z - zi
    sx, sy, sz = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy), fz * fz * (3 - 2 * fz)
    total = 0.0
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                w = (sx if dx else 1 - sx) * (sy if dy else 1 - sy) * (sz if dz else 1 - sz)
                total += w * lattice(xi + dx, yi + dy, zi + dz, seed)
    return total


def fractal(x, y, z, seed):
    return sum(
        value_noise(x * 2**o, y * 2**o, z * 2**o, seed + o) / 2**o for o in range(4)
    ) / 1.875


def plume(n):
    """Density per voxel (x, y, z) of an n × 2n × n grid, y up."""
    voxels = {}
    for y in range(2 * n):
        h = y / (2 * n)
        # The column's axis curls as it rises; it widens and thins.
        cx = 0.5 * n + 0.12 * n * math.sin(5.0 * h) * h
        cz = 0.5 * n + 0.10 * n * math.cos(4.0 * h) * h
        radius = n * (0.1 + 0.32 * h)
        for x in range(n):
            for z in range(n):
                r = math.hypot(x - cx, z - cz) / radius
                if r > 1.6:
                    continue
                puffs = fractal(x / 7.0, y / 7.0, z / 7.0, 7)
                billows = max(0.0, puffs - 0.3) * 2.5
                d = max(0.0, 1.0 - r * r / 1.6) * billows * (1.0 - 0.5 * h)
                d *= min(1.0, y / 3.0)
                if d > 0.02:
                    voxels[(x, y, z)] = d
    return voxels


def string(s):
    b = s.encode()
    return struct.pack("<I", len(b)) + b


def mask(bits, count):
    out = bytearray()
    for w in range(count // 64):
        word = 0
        for i in range(64):
            if (w * 64 + i) in bits:
                word |= 1 << i
        out += struct.pack("<Q", word)
    return bytes(out)


BLOSC = None
ACTIVE_MASK = False


def values(vals, active=None):
    """A node's values: all of them (metadata 6), or with active-mask compression only the
    active ones, the inactive all 0 (metadata 0), as OpenVDB writes by default."""
    if ACTIVE_MASK:
        vals = [vals[i] for i in sorted(active or ())]
        if not vals:
            return bytes([0]) + struct.pack("<q", 0)
    raw = struct.pack("<%de" % len(vals), *vals)
    if BLOSC:
        # As OpenVDB's bloscToStream: LZ4, level 9, byte shuffle, the value's size as typesize.
        z = BLOSC.compress(raw, typesize=2, clevel=9, shuffle=BLOSC.SHUFFLE, cname="lz4")
    else:
        z = zlib.compress(raw)
    return bytes([0 if ACTIVE_MASK else 6]) + struct.pack("<q", len(z)) + z


def write_vdb(voxels, voxel_size, translation):
    tree = {}
    for (x, y, z), v in voxels.items():
        i5 = ((x & 4095) >> 7) << 10 | ((y & 4095) >> 7) << 5 | ((z & 4095) >> 7)
        i4 = ((x & 127) >> 3) << 8 | ((y & 127) >> 3) << 4 | ((z & 127) >> 3)
        i3 = (x & 7) << 6 | (y & 7) << 3 | (z & 7)
        tree.setdefault(i5, {}).setdefault(i4, {})[i3] = v
    head = struct.pack("<qIIIB", 0x56444220, 224, 11, 0, 1)
    head += b"5f0d3a52-7c1e-4b8e-9a51-2d7e4c3b9f10" + struct.pack("<I", 0) + struct.pack("<I", 1)
    # Saved as half floats: OpenVDB appends "_HalfFloat" to the type and sets the metadata.
    head += string("density") + string("Tree_float_5_4_3_HalfFloat") + string("")
    grid_pos = len(head) + 24
    # Blosc or zip, with or without active-mask compression.
    grid = struct.pack("<I", (4 if BLOSC else 1) | (2 if ACTIVE_MASK else 0))
    meta = [("class", "string", b"fog volume"), ("is_saved_as_half_float", "bool", b"\x01")]
    grid += struct.pack("<I", len(meta))
    for name, ty, data in meta:
        grid += string(name) + string(ty) + struct.pack("<I", len(data)) + data
    s = voxel_size
    grid += string("ScaleTranslateMap")
    for v in (translation, (s,) * 3, (s,) * 3, (1 / s,) * 3, (1 / (s * s),) * 3, (0.5 / s,) * 3):
        grid += struct.pack("<3d", *v)
    grid += struct.pack("<IfII", 1, 0.0, 0, 1)
    grid += struct.pack("<3i", 0, 0, 0)
    grid += mask(tree, 32768) + mask(set(), 32768) + values([0.0] * 32768)
    for i5 in sorted(tree):
        node4 = tree[i5]
        grid += mask(node4, 4096) + mask(set(), 4096) + values([0.0] * 4096)
        for i4 in sorted(node4):
            grid += mask(node4[i4], 512)
    block_pos = grid_pos + len(grid)
    for i5 in sorted(tree):
        for i4 in sorted(tree[i5]):
            leaf = tree[i5][i4]
            grid += mask(leaf, 512) + values([leaf.get(i, 0.0) for i in range(512)], leaf)
    end_pos = grid_pos + len(grid)
    return head + struct.pack("<QQQ", grid_pos, block_pos, end_pos) + grid


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", type=int, default=48, help="voxels across (2x that high)")
    parser.add_argument(
        "--out", default=os.path.join(os.path.dirname(__file__), "..", "smoke.vdb")
    )
    parser.add_argument(
        "--blosc",
        action="store_true",
        help="Blosc (LZ4) compression, as Blender's caches default to (needs `pip install blosc`)",
    )
    parser.add_argument(
        "--active-mask",
        action="store_true",
        help="write only active values (OpenVDB's default, and Blender's)",
    )
    args = parser.parse_args()
    global ACTIVE_MASK
    ACTIVE_MASK = args.active_mask
    if args.blosc:
        global BLOSC  # noqa: PLW0603
        import blosc

        BLOSC = blosc
    n = args.size
    voxels = plume(n)
    # 2 units across, 4 high, its base centred on the origin.
    size = 2.0 / n
    data = write_vdb(voxels, size, (-1.0 + 0.5 * size, 0.5 * size, -1.0 + 0.5 * size))
    with open(args.out, "wb") as f:
        f.write(data)
    print(f"{args.out}: {len(voxels)} active voxels, {len(data)} bytes")


if __name__ == "__main__":
    main()
