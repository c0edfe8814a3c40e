//! A generated stress mesh: a bumpy ("displaced") sphere of any size, closed and watertight, with
//! area-weighted vertex normals, written as binary PLY. `glint stress-mesh` writes it, so the
//! ~1M-triangle file never has to be committed.

use glam::Vec3;
use std::io::Write;
use std::path::Path;

/// A unit sphere whose radius is scaled by `1 + 0.08 sin(12θ) sin(12φ)`, as `rings` rings of
/// `segments` vertices between two poles: 2 · segments · (rings − 1) triangles.
pub struct StressMesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
}

impl StressMesh {
    /// About `triangles` triangles (at least 8 · 4): rings are half the segments.
    pub fn with_triangles(triangles: usize) -> StressMesh {
        let segments = ((triangles as f64).sqrt().round() as usize).max(8);
        let rings = (segments / 2).max(4);
        Self::new(segments, rings)
    }

    pub fn new(segments: usize, rings: usize) -> StressMesh {
        Self::displaced(segments, rings, 0.08)
    }

    /// A UV sphere of unit radius whose radius is displaced by `amplitude` (0: a convex,
    /// tessellated sphere, every vertex on the unit sphere).
    pub fn displaced(segments: usize, rings: usize, amplitude: f32) -> StressMesh {
        use std::f32::consts::PI;
        let radius =
            |theta: f32, phi: f32| 1.0 + amplitude * (12.0 * theta).sin() * (12.0 * phi).sin();
        let mut positions = vec![Vec3::Y];
        for r in 1..rings {
            let theta = PI * r as f32 / rings as f32;
            for s in 0..segments {
                let phi = 2.0 * PI * s as f32 / segments as f32;
                let dir = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                positions.push(dir * radius(theta, phi));
            }
        }
        positions.push(-Vec3::Y);
        let south = positions.len() as u32 - 1;
        let ring = |r: usize, s: usize| (1 + (r - 1) * segments + s % segments) as u32;
        let mut indices = Vec::with_capacity(2 * segments * (rings - 1));
        for s in 0..segments {
            indices.push([0, ring(1, s + 1), ring(1, s)]);
            indices.push([south, ring(rings - 1, s), ring(rings - 1, s + 1)]);
        }
        for r in 1..rings - 1 {
            for s in 0..segments {
                let (a, b) = (ring(r, s), ring(r, s + 1));
                let (c, d) = (ring(r + 1, s), ring(r + 1, s + 1));
                indices.push([a, b, d]);
                indices.push([a, d, c]);
            }
        }
        let mut normals = vec![Vec3::ZERO; positions.len()];
        for t in &indices {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                normals[i as usize] += n;
            }
        }
        for n in &mut normals {
            *n = n.normalize_or_zero();
        }
        StressMesh {
            positions,
            normals,
            indices,
        }
    }

    /// Writes binary little-endian PLY (positions, normals, triangles).
    pub fn write_ply(&self, path: &Path) -> std::io::Result<()> {
        let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
        self.encode_ply(&mut out)?;
        out.flush()
    }

    /// The binary PLY file, written to `out`.
    pub fn encode_ply(&self, out: &mut impl Write) -> std::io::Result<()> {
        write!(
            out,
            "ply\nformat binary_little_endian 1.0\ncomment glint stress-mesh: a displaced sphere\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            self.positions.len(),
            self.indices.len()
        )?;
        for (p, n) in self.positions.iter().zip(&self.normals) {
            for v in p.to_array().iter().chain(n.to_array().iter()) {
                out.write_all(&v.to_le_bytes())?;
            }
        }
        for t in &self.indices {
            out.write_all(&[3])?;
            for i in t {
                out.write_all(&(*i as i32).to_le_bytes())?;
            }
        }
        Ok(())
    }
}
