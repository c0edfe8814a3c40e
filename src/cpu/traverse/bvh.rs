//! BVH traversal (WGSL side: `shaders/traverse/bvh.wgsl`). One BVH over every sphere, quad, triangle
//! and instance, built on the host (`src/kernel/bvh/mod.rs`) and flattened into `bvh_nodes`; an
//! instance's leaf entry walks its mesh's own BVH (`src/cpu/traverse/blas.rs`). A fixed stack, the
//! nearer child first, and popped nodes skipped when they start beyond the closest hit so far.
//! Shadow rays stop at the first primitive in front of the one they aim at. Which hit is the
//! closest, and which primitives are in front, is the closest-hit rule's
//! ([`hit_comes_first`]), whatever the order of visits. The tests the walks share are in
//! `bvh_ray.rs`.

use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::hit::{hit_comes_first, ClosestPrimitive, NO_HIT};
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::traverse::blas::hit_instance;
use crate::cpu::traverse::bvh_ray::bvh_ray;
use crate::cpu::traverse::bvh_ray::hit_box;
use crate::cpu::traverse::bvh_ray::hit_primitive;
use crate::cpu::traverse::bvh_ray::primitive_box_entry;
use crate::cpu::traverse::bvh_ray::widened;
use crate::cpu::traverse::bvh_ray::BvhRay;
use crate::cpu::traverse::bvh_ray::NO_PRIMITIVE;
use crate::cpu::traverse::wide::wide_traverse;
use crate::kernel::types::{
    NO_INSTANCE, PRIMITIVE_INDEX_MASK, PRIMITIVE_INSTANCE, PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD,
    PRIMITIVE_TRIANGLE,
};

use crate::kernel::bvh::BVH_STACK_SIZE;

/// The closest primitive through the BVH that comes before the bound (`t_max`,
/// `max_reference`) by the closest-hit rule ([`hit_comes_first`]); a closest-hit search passes
/// (`NO_HIT`, 0), which no miss comes before. With `shadow_target` not [`NO_PRIMITIVE`], it is
/// a shadow ray's test instead: the bound is the target's hit, and the first other primitive
/// before it ends the search (returned with its t); none found returns t = `NO_HIT`.
///
/// Boxes are skipped when the ray enters them beyond `t_prune` (at least `t_max`), and once a
/// hit is found, beyond its t or, if later, where the ray enters the box of the leaf it is in.
/// Rounding can put a primitive's t a few ulps before its own box's entry, so a copy of it
/// (hit at the same t, and coming before it by the rule) in a box of its own, the same box,
/// must be compared against that entry, not the t, or it would be skipped.
pub fn bvh_traverse(
    geometry: &Geometry,
    r: &BvhRay,
    t_max: f32,
    t_prune: f32,
    max_reference: u32,
    shadow_target: u32,
) -> ClosestPrimitive {
    // The wide tree where the CPU's layout is wide (src/kernel/bvh/layout.rs).
    if !geometry.bvh_wide_nodes.is_empty() {
        return wide_traverse(geometry, r, t_max, t_prune, max_reference, shadow_target);
    }
    let nodes = geometry.bvh_nodes;
    let mut best = ClosestPrimitive {
        t: t_max,
        primitive: PRIMITIVE_QUAD,
        index: 0,
        instance: NO_INSTANCE,
    };
    let mut best_reference = max_reference;
    let mut prune = t_prune;
    let mut found = false;
    let root = &nodes[0];
    // Where the ray enters the node being entered.
    let mut node_entry = hit_box(root, r, prune);
    if node_entry == NO_HIT {
        return ClosestPrimitive {
            t: NO_HIT,
            primitive: PRIMITIVE_QUAD,
            index: 0,
            instance: NO_INSTANCE,
        };
    }
    // The node being entered, as its first and count, read with its box when its parent was
    // visited. The kernel reads the node again instead, and keeps only node indices on its
    // stack, redoing a popped node's box test: on lavapipe, per-lane memory costs more than
    // that arithmetic, and carrying first and count measured no faster (BENCHMARKS.md). The
    // decisions are the same: a popped node's entry distance has not changed, only the bound
    // can have shrunk.
    let (mut first, mut count) = (root.first, root.count);
    // Far children left for later: what entering them needs, and where the ray enters their box.
    let mut stack = [(0u32, 0u32, 0f32); BVH_STACK_SIZE];
    let mut top = 0usize;
    loop {
        if count > 0 {
            for i in first..first + count {
                let reference = geometry.bvh_primitives[i as usize];
                if reference >> PRIMITIVE_KIND_SHIFT == PRIMITIVE_INSTANCE {
                    // Its closest triangle that comes before the best so far: at the same t
                    // only if this reference is the lower (the rule, extended by triangle).
                    let instance = reference & PRIMITIVE_INDEX_MASK;
                    let h = hit_instance(
                        geometry,
                        instance,
                        &r.ray,
                        best.t,
                        reference < best_reference,
                        prune,
                        shadow_target != NO_PRIMITIVE,
                    );
                    if h.t != NO_HIT {
                        best = ClosestPrimitive {
                            t: h.t,
                            primitive: PRIMITIVE_TRIANGLE,
                            index: h.triangle,
                            instance,
                        };
                        best_reference = reference;
                        prune = h.prune.max(node_entry);
                        found = true;
                        if shadow_target != NO_PRIMITIVE {
                            return best;
                        }
                    }
                    continue;
                }
                let t = hit_primitive(geometry, reference, r);
                // The target is excluded by name too, not only by the rule: a shader compiler
                // may round its test here and in `bvh_first_hit_is` differently.
                if hit_comes_first(t, reference, best.t, best_reference)
                    && reference != shadow_target
                {
                    best = ClosestPrimitive {
                        t,
                        primitive: reference >> PRIMITIVE_KIND_SHIFT,
                        index: reference & PRIMITIVE_INDEX_MASK,
                        instance: NO_INSTANCE,
                    };
                    best_reference = reference;
                    prune = t.max(node_entry);
                    found = true;
                    if shadow_target != NO_PRIMITIVE {
                        return best;
                    }
                }
            }
        } else {
            let left = &nodes[first as usize];
            let right = &nodes[first as usize + 1];
            let t_left = hit_box(left, r, prune);
            let t_right = hit_box(right, r, prune);
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
        // Pop the next node that may still hold something before the best hit.
        let mut popped = false;
        while top > 0 {
            top -= 1;
            let (node_first, node_count, t_entry) = stack[top];
            if t_entry <= widened(prune) {
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

pub fn bvh_closest_primitive(geometry: &Geometry, ray: &Ray) -> ClosestPrimitive {
    bvh_traverse(geometry, &bvh_ray(ray), NO_HIT, NO_HIT, 0, NO_PRIMITIVE)
}

/// A shadow target no leaf holds: [`bvh_escapes`]' search for any hit. Not a kind's first
/// reference (`PRIMITIVE_INSTANCE << PRIMITIVE_KIND_SHIFT` is instance 0's), but the last one
/// below [`NO_PRIMITIVE`], which no scene has that many instances to reach.
pub const NO_TARGET: u32 = u32::MAX - 1;

/// Whether `ray` hits nothing: a shadow-ray search for any hit, with no target.
pub fn bvh_escapes(geometry: &Geometry, ray: &Ray) -> bool {
    bvh_traverse(geometry, &bvh_ray(ray), NO_HIT, NO_HIT, 0, NO_TARGET).t == NO_HIT
}

pub fn bvh_first_hit_is(geometry: &Geometry, ray: &Ray, primitive: u32, index: u32) -> bool {
    let r = bvh_ray(ray);
    let target = (primitive << PRIMITIVE_KIND_SHIFT) | index;
    let t_target = hit_primitive(geometry, target, &r);
    if t_target == NO_HIT {
        return false;
    }
    // Pruned no earlier than where the ray enters the target's own box: a primitive before it
    // at the same t, a copy of it, is in a box the same as that one.
    let t_prune = t_target.max(primitive_box_entry(geometry, target, &r));
    bvh_traverse(geometry, &r, t_target, t_prune, target, target).t == NO_HIT
}
