//! Triangles (WGSL side: `shaders/geometry/triangle.wgsl`): watertight intersection and area sampling.
//!
//! Intersection is Woop, Benthin and Wald's "Watertight Ray/Triangle Intersection" (JCGT 2013):
//! the ray is made the +z axis of a sheared frame, and each edge's 2D edge function is computed
//! from the same two vertices, in the same order, by whichever triangle shares the edge. A ray
//! through a shared edge or vertex therefore sees it inside (or on the edge of) at least one of
//! the triangles, never outside both.

use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::geometry::surface::{parametric_point, SurfacePoint};
use crate::kernel::types::Triangle;
use glam::Vec3;

/// A ray prepared once for all the triangles it is tested against.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay {
    pub origin: Vec3,
    /// The axis the direction is largest along (z of the sheared frame), and the other two, in
    /// the order that keeps the frame's winding.
    pub kx: usize,
    pub ky: usize,
    pub kz: usize,
    /// The shear that maps the direction to (0, 0, 1): (dx/dz, dy/dz, 1/dz).
    pub shear: Vec3,
}

pub fn triangle_ray(ray: &Ray) -> TriangleRay {
    let a = ray.dir.abs();
    let kz = if a.x > a.y && a.x > a.z {
        0
    } else if a.y > a.z {
        1
    } else {
        2
    };
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if ray.dir[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let dz = ray.dir[kz];
    TriangleRay {
        origin: ray.origin,
        kx,
        ky,
        kz,
        shear: Vec3::new(ray.dir[kx] / dz, ray.dir[ky] / dz, 1.0 / dz),
    }
}

/// The scaled edge functions (u, v, w: the weights of v0, v1, v2, not yet divided by their
/// sum) and the scaled distance, of a ray against a triangle.
#[derive(Clone, Copy, Debug)]
pub struct TriangleEdges {
    pub u: f32,
    pub v: f32,
    pub w: f32,
    pub t_scaled: f32,
}

pub fn triangle_edges(tri: &Triangle, r: &TriangleRay) -> TriangleEdges {
    let a = Vec3::from(tri.v0) - r.origin;
    let b = Vec3::from(tri.v1) - r.origin;
    let c = Vec3::from(tri.v2) - r.origin;
    let ax = a[r.kx] - r.shear.x * a[r.kz];
    let ay = a[r.ky] - r.shear.y * a[r.kz];
    let bx = b[r.kx] - r.shear.x * b[r.kz];
    let by = b[r.ky] - r.shear.y * b[r.kz];
    let cx = c[r.kx] - r.shear.x * c[r.kz];
    let cy = c[r.ky] - r.shear.y * c[r.kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let t_scaled =
        u * (r.shear.z * a[r.kz]) + v * (r.shear.z * b[r.kz]) + w * (r.shear.z * c[r.kz]);
    TriangleEdges { u, v, w, t_scaled }
}

/// t > 0 of a hit from either side, or `NO_HIT`. Points on an edge count as inside.
pub fn hit_triangle(tri: &Triangle, r: &TriangleRay) -> f32 {
    let e = triangle_edges(tri, r);
    if (e.u < 0.0 || e.v < 0.0 || e.w < 0.0) && (e.u > 0.0 || e.v > 0.0 || e.w > 0.0) {
        return NO_HIT;
    }
    let det = e.u + e.v + e.w;
    if det == 0.0 {
        return NO_HIT;
    }
    let t = e.t_scaled / det;
    // Written to reject NaN as the WGSL does.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(t > 0.0) {
        return NO_HIT;
    }
    t
}

/// Barycentric weights of v0, v1, v2 where the ray meets the triangle (it must hit it).
pub fn triangle_barycentrics(tri: &Triangle, r: &TriangleRay) -> Vec3 {
    let e = triangle_edges(tri, r);
    Vec3::new(e.u, e.v, e.w) / (e.u + e.v + e.w)
}

/// The point with barycentric weights `b` (of v0, v1, v2), on the triangle's plane, with its
/// rounding error (`surface.rs`): v0 + b.y e1 + b.z e2, with the same edges as `triangle_normal`.
/// The watertight test shears the axes into one another, so its rounding along any axis
/// depends on every coordinate: the bound is the largest of the three, in every axis (else a
/// wall in the plane x = 0 would get no offset along x at all, and its rays would hit it again).
pub fn triangle_surface_point(tri: &Triangle, b: Vec3) -> SurfacePoint {
    let v0 = Vec3::from(tri.v0);
    let point = parametric_point(
        v0,
        Vec3::from(tri.v1) - v0,
        Vec3::from(tri.v2) - v0,
        b.y,
        b.z,
    );
    SurfacePoint {
        position: point.position,
        error: Vec3::splat(point.error.max_element()),
    }
}

pub fn triangle_normal(tri: &Triangle) -> Vec3 {
    (Vec3::from(tri.v1) - Vec3::from(tri.v0))
        .cross(Vec3::from(tri.v2) - Vec3::from(tri.v0))
        .normalize()
}

/// The barycentrics (of v0, v1, v2) of a point uniform on a triangle's area, from two uniform
/// numbers (the square-root warp).
pub fn triangle_sample_barycentrics(u: (f32, f32)) -> Vec3 {
    let su = u.0.sqrt();
    let b0 = 1.0 - su;
    let b1 = u.1 * su;
    Vec3::new(b0, b1, 1.0 - b0 - b1)
}

/// The point of the triangle at barycentrics `b`.
pub fn triangle_point(tri: &Triangle, b: Vec3) -> Vec3 {
    b.x * Vec3::from(tri.v0) + b.y * Vec3::from(tri.v1) + b.z * Vec3::from(tri.v2)
}

/// Distance along a unit direction from p to the triangle's plane (negative or NaN: none ahead).
pub fn triangle_plane_distance(tri: &Triangle, normal: Vec3, p: Vec3, dir: Vec3) -> f32 {
    normal.dot(Vec3::from(tri.v0) - p) / normal.dot(dir)
}
