//! Ray-scene intersection (WGSL side: `shaders/geometry/intersect.wgsl`): the closest primitive,
//! shadow rays' tests and the full hit, through whichever structure the scene has (the BVH
//! walks of `crate::cpu::traverse`, or the scan), built on `hit.rs`'s tests. Ray directions
//! are unit length.

use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::alpha::hit_scene_triangle;
use crate::cpu::geometry::hit::hit_quad;
use crate::cpu::geometry::hit::hit_sphere;
use crate::cpu::geometry::hit::ClosestPrimitive;
use crate::cpu::geometry::hit::Hit;
use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::geometry::instance::{
    own_triangle_count, scan_instances, scene_triangle, scene_triangle_normals,
};
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::geometry::shading_normal::valid_shading_normal;
use crate::cpu::geometry::surface::{parametric_point, sphere_point};
use crate::cpu::geometry::triangle::{
    triangle_barycentrics, triangle_normal, triangle_ray, triangle_surface_point,
};
use crate::cpu::textures::texture::{both_sets, sphere_uv, triangle_uv};
use crate::cpu::traverse::bvh::{
    bvh_closest_primitive, bvh_escapes, bvh_first_hit_is, bvh_traverse,
};
use crate::cpu::traverse::bvh_ray::bvh_ray;
use crate::kernel::types::{
    NO_INSTANCE, PRIMITIVE_ENVIRONMENT, PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD, PRIMITIVE_SPHERE,
    PRIMITIVE_TRIANGLE,
};
use glam::{Vec2, Vec3, Vec4};

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

/// Whether nothing lies along `ray` before distance `t_max` (a shadow ray to a point).
pub fn unoccluded_before(geometry: &Geometry, ray: &Ray, t_max: f32) -> bool {
    if !geometry.bvh_nodes.is_empty() {
        // Any hit nearer than t_max ends the search (a target no primitive matches).
        let no_target = PRIMITIVE_ENVIRONMENT << PRIMITIVE_KIND_SHIFT;
        return bvh_traverse(geometry, &bvh_ray(ray), t_max, t_max, 0, no_target).t == NO_HIT;
    }
    closest_primitive(geometry, ray).t >= t_max
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
