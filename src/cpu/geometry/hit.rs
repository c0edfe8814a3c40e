//! What a ray meets (WGSL side: `shaders/geometry/hit.wgsl`): a hit and the nearest primitive,
//! the closest-hit rule every traversal keeps, and the sphere and quad tests. Below every
//! traversal: the walks in `crate::cpu::traverse` and the scene-level queries in
//! `intersect.rs` build on it. Ray directions are unit length.

use crate::cpu::core::ray::Ray;
use crate::kernel::types::{Quad, Sphere};
use glam::{Vec3, Vec4};

pub const NO_HIT: f32 = 3.402823e38;

#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    /// The hit point, put back on the surface (`surface.rs`), so errors cannot build up over
    /// many bounces, and a bound on its rounding error per coordinate.
    pub position: Vec3,
    pub error: Vec3,
    /// Geometric normal, unit length, facing against the incoming ray. It alone decides which
    /// side of the surface a ray is on (offsets, entering or leaving glass).
    pub normal: Vec3,
    /// The normal to shade with, on the geometric normal's side: interpolated vertex normals
    /// on smooth triangles, the geometric normal elsewhere.
    pub shading_normal: Vec3,
    pub material: u32,
    /// True when the ray hit the side the surface's outward normal points to.
    pub front_face: bool,
    /// Which primitive: `PRIMITIVE_SPHERE`, `PRIMITIVE_QUAD` or `PRIMITIVE_TRIANGLE`, and its index.
    pub primitive: u32,
    pub index: u32,
    /// Texture coordinates, set 0 in xy and set 1 in zw (`texture.rs`'s `both_sets`);
    /// computed only when `Geometry::textured`.
    pub uv: Vec4,
    /// A triangle hit's barycentrics (of v0, v1, v2), for its vertex tangents
    /// (`normal_map.rs`); zero on other primitives.
    pub barycentrics: Vec3,
}

/// Nearest t > 0 of a sphere hit, or `NO_HIT`. The discriminant is r² − |oc − h d|² rather
/// than h² − c, which cancels catastrophically for small spheres far from the ray origin.
#[inline]
pub fn hit_sphere(s: &Sphere, ray: &Ray) -> f32 {
    let oc = Vec3::from(s.center) - ray.origin;
    let h = ray.dir.dot(oc);
    let perp = oc - h * ray.dir;
    let r2 = s.radius * s.radius;
    let disc = r2 - perp.dot(perp);
    if disc < 0.0 {
        return NO_HIT;
    }
    let c = oc.dot(oc) - r2;
    // Roots of t² − 2ht + c = 0 in the cancellation-free form: q and c / q.
    let q = h + if h >= 0.0 { 1.0 } else { -1.0 } * disc.sqrt();
    let t0 = q.min(c / q);
    let t1 = q.max(c / q);
    if t0 > 0.0 {
        return t0;
    }
    if t1 > 0.0 {
        return t1;
    }
    NO_HIT
}

/// t of a quad hit, or `NO_HIT`: the plane, then 0 ≤ (u·w)/(u·u) ≤ 1 and 0 ≤ (v·w)/(v·v) ≤ 1
/// for the offset w of the hit point from the corner.
#[inline]
pub fn hit_quad(q: &Quad, ray: &Ray) -> f32 {
    let normal = Vec3::from(q.normal);
    let denom = normal.dot(ray.dir);
    if denom.abs() < 1e-12 {
        return NO_HIT;
    }
    let t = (q.plane_offset - normal.dot(ray.origin)) / denom;
    // Written to reject NaN as the WGSL does.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(t > 0.0) {
        return NO_HIT;
    }
    let w = ray.origin + t * ray.dir - Vec3::from(q.corner);
    let a = Vec3::from(q.u_dual).dot(w);
    let b = Vec3::from(q.v_dual).dot(w);
    if !(0.0..=1.0).contains(&a) || !(0.0..=1.0).contains(&b) {
        return NO_HIT;
    }
    t
}

/// The nearest primitive a ray meets, without the hit's point, normal and material: all a
/// shadow ray needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPrimitive {
    /// `NO_HIT` when the ray meets nothing.
    pub t: f32,
    /// `PRIMITIVE_SPHERE`, `PRIMITIVE_QUAD` or `PRIMITIVE_TRIANGLE`, and its index.
    pub primitive: u32,
    pub index: u32,
    /// The instance a triangle was hit through (`instance.rs`), or `NO_INSTANCE`: `index` is
    /// then the triangle's in the arrays, which hold it in the instance's coordinates.
    pub instance: u32,
}

/// The closest-hit rule, the same for every traversal on every device so that any structure
/// finds the same hit: the smallest t, and among equal t the lowest primitive reference,
/// `(kind << PRIMITIVE_KIND_SHIFT) | index`, that is spheres first, then quads, then
/// triangles, each by index. Whether a hit at `t` on `reference` comes before the best so far.
pub fn hit_comes_first(t: f32, reference: u32, best_t: f32, best_reference: u32) -> bool {
    t < best_t || (t == best_t && reference < best_reference)
}
