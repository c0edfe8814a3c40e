//! Ray-scene intersection (WGSL side: `shaders/geometry/intersect.wgsl`). Ray directions are unit length.

use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::alpha::{hit_scene_triangle, AlphaTest};
use crate::cpu::geometry::instance::{
    own_triangle_count, scan_instances, scene_triangle, scene_triangle_normals,
};
use crate::cpu::geometry::shading_normal::valid_shading_normal;
use crate::cpu::geometry::surface::{parametric_point, sphere_point};
use crate::cpu::geometry::triangle::{
    triangle_barycentrics, triangle_normal, triangle_ray, triangle_surface_point,
};
use crate::cpu::textures::texture::{both_sets, sphere_uv, triangle_uv};
use crate::cpu::traverse::bvh::{bvh_closest_primitive, bvh_escapes, bvh_first_hit_is};
use crate::kernel::types::{
    BvhNode, BvhWideNode, Instance, Quad, Sphere, Triangle, TriangleNormals, TriangleUvs,
    NO_INSTANCE, PRIMITIVE_ENVIRONMENT, PRIMITIVE_QUAD, PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE,
};
use glam::{Vec2, Vec3, Vec4};

/// The scene's surfaces as the kernel's intersection code reads them. With `bvh_nodes` empty,
/// every ray tests every primitive (the kernel's `USE_BVH = false`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Geometry<'a> {
    pub spheres: &'a [Sphere],
    pub quads: &'a [Quad],
    pub triangles: &'a [Triangle],
    pub triangle_normals: &'a [TriangleNormals],
    pub bvh_nodes: &'a [BvhNode],
    pub bvh_primitives: &'a [u32],
    /// Instanced meshes' placements (`instance.rs`); empty without any.
    pub instances: &'a [Instance],
    /// The same tree 4 wide, traversed instead of `bvh_nodes` when not empty (the CPU's
    /// layout: src/kernel/bvh/layout.rs).
    pub bvh_wide_nodes: &'a [BvhWideNode],
    /// One per triangle when `textured`.
    pub triangle_uvs: &'a [TriangleUvs],
    /// The second set, where a texture reads it (else empty).
    pub triangle_uvs1: &'a [TriangleUvs],
    /// Whether hits need texture coordinates (the kernel's `HAS_TEXTURES`).
    pub textured: bool,
    /// Alpha-tested and blended triangles (`alpha.rs`); off by default.
    pub alpha: AlphaTest<'a>,
}

impl<'a> Geometry<'a> {
    /// Spheres and quads only, tested one by one.
    pub fn new(spheres: &'a [Sphere], quads: &'a [Quad]) -> Geometry<'a> {
        Geometry {
            spheres,
            quads,
            ..Default::default()
        }
    }
}

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

pub fn closest_primitive(geometry: &Geometry, ray: &Ray) -> ClosestPrimitive {
    if !geometry.bvh_nodes.is_empty() {
        return bvh_closest_primitive(geometry, ray);
    }
    scan_closest_primitive(geometry, ray)
}

/// The closest primitive by testing every one: the structure without a BVH, and what every
/// other traversal must agree with. It visits primitives in the closest-hit rule's order
/// ([`hit_comes_first`]) and keeps only strictly nearer hits, so among equal t the first, the
/// lowest reference, wins.
pub fn scan_closest_primitive(geometry: &Geometry, ray: &Ray) -> ClosestPrimitive {
    let mut best = ClosestPrimitive {
        t: NO_HIT,
        primitive: PRIMITIVE_QUAD,
        index: 0,
        instance: NO_INSTANCE,
    };
    for (i, s) in geometry.spheres.iter().enumerate() {
        let t = hit_sphere(s, ray);
        if t < best.t {
            best = ClosestPrimitive {
                t,
                primitive: PRIMITIVE_SPHERE,
                index: i as u32,
                instance: NO_INSTANCE,
            };
        }
    }
    for (i, q) in geometry.quads.iter().enumerate() {
        let t = hit_quad(q, ray);
        if t < best.t {
            best = ClosestPrimitive {
                t,
                primitive: PRIMITIVE_QUAD,
                index: i as u32,
                instance: NO_INSTANCE,
            };
        }
    }
    let own = own_triangle_count(geometry);
    if own > 0 {
        let r = triangle_ray(ray);
        for (i, tri) in geometry.triangles[..own].iter().enumerate() {
            let t = hit_scene_triangle(&geometry.alpha, i as u32, tri, &r);
            if t < best.t {
                best = ClosestPrimitive {
                    t,
                    primitive: PRIMITIVE_TRIANGLE,
                    index: i as u32,
                    instance: NO_INSTANCE,
                };
            }
        }
    }
    // Not called without instances: the call alone was 2% of a CPU render of the plain box.
    if geometry.instances.is_empty() {
        return best;
    }
    scan_instances(geometry, ray, best)
}

/// Whether the first thing `ray` meets is the primitive (`primitive`, `index`).
pub fn first_hit_is(geometry: &Geometry, ray: &Ray, primitive: u32, index: u32) -> bool {
    if primitive == PRIMITIVE_ENVIRONMENT {
        return escapes(geometry, ray);
    }
    if !geometry.bvh_nodes.is_empty() {
        return bvh_first_hit_is(geometry, ray, primitive, index);
    }
    let closest = closest_primitive(geometry, ray);
    // A target is placed as it is: a light never goes through an instance.
    closest.t != NO_HIT
        && closest.primitive == primitive
        && closest.index == index
        && closest.instance == NO_INSTANCE
}

/// Whether `ray` leaves the scene without hitting anything (it then sees the environment).
pub fn escapes(geometry: &Geometry, ray: &Ray) -> bool {
    if !geometry.bvh_nodes.is_empty() {
        return bvh_escapes(geometry, ray);
    }
    closest_primitive(geometry, ray).t == NO_HIT
}

/// The nearest hit of `ray` among all primitives; `t == NO_HIT` when there is none.
pub fn intersect_scene(geometry: &Geometry, ray: &Ray) -> Hit {
    let closest = closest_primitive(geometry, ray);
    if closest.t == NO_HIT {
        return Hit {
            t: NO_HIT,
            position: Vec3::ZERO,
            error: Vec3::ZERO,
            normal: Vec3::ZERO,
            shading_normal: Vec3::ZERO,
            material: 0,
            front_face: false,
            primitive: 0,
            index: 0,
            uv: Vec4::ZERO,
            barycentrics: Vec3::ZERO,
        };
    }
    // Zero: shade with the geometric normal.
    let mut shading = Vec3::ZERO;
    let mut uv = Vec4::ZERO;
    let mut barycentrics = Vec3::ZERO;
    let (outward, surface, material) = if closest.primitive == PRIMITIVE_SPHERE {
        let s = &geometry.spheres[closest.index as usize];
        // Normalised, not divided by the radius: a normal a little too long would make
        // reflected directions too long, and the error would grow with every bounce.
        let outward = (ray.origin + closest.t * ray.dir - Vec3::from(s.center)).normalize();
        if geometry.textured {
            uv = both_sets(sphere_uv(outward));
        }
        (
            outward,
            sphere_point(Vec3::from(s.center), s.radius, outward),
            s.material,
        )
    } else if closest.primitive == PRIMITIVE_TRIANGLE {
        let tri = &scene_triangle(geometry, closest.instance, closest.index);
        let b = triangle_barycentrics(tri, &triangle_ray(ray));
        barycentrics = b;
        let n = &scene_triangle_normals(geometry, closest.instance, closest.index);
        if n.smooth_shading != 0 {
            shading = (b.x * Vec3::from(n.n0) + b.y * Vec3::from(n.n1) + b.z * Vec3::from(n.n2))
                .normalize();
        }
        if geometry.textured {
            uv = triangle_uv(
                geometry.triangle_uvs,
                geometry.triangle_uvs1,
                closest.index,
                b,
            );
        }
        // On the triangle's plane: v0 + b1 e1 + b2 e2, from the edges the normal is made of.
        (
            triangle_normal(tri),
            triangle_surface_point(tri, b),
            tri.material,
        )
    } else {
        let q = &geometry.quads[closest.index as usize];
        // On the plane through corner, edge_u and edge_v: the hit test's a and b, clamped.
        let w = ray.origin + closest.t * ray.dir - Vec3::from(q.corner);
        let a = Vec3::from(q.u_dual).dot(w).clamp(0.0, 1.0);
        let b = Vec3::from(q.v_dual).dot(w).clamp(0.0, 1.0);
        if geometry.textured {
            uv = both_sets(Vec2::new(a, b));
        }
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
    let normal = if front_face { outward } else { -outward };
    let shading_normal = if shading != Vec3::ZERO {
        let facing = if shading.dot(normal) >= 0.0 {
            shading
        } else {
            -shading
        };
        valid_shading_normal(normal, -ray.dir, facing)
    } else {
        normal
    };
    Hit {
        t: closest.t,
        position: surface.position,
        error: surface.error,
        normal,
        shading_normal,
        material,
        front_face,
        primitive: closest.primitive,
        index: closest.index,
        uv,
        barycentrics,
    }
}

/// Whether `dir` is on one side of the surface by the shading normal and on the other by the
/// geometric normal: following it would leak light through a smooth-shaded surface, so such
/// directions carry nothing. Never true where the shading normal is the geometric one.
pub fn crosses_shading_side(dir: Vec3, hit: &Hit) -> bool {
    dir.dot(hit.normal) * dir.dot(hit.shading_normal) < 0.0
}
