//! Ray-scene intersection (WGSL side: `shaders/intersect.wgsl`). Ray directions are unit length.

use super::surface::{parametric_point, sphere_point};
use super::Ray;
use crate::shader_types::{Quad, Sphere, PRIMITIVE_QUAD, PRIMITIVE_SPHERE};
use glam::Vec3;

pub const NO_HIT: f32 = 3.402823e38;

#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    /// The hit point, put back on the surface (`surface.rs`), so errors cannot build up over
    /// many bounces, and a bound on its rounding error per coordinate.
    pub position: Vec3,
    pub error: Vec3,
    /// Geometric normal, unit length, facing against the incoming ray.
    pub normal: Vec3,
    pub material: u32,
    /// True when the ray hit the side the surface's outward normal points to.
    pub front_face: bool,
    /// Which primitive: `PRIMITIVE_SPHERE` or `PRIMITIVE_QUAD`, and its index.
    pub primitive: u32,
    pub index: u32,
}

/// Nearest t > 0 of a sphere hit, or `NO_HIT`. The discriminant is r² − |oc − h d|² rather
/// than h² − c, which cancels catastrophically for small spheres far from the ray origin.
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
    /// `PRIMITIVE_SPHERE` or `PRIMITIVE_QUAD`, and its index.
    pub primitive: u32,
    pub index: u32,
}

pub fn closest_primitive(spheres: &[Sphere], quads: &[Quad], ray: &Ray) -> ClosestPrimitive {
    let mut best = ClosestPrimitive {
        t: NO_HIT,
        primitive: PRIMITIVE_QUAD,
        index: 0,
    };
    for (i, s) in spheres.iter().enumerate() {
        let t = hit_sphere(s, ray);
        if t < best.t {
            best = ClosestPrimitive {
                t,
                primitive: PRIMITIVE_SPHERE,
                index: i as u32,
            };
        }
    }
    for (i, q) in quads.iter().enumerate() {
        let t = hit_quad(q, ray);
        if t < best.t {
            best = ClosestPrimitive {
                t,
                primitive: PRIMITIVE_QUAD,
                index: i as u32,
            };
        }
    }
    best
}

/// Whether the first thing `ray` meets is the primitive (`primitive`, `index`).
pub fn first_hit_is(
    spheres: &[Sphere],
    quads: &[Quad],
    ray: &Ray,
    primitive: u32,
    index: u32,
) -> bool {
    let closest = closest_primitive(spheres, quads, ray);
    closest.t != NO_HIT && closest.primitive == primitive && closest.index == index
}

/// The nearest hit of `ray` among all spheres and quads; `t == NO_HIT` when there is none.
pub fn intersect_scene(spheres: &[Sphere], quads: &[Quad], ray: &Ray) -> Hit {
    let closest = closest_primitive(spheres, quads, ray);
    if closest.t == NO_HIT {
        return Hit {
            t: NO_HIT,
            position: Vec3::ZERO,
            error: Vec3::ZERO,
            normal: Vec3::ZERO,
            material: 0,
            front_face: false,
            primitive: 0,
            index: 0,
        };
    }
    let (outward, surface, material) = if closest.primitive == PRIMITIVE_SPHERE {
        let s = &spheres[closest.index as usize];
        // Normalised, not divided by the radius: a normal a little too long would make
        // reflected directions too long, and the error would grow with every bounce.
        let outward = (ray.origin + closest.t * ray.dir - Vec3::from(s.center)).normalize();
        (
            outward,
            sphere_point(Vec3::from(s.center), s.radius, outward),
            s.material,
        )
    } else {
        let q = &quads[closest.index as usize];
        // On the plane through corner, edge_u and edge_v: the hit test's a and b, clamped.
        let w = ray.origin + closest.t * ray.dir - Vec3::from(q.corner);
        let a = Vec3::from(q.u_dual).dot(w).clamp(0.0, 1.0);
        let b = Vec3::from(q.v_dual).dot(w).clamp(0.0, 1.0);
        (
            Vec3::from(q.normal),
            parametric_point(
                Vec3::from(q.corner),
                Vec3::from(q.edge_u),
                Vec3::from(q.edge_v),
                a,
                b,
            ),
            q.material,
        )
    };
    let front_face = outward.dot(ray.dir) < 0.0;
    Hit {
        t: closest.t,
        position: surface.position,
        error: surface.error,
        normal: if front_face { outward } else { -outward },
        material,
        front_face,
        primitive: closest.primitive,
        index: closest.index,
    }
}
