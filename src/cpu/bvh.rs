//! BVH traversal (WGSL side: `shaders/bvh.wgsl`). One BVH over every sphere, quad and triangle,
//! built on the host (`src/scene/bvh.rs`) and flattened into `bvh_nodes`. A fixed stack, the
//! nearer child first, and popped nodes skipped when they start beyond the closest hit so far.
//! Shadow rays stop at the first primitive in front of the one they aim at. The order of
//! visits is the kernel's, so ties between equally near primitives resolve the same way.

use super::intersect::{hit_quad, hit_sphere, ClosestPrimitive, Geometry, NO_HIT};
use super::triangle::{hit_triangle, triangle_ray, TriangleRay};
use super::Ray;
use crate::shader_types::{
    BvhNode, PRIMITIVE_ENVIRONMENT, PRIMITIVE_INDEX_MASK, PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD,
    PRIMITIVE_TRIANGLE,
};
use glam::Vec3;

/// Enough for any tree the host accepts: it rejects trees deeper than this.
pub const BVH_STACK_SIZE: usize = 64;

/// No shadow target: [`bvh_traverse`] looks for the closest hit.
pub const NO_PRIMITIVE: u32 = u32::MAX;

/// A ray with what the box and triangle tests share across nodes.
#[derive(Clone, Copy, Debug)]
pub struct BvhRay {
    pub ray: Ray,
    /// 1 / dir, with zero components replaced by a tiny value of the same sign, so the slab
    /// test never multiplies 0 by infinity.
    pub inv_dir: Vec3,
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
        inv_dir: 1.0 / dir,
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
    let t0 = (Vec3::from(node.min) - r.ray.origin) * r.inv_dir;
    let t1 = (Vec3::from(node.max) - r.ray.origin) * r.inv_dir;
    let near =
        t0.x.min(t1.x)
            .max(t0.y.min(t1.y))
            .max(t0.z.min(t1.z).max(0.0));
    let far = t0.x.max(t1.x).min(t0.y.max(t1.y)).min(t0.z.max(t1.z)) * BOX_SLACK;
    if near <= far.min(widened(t_max)) {
        return near;
    }
    NO_HIT
}

pub fn hit_primitive(geometry: &Geometry, reference: u32, r: &BvhRay) -> f32 {
    let kind = reference >> PRIMITIVE_KIND_SHIFT;
    let index = (reference & PRIMITIVE_INDEX_MASK) as usize;
    if kind == PRIMITIVE_TRIANGLE {
        return hit_triangle(&geometry.triangles[index], &r.tri);
    }
    if kind == PRIMITIVE_QUAD {
        return hit_quad(&geometry.quads[index], &r.ray);
    }
    hit_sphere(&geometry.spheres[index], &r.ray)
}

/// The closest primitive through the BVH. With `shadow_target` not [`NO_PRIMITIVE`], it is a
/// shadow ray's test instead: `t_max` is the target's distance, and the first other primitive
/// nearer than that ends the search (returned with its t); none found returns t = `NO_HIT`.
pub fn bvh_traverse(
    geometry: &Geometry,
    r: &BvhRay,
    t_max: f32,
    shadow_target: u32,
) -> ClosestPrimitive {
    let nodes = geometry.bvh_nodes;
    let mut best = ClosestPrimitive {
        t: t_max,
        primitive: PRIMITIVE_QUAD,
        index: 0,
    };
    let mut found = false;
    // Node indices only, as the kernel keeps them: a popped node's entry distance is
    // recomputed by the same arithmetic, so the decision is the same.
    let mut stack = [0u32; BVH_STACK_SIZE];
    let mut top = 0usize;
    let mut node_index = 0usize;
    if hit_box(&nodes[0], r, best.t) == NO_HIT {
        return ClosestPrimitive {
            t: NO_HIT,
            primitive: PRIMITIVE_QUAD,
            index: 0,
        };
    }
    loop {
        let node = &nodes[node_index];
        if node.count > 0 {
            for i in 0..node.count {
                let reference = geometry.bvh_primitives[(node.first + i) as usize];
                let t = hit_primitive(geometry, reference, r);
                if t < best.t && reference != shadow_target {
                    best = ClosestPrimitive {
                        t,
                        primitive: reference >> PRIMITIVE_KIND_SHIFT,
                        index: reference & PRIMITIVE_INDEX_MASK,
                    };
                    found = true;
                    if shadow_target != NO_PRIMITIVE {
                        return best;
                    }
                }
            }
        } else {
            let left = node.first;
            let t_left = hit_box(&nodes[left as usize], r, best.t);
            let t_right = hit_box(&nodes[left as usize + 1], r, best.t);
            if t_left != NO_HIT && t_right != NO_HIT {
                let left_first = t_left <= t_right;
                stack[top] = if left_first { left + 1 } else { left };
                top += 1;
                node_index = if left_first { left } else { left + 1 } as usize;
                continue;
            }
            if t_left != NO_HIT {
                node_index = left as usize;
                continue;
            }
            if t_right != NO_HIT {
                node_index = left as usize + 1;
                continue;
            }
        }
        // Pop the next node that may still hold something nearer than the best hit.
        let mut popped = false;
        while top > 0 {
            top -= 1;
            if hit_box(&nodes[stack[top] as usize], r, best.t) != NO_HIT {
                node_index = stack[top] as usize;
                popped = true;
                break;
            }
        }
        if !popped {
            break;
        }
    }
    if !found {
        best.t = NO_HIT;
    }
    best
}

pub fn bvh_closest_primitive(geometry: &Geometry, ray: &Ray) -> ClosestPrimitive {
    bvh_traverse(geometry, &bvh_ray(ray), NO_HIT, NO_PRIMITIVE)
}

/// Whether `ray` hits nothing: a shadow-ray search for any hit, with no target.
pub fn bvh_escapes(geometry: &Geometry, ray: &Ray) -> bool {
    let no_target = PRIMITIVE_ENVIRONMENT << PRIMITIVE_KIND_SHIFT;
    bvh_traverse(geometry, &bvh_ray(ray), NO_HIT, no_target).t == NO_HIT
}

pub fn bvh_first_hit_is(geometry: &Geometry, ray: &Ray, primitive: u32, index: u32) -> bool {
    let r = bvh_ray(ray);
    let target = (primitive << PRIMITIVE_KIND_SHIFT) | index;
    let t_target = hit_primitive(geometry, target, &r);
    if t_target == NO_HIT {
        return false;
    }
    bvh_traverse(geometry, &r, t_target, target).t == NO_HIT
}
