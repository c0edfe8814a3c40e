//! Instances (WGSL side: `shaders/geometry/instance.wgsl`). A mesh placed many times keeps its
//! triangles once, in its own coordinates, and each placement keeps its transforms
//! (`src/kernel/scene/acceleration.rs`), so memory grows with unique geometry. A hit through an instance
//! carries (instance, triangle); what shading reads of the triangle is put in the scene's
//! coordinates here, so the code after intersection is the same for every triangle. Triangles
//! placed as they are ([`NO_INSTANCE`]) are read unchanged, without arithmetic.

use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::alpha::hit_scene_triangle;
use crate::cpu::geometry::hit::ClosestPrimitive;
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::geometry::triangle::triangle_ray;
use crate::kernel::types::{Instance, Triangle, TriangleNormals, NO_INSTANCE, PRIMITIVE_TRIANGLE};
use glam::Vec3;

fn row(r: &[f32; 4]) -> Vec3 {
    Vec3::new(r[0], r[1], r[2])
}

/// rows · (p, 1): a point through a 3×4 transform.
pub fn transform_point(rows: &[[f32; 4]; 3], p: Vec3) -> Vec3 {
    Vec3::new(
        row(&rows[0]).dot(p) + rows[0][3],
        row(&rows[1]).dot(p) + rows[1][3],
        row(&rows[2]).dot(p) + rows[2][3],
    )
}

/// rows · (v, 0): a direction through a 3×4 transform's linear part.
pub fn transform_vector(rows: &[[f32; 4]; 3], v: Vec3) -> Vec3 {
    Vec3::new(
        row(&rows[0]).dot(v),
        row(&rows[1]).dot(v),
        row(&rows[2]).dot(v),
    )
}

/// The ray in the instance's own coordinates. The direction is not renormalised, so t is the
/// same parameter along both rays and hits compare across instances by t.
pub fn object_ray(inst: &Instance, ray: &Ray) -> Ray {
    Ray {
        origin: transform_point(&inst.to_object, ray.origin),
        dir: transform_vector(&inst.to_object, ray.dir),
    }
}

/// A normal in the scene's coordinates: through the inverse transpose of the instance's
/// linear part, which is the transpose of `to_object`'s, so no third matrix is stored.
pub fn normal_to_world(inst: &Instance, n: Vec3) -> Vec3 {
    let m = &inst.to_object;
    (n.x * row(&m[0]) + n.y * row(&m[1]) + n.z * row(&m[2])).normalize()
}

/// Triangle `index`, hit through `instance`, in the scene's coordinates.
pub fn scene_triangle(geometry: &Geometry, instance: u32, index: u32) -> Triangle {
    let mut tri = geometry.triangles[index as usize];
    if instance != NO_INSTANCE {
        let m = &geometry.instances[instance as usize].to_world;
        tri.v0 = transform_point(m, Vec3::from(tri.v0)).into();
        tri.v1 = transform_point(m, Vec3::from(tri.v1)).into();
        tri.v2 = transform_point(m, Vec3::from(tri.v2)).into();
    }
    tri
}

/// Triangle `index`'s vertex normals, hit through `instance`, in the scene's coordinates.
pub fn scene_triangle_normals(geometry: &Geometry, instance: u32, index: u32) -> TriangleNormals {
    let mut n = geometry.triangle_normals[index as usize];
    if instance != NO_INSTANCE && n.smooth_shading != 0 {
        let inst = &geometry.instances[instance as usize];
        n.n0 = normal_to_world(inst, Vec3::from(n.n0)).into();
        n.n1 = normal_to_world(inst, Vec3::from(n.n1)).into();
        n.n2 = normal_to_world(inst, Vec3::from(n.n2)).into();
    }
    n
}

/// How many triangles are placed as they are: those before the first instanced mesh's.
pub fn own_triangle_count(geometry: &Geometry) -> usize {
    geometry
        .instances
        .first()
        .map_or(geometry.triangles.len(), |i| i.first_triangle as usize)
}

/// `best`, or the closest hit on an instance's triangle if it comes before it, testing every
/// triangle of every instance in the closest-hit rule's order (instances, then their
/// triangles, by index) and keeping only strictly nearer hits: the scan's part for instances
/// (`scan_closest_primitive`), which the two-level traversal must agree with.
pub fn scan_instances(geometry: &Geometry, ray: &Ray, best: ClosestPrimitive) -> ClosestPrimitive {
    let mut out = best;
    for (k, inst) in geometry.instances.iter().enumerate() {
        let r = triangle_ray(&object_ray(inst, ray));
        for i in inst.first_triangle..inst.first_triangle + inst.triangle_count {
            let t = hit_scene_triangle(&geometry.alpha, i, &geometry.triangles[i as usize], &r);
            if t < out.t {
                out = ClosestPrimitive {
                    t,
                    primitive: PRIMITIVE_TRIANGLE,
                    index: i,
                    instance: k as u32,
                };
            }
        }
    }
    out
}
