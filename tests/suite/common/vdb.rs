//! Small OpenVDB files for the grid media tests, written here rather than kept as binaries: a
//! minimal writer of the format as OpenVDB 11 writes it (file version 224), for float grids
//! (or another type name, for the refusals), zlib-compressed node values without active-mask
//! compression, every leaf value written. Layout per OpenVDB's `io/Archive.cc` and
//! `tree/{RootNode,InternalNode,LeafNode}.h`: the header (magic, versions, UUID, metadata,
//! grid count), then per grid its descriptor (name, type, instance parent, and the stream
//! positions of the grid, its leaf buffers and its end), its compression flags, metadata,
//! transform, the tree's topology (root, 32³ and 16³ internal nodes with their child and value
//! masks and values, leaf value masks) and the leaves' values.

use flate2::write::ZlibEncoder;
use std::collections::BTreeMap;
use std::io::Write;

/// One grid: its voxels by index coordinate (a voxel is active where it is listed).
pub struct VdbGrid {
    pub name: String,
    /// `Tree_float_5_4_3` for a float grid.
    pub grid_type: String,
    /// Values stored as 16-bit floats (`is_saved_as_half_float`, and the type named with
    /// `_HalfFloat` after it), as OpenVDB saves them and Blender's caches are.
    pub half: bool,
    pub voxel_size: f64,
    pub translation: [f64; 3],
    pub voxels: BTreeMap<[i32; 3], f32>,
}

impl VdbGrid {
    /// A float grid named `name` with the voxels of box [0, n)³ where `f` is non-zero.
    pub fn float(name: &str, n: [i32; 3], f: impl Fn(i32, i32, i32) -> f32) -> VdbGrid {
        let mut voxels = BTreeMap::new();
        for x in 0..n[0] {
            for y in 0..n[1] {
                for z in 0..n[2] {
                    let v = f(x, y, z);
                    if v != 0.0 {
                        voxels.insert([x, y, z], v);
                    }
                }
            }
        }
        VdbGrid {
            name: name.into(),
            grid_type: "Tree_float_5_4_3".into(),
            half: false,
            voxel_size: 1.0,
            translation: [0.0; 3],
            voxels,
        }
    }
}

fn string(out: &mut Vec<u8>, s: &str) {
    out.extend((s.len() as u32).to_le_bytes());
    out.extend(s.as_bytes());
}

fn dvec3(out: &mut Vec<u8>, v: [f64; 3]) {
    for x in v {
        out.extend(x.to_le_bytes());
    }
}

fn mask(out: &mut Vec<u8>, bits: &[bool]) {
    for word in bits.chunks(64) {
        let mut w = 0u64;
        for (i, &b) in word.iter().enumerate() {
            w |= (b as u64) << i;
        }
        out.extend(w.to_le_bytes());
    }
}

/// A node's values: metadata 6 (all values, no mask), then the zlib stream's size and bytes.
fn values(out: &mut Vec<u8>, values: &[f32], half: bool) {
    out.push(6);
    let mut raw = Vec::new();
    for &v in values {
        if half {
            raw.extend(half::f16::from_f32(v).to_le_bytes());
        } else {
            raw.extend(v.to_le_bytes());
        }
    }
    let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw).unwrap();
    let zipped = z.finish().unwrap();
    out.extend((zipped.len() as i64).to_le_bytes());
    out.extend(zipped);
}

type Leaf = BTreeMap<u32, f32>;
type Node4 = BTreeMap<u32, Leaf>;
type Node5 = BTreeMap<u32, Node4>;

/// The bytes of an OpenVDB file holding `grids`.
pub fn write_vdb(grids: &[VdbGrid]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend(0x5644_4220i64.to_le_bytes());
    out.extend(224u32.to_le_bytes());
    out.extend(11u32.to_le_bytes());
    out.extend(0u32.to_le_bytes());
    out.push(1);
    out.extend(b"0a1b2c3d-4e5f-6071-8293-a4b5c6d7e8f9");
    out.extend(0u32.to_le_bytes());
    out.extend((grids.len() as u32).to_le_bytes());
    for g in grids {
        string(&mut out, &g.name);
        // OpenVDB names a grid saved as half floats by its type and "_HalfFloat".
        if g.half {
            string(&mut out, &format!("{}_HalfFloat", g.grid_type));
        } else {
            string(&mut out, &g.grid_type);
        }
        string(&mut out, "");
        let positions = out.len();
        out.extend([0u8; 24]);
        let grid_pos = out.len() as u64;
        // Compression: zip, no active mask.
        out.extend(1u32.to_le_bytes());
        let mut meta: Vec<(&str, &str, Vec<u8>)> =
            vec![("class", "string", b"fog volume".to_vec())];
        if g.half {
            meta.push(("is_saved_as_half_float", "bool", vec![1]));
        }
        out.extend((meta.len() as u32).to_le_bytes());
        for (name, ty, data) in meta {
            string(&mut out, name);
            string(&mut out, ty);
            out.extend((data.len() as u32).to_le_bytes());
            out.extend(data);
        }
        string(&mut out, "ScaleTranslateMap");
        let s = g.voxel_size;
        dvec3(&mut out, g.translation);
        dvec3(&mut out, [s; 3]);
        dvec3(&mut out, [s; 3]);
        dvec3(&mut out, [1.0 / s; 3]);
        dvec3(&mut out, [1.0 / (s * s); 3]);
        dvec3(&mut out, [0.5 / s; 3]);
        // The tree: root children by origin, then their 16³-of-leaves children, then leaves.
        let mut roots: BTreeMap<[i32; 3], Node5> = BTreeMap::new();
        for (&[x, y, z], &v) in &g.voxels {
            let origin = [x & !4095, y & !4095, z & !4095];
            let i5 = (((x & 4095) >> 7) << 10 | ((y & 4095) >> 7) << 5 | ((z & 4095) >> 7)) as u32;
            let i4 = (((x & 127) >> 3) << 8 | ((y & 127) >> 3) << 4 | ((z & 127) >> 3)) as u32;
            let i3 = ((x & 7) << 6 | (y & 7) << 3 | (z & 7)) as u32;
            roots
                .entry(origin)
                .or_default()
                .entry(i5)
                .or_default()
                .entry(i4)
                .or_default()
                .insert(i3, v);
        }
        out.extend(1u32.to_le_bytes());
        out.extend(0f32.to_le_bytes());
        out.extend(0u32.to_le_bytes());
        out.extend((roots.len() as u32).to_le_bytes());
        for (origin, node5) in &roots {
            for c in origin {
                out.extend(c.to_le_bytes());
            }
            let children: Vec<bool> = (0..32768).map(|i| node5.contains_key(&i)).collect();
            mask(&mut out, &children);
            mask(&mut out, &[false; 32768]);
            values(&mut out, &[0.0; 32768], g.half);
            for node4 in node5.values() {
                let children: Vec<bool> = (0..4096).map(|i| node4.contains_key(&i)).collect();
                mask(&mut out, &children);
                mask(&mut out, &[false; 4096]);
                values(&mut out, &[0.0; 4096], g.half);
                for leaf in node4.values() {
                    let active: Vec<bool> = (0..512).map(|i| leaf.contains_key(&i)).collect();
                    mask(&mut out, &active);
                }
            }
        }
        let block_pos = out.len() as u64;
        for node5 in roots.values() {
            for node4 in node5.values() {
                for leaf in node4.values() {
                    let active: Vec<bool> = (0..512).map(|i| leaf.contains_key(&i)).collect();
                    mask(&mut out, &active);
                    let all: Vec<f32> = (0..512)
                        .map(|i| leaf.get(&i).copied().unwrap_or(0.0))
                        .collect();
                    values(&mut out, &all, g.half);
                }
            }
        }
        let end_pos = out.len() as u64;
        for (k, p) in [grid_pos, block_pos, end_pos].into_iter().enumerate() {
            out[positions + 8 * k..positions + 8 * k + 8].copy_from_slice(&p.to_le_bytes());
        }
    }
    out
}
