//! The bottom level of the two-level structure (WGSL side: `shaders/traverse/blas.wgsl`): an
//! instance in the top-level BVH (`src/cpu/traverse/bvh.rs`) is hit by walking its mesh's own BVH, laid
//! out in `bvh_nodes` after the top level's, with the ray in the mesh's coordinates
//! (`src/cpu/geometry/instance.rs`). The walk is `bvh_traverse`'s, over triangles only, written again
//! as the kernel must (WGSL has no recursion nor function parameters).

use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::alpha::hit_scene_triangle;
use crate::cpu::geometry::hit::{hit_comes_first, NO_HIT};
use crate::cpu::geometry::instance::object_ray;
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::traverse::bvh_ray::{bvh_ray, hit_box, widened};
use crate::kernel::bvh::BVH_STACK_SIZE;
use crate::kernel::types::PRIMITIVE_INDEX_MASK;

/// An instance's closest triangle: its t (`NO_HIT` for none), its index in the triangle
/// arrays, and how far the walk still looked once it had it (max of t and the entry into its
/// leaf), which the top level keeps looking to, for a coincident instance's copy of the hit.
#[derive(Clone, Copy, Debug)]
pub struct InstanceHit {
    pub t: f32,
    pub triangle: u32,
    pub prune: f32,
}

/// The closest of instance `instance`'s triangles along `ray` (in the scene's coordinates)
/// that comes before the best hit so far, at `t_max`: at `t_max` itself only when `ties_win`
/// (the instance's reference is below the best's), and then the lowest triangle, so the rule
/// holds lexicographically on (t, top-level reference, triangle). Boxes beyond `t_prune` are
/// skipped, as in `bvh_traverse`; `any_hit` returns the first such triangle found (shadow
/// rays).
pub fn hit_instance(
    geometry: &Geometry,
    instance: u32,
    ray: &Ray,
    t_max: f32,
    ties_win: bool,
    t_prune: f32,
    any_hit: bool,
) -> InstanceHit {
    let nodes = geometry.bvh_nodes;
    let inst = &geometry.instances[instance as usize];
    let r = bvh_ray(&object_ray(inst, ray));
    let mut best = InstanceHit {
        t: t_max,
        triangle: 0,
        prune: t_prune,
    };
    let mut best_reference = if ties_win { u32::MAX } else { 0 };
    let mut found = false;
    let root = &nodes[inst.blas_root as usize];
    let mut node_entry = hit_box(root, &r, t_prune);
    if node_entry == NO_HIT {
        return InstanceHit {
            t: NO_HIT,
            triangle: 0,
            prune: t_prune,
        };
    }
    let (mut first, mut count) = (root.first, root.count);
    let mut stack = [(0u32, 0u32, 0f32); BVH_STACK_SIZE];
    let mut top = 0usize;
    loop {
        if count > 0 {
            for i in first..first + count {
                let reference = geometry.bvh_primitives[i as usize];
                let triangle = reference & PRIMITIVE_INDEX_MASK;
                let tri = &geometry.triangles[triangle as usize];
                let t = hit_scene_triangle(&geometry.alpha, triangle, tri, &r.tri);
                if hit_comes_first(t, reference, best.t, best_reference) {
                    best = InstanceHit {
                        t,
                        triangle,
                        prune: t.max(node_entry),
                    };
                    best_reference = reference;
                    found = true;
                    if any_hit {
                        return best;
                    }
                }
            }
        } else {
            let left = &nodes[first as usize];
            let right = &nodes[first as usize + 1];
            let t_left = hit_box(left, &r, best.prune);
            let t_right = hit_box(right, &r, best.prune);
            if t_left != NO_HIT && t_right != NO_HIT {
                let (near, far, t_near, t_far) = if t_left <= t_right {
                    (left, right, t_left, t_right)
                } else {
                    (right, left, t_right, t_left)
                };
                stack[top] = (far.first, far.count, t_far);
                top += 1;
                (first, count, node_entry) = (near.first, near.count, t_near);
                continue;
            }
            if t_left != NO_HIT {
                (first, count, node_entry) = (left.first, left.count, t_left);
                continue;
            }
            if t_right != NO_HIT {
                (first, count, node_entry) = (right.first, right.count, t_right);
                continue;
            }
        }
        let mut popped = false;
        while top > 0 {
            top -= 1;
            let (node_first, node_count, t_entry) = stack[top];
            if t_entry <= widened(best.prune) {
                (first, count, node_entry) = (node_first, node_count, t_entry);
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
