//! The primitives as the kernel reads them: spheres, quads (with their plane and duals
//! precomputed) and triangles, each with its probability of being picked by light sampling,
//! and the per-triangle shading attributes, each array present only where something reads it.

use crate::kernel::types::{self, TriangleColors, TriangleNormals, TriangleTangents, TriangleUvs};
use crate::scene::{Scene, Triangle};
use glam::{Vec2, Vec4};

/// The spheres, `light_probability[i]` the i-th's.
pub(super) fn kernel_spheres(scene: &Scene, light_probability: &[f32]) -> Vec<types::Sphere> {
    scene
        .spheres
        .iter()
        .enumerate()
        .map(|(i, s)| types::Sphere {
            center: s.center.into(),
            radius: s.radius,
            material: s.material,
            light_probability: light_probability[i],
            _pad: [0; 2],
        })
        .collect()
}

/// The quads with their area, plane and edges' duals, `light_probability[i]` the i-th's.
pub(super) fn kernel_quads(scene: &Scene, light_probability: &[f32]) -> Vec<types::Quad> {
    scene
        .quads
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let cross = q.u.cross(q.v);
            let normal = cross.normalize();
            types::Quad {
                corner: q.corner.into(),
                material: q.material,
                edge_u: q.u.into(),
                area: cross.length(),
                edge_v: q.v.into(),
                plane_offset: normal.dot(q.corner),
                normal: normal.into(),
                light_probability: light_probability[i],
                u_dual: (q.u / q.u.dot(q.u)).into(),
                v_dual: (q.v / q.v.dot(q.v)).into(),
                ..Default::default()
            }
        })
        .collect()
}

/// The `stored` triangles with their area; `light_probability` covers the scene's own, which
/// come first (instanced ones never emit: 0).
pub(super) fn kernel_triangles(
    stored: &[&Triangle],
    light_probability: &[f32],
) -> Vec<types::Triangle> {
    stored
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let [a, b, c] = t.vertices;
            types::Triangle {
                v0: a.into(),
                material: t.material,
                v1: b.into(),
                light_probability: light_probability.get(i).copied().unwrap_or(0.0),
                v2: c.into(),
                area: 0.5 * (b - a).cross(c - a).length(),
            }
        })
        .collect()
}

/// One per triangle: its vertex normals, or flat shading without them.
pub(super) fn triangle_normals(stored: &[&Triangle]) -> Vec<TriangleNormals> {
    stored
        .iter()
        .map(|t| match t.normals {
            Some([n0, n1, n2]) => TriangleNormals {
                n0: n0.into(),
                smooth_shading: 1,
                n1: n1.into(),
                n2: n2.into(),
                ..Default::default()
            },
            None => TriangleNormals::default(),
        })
        .collect()
}

/// One per triangle: the texture coordinates `set` picks, zero where a triangle has none.
fn uvs(stored: &[&Triangle], set: impl Fn(&Triangle) -> Option<[Vec2; 3]>) -> Vec<TriangleUvs> {
    stored
        .iter()
        .map(|t| {
            let [uv0, uv1, uv2] = set(t).unwrap_or_default().map(|uv| uv.into());
            TriangleUvs { uv0, uv1, uv2 }
        })
        .collect()
}

/// The first set of texture coordinates, one per triangle when the scene has textures, else
/// empty.
pub(super) fn triangle_uvs(scene: &Scene, stored: &[&Triangle]) -> Vec<TriangleUvs> {
    if scene.textures.is_empty() {
        Vec::new()
    } else {
        uvs(stored, |t| t.uvs)
    }
}

/// The second set (glTF's TEXCOORD_1), one per triangle when a texture reads it, else empty.
pub(super) fn triangle_uvs1(scene: &Scene, stored: &[&Triangle]) -> Vec<TriangleUvs> {
    if scene.textures.descriptors.iter().any(|t| t.uv_set == 1) {
        uvs(stored, |t| t.uvs1)
    } else {
        Vec::new()
    }
}

/// One per triangle when a material has a normal map, else empty.
pub(super) fn triangle_tangents(scene: &Scene, stored: &[&Triangle]) -> Vec<TriangleTangents> {
    if scene.materials.iter().any(|m| m.has_normal_map()) {
        stored
            .iter()
            .map(|t| {
                let [t0, t1, t2] = t.tangents.unwrap_or_default().map(|t| t.into());
                TriangleTangents { t0, t1, t2 }
            })
            .collect()
    } else {
        Vec::new()
    }
}

/// One per triangle when a triangle has vertex colours, else empty; white where a triangle
/// has none: the colours multiply.
pub(super) fn triangle_colors(stored: &[&Triangle]) -> Vec<TriangleColors> {
    if stored.iter().any(|t| t.colors.is_some()) {
        stored
            .iter()
            .map(|t| {
                let [c0, c1, c2] = t.colors.unwrap_or([Vec4::ONE; 3]).map(|c| c.into());
                TriangleColors { c0, c1, c2 }
            })
            .collect()
    } else {
        Vec::new()
    }
}
