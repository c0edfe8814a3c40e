//! What the BVH walks share (WGSL side: `shaders/traverse/bvh_ray.wgsl`): the ray with its
//! reciprocal direction, the box test and its rounding slack, and the leaves' primitive tests.
//! The walks themselves are `bvh.rs`, `blas.rs` and `wide.rs`.
use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::alpha::hit_scene_triangle;
use crate::cpu::geometry::hit::hit_quad;
use crate::cpu::geometry::hit::hit_sphere;
use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::geometry::triangle::triangle_ray;
use crate::cpu::geometry::triangle::TriangleRay;
use crate::kernel::types::BvhNode;
use crate::kernel::types::PRIMITIVE_INDEX_MASK;
use crate::kernel::types::PRIMITIVE_KIND_SHIFT;
use crate::kernel::types::PRIMITIVE_QUAD;
use crate::kernel::types::PRIMITIVE_TRIANGLE;
use glam::{Vec3, Vec3A};

/// No shadow target: [`bvh_traverse`] looks for the closest hit.
pub const NO_PRIMITIVE: u32 = u32::MAX;

/// A ray with what the box and triangle tests share across nodes.
#[derive(Clone, Copy, Debug)]
pub struct BvhRay {
    pub ray: Ray,
    /// 1 / dir, with zero components replaced by a tiny value of the same sign, so the slab
    /// test never multiplies 0 by infinity.
    pub inv_dir: Vec3A,
    /// The origin again, in the SIMD layout the box test works in.
    pub origin: Vec3A,
    pub tri: TriangleRay,
}

pub fn bvh_ray(ray: &Ray) -> BvhRay {
    let tiny = Vec3::select(
        ray.dir.cmpge(Vec3::ZERO),
        Vec3::splat(1e-20),
        Vec3::splat(-1e-20),
    );
    let dir = Vec3::select(ray.dir.abs().cmplt(Vec3::splat(1e-20)), tiny, ray.dir);
    BvhRay {
        ray: *ray,
        inv_dir: Vec3A::from(1.0 / dir),
        origin: Vec3A::from(ray.origin),
        tri: triangle_ray(ray),
    }
}

/// 1 + 2γ(3), a little more than the relative rounding error of a slab distance or a
/// triangle's t (Ize, "Robust BVH Ray Traversal", 2013).
pub const BOX_SLACK: f32 = 1.000_000_4;

/// t widened by [`BOX_SLACK`]; `NO_HIT` stays `NO_HIT` rather than overflowing.
pub fn widened(t: f32) -> f32 {
    if t > 1e38 {
        t
    } else {
        t * BOX_SLACK
    }
}

/// Where the ray enters a node's box (0 when it starts inside), or `NO_HIT` when it misses the
/// box or enters it beyond `t_max`. The exit distance and `t_max` are widened by [`BOX_SLACK`],
/// so rounding never drops a box the ray grazes, nor one whose primitive is hit within an ulp
/// of the best hit so far (as at a vertex many triangles share): the primitive tests decide
/// those.
pub fn hit_box(node: &BvhNode, r: &BvhRay, t_max: f32) -> f32 {
    // All three axes at once: the same IEEE operations as the kernel's per-component ones, and
    // no NaN can arise (inv_dir is finite and non-zero), so min and max agree exactly.
    let t0 = (Vec3A::from(node.min) - r.origin) * r.inv_dir;
    let t1 = (Vec3A::from(node.max) - r.origin) * r.inv_dir;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element() * BOX_SLACK;
    if near <= far.min(widened(t_max)) {
        return near;
    }
    NO_HIT
}

pub fn hit_primitive(geometry: &Geometry, reference: u32, r: &BvhRay) -> f32 {
    let kind = reference >> PRIMITIVE_KIND_SHIFT;
    let index = (reference & PRIMITIVE_INDEX_MASK) as usize;
    if kind == PRIMITIVE_TRIANGLE {
        let tri = &geometry.triangles[index];
        return hit_scene_triangle(&geometry.alpha, index as u32, tri, &r.tri);
    }
    if kind == PRIMITIVE_QUAD {
        return hit_quad(&geometry.quads[index], &r.ray);
    }
    hit_sphere(&geometry.spheres[index], &r.ray)
}

/// Where `r` enters the box of the primitive `reference` (the box the host builds the BVH
/// over: `primitive_boxes` in src/kernel/bvh/mod.rs, the same arithmetic), or `NO_HIT`.
pub fn primitive_box_entry(geometry: &Geometry, reference: u32, r: &BvhRay) -> f32 {
    let kind = reference >> PRIMITIVE_KIND_SHIFT;
    let index = (reference & PRIMITIVE_INDEX_MASK) as usize;
    let (min, max) = if kind == PRIMITIVE_TRIANGLE {
        let t = &geometry.triangles[index];
        let (a, b, c) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
        (a.min(b).min(c), a.max(b).max(c))
    } else if kind == PRIMITIVE_QUAD {
        let q = &geometry.quads[index];
        let p = Vec3::from(q.corner);
        let (pu, pv) = (p + Vec3::from(q.edge_u), p + Vec3::from(q.edge_v));
        let puv = pu + Vec3::from(q.edge_v);
        (p.min(pu).min(pv).min(puv), p.max(pu).max(pv).max(puv))
    } else {
        let s = &geometry.spheres[index];
        let c = Vec3::from(s.center);
        (c - s.radius, c + s.radius)
    };
    let node = BvhNode {
        min: min.to_array(),
        max: max.to_array(),
        ..Default::default()
    };
    hit_box(&node, r, NO_HIT)
}
