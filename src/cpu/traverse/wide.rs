//! 4-wide BVH traversal (WGSL side: `shaders/traverse/wide.wgsl`), over the tree
//! `src/kernel/bvh/wide.rs` collapses from the binary one. The meaning and the arguments are
//! `bvh_traverse`'s (`src/cpu/traverse/bvh.rs`), and so are the leaves' tests and bookkeeping
//! (`hit_primitive`, `hit_comes_first`, the leaf-entry pruning): only the inner nodes differ.
//! A node's four boxes are tested at once, and its children are pushed farthest first, so
//! the nearest is visited next; entries popped beyond the best hit so far are skipped.

use crate::cpu::geometry::hit::{hit_comes_first, ClosestPrimitive, NO_HIT};

use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::traverse::bvh_ray::{hit_primitive, widened, BvhRay, BOX_SLACK, NO_PRIMITIVE};
use crate::kernel::bvh::wide::WIDE_STACK_SIZE;
use crate::kernel::types::{
    BvhWideNode, NO_INSTANCE, PRIMITIVE_INDEX_MASK, PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD,
    WIDE_EMPTY_CHILD,
};
use glam::{BVec4A, Vec4};

/// Where the ray enters each of the node's four child boxes (0 when it starts inside), or
/// `NO_HIT` where it misses the box, enters it beyond `t_max`, or the slot holds no child.
/// Each child's is `hit_box`'s arithmetic (src/cpu/traverse/bvh.rs), on four boxes at once: the same
/// IEEE operations, and no NaN can arise (inv_dir is finite and non-zero).
pub fn hit_wide_boxes(node: &BvhWideNode, r: &BvhRay, t_max: f32) -> Vec4 {
    let slab = |min: [f32; 4], max: [f32; 4], origin: f32, inv: f32| {
        let t0 = (Vec4::from(min) - origin) * inv;
        let t1 = (Vec4::from(max) - origin) * inv;
        (t0.min(t1), t0.max(t1))
    };
    let (near_x, far_x) = slab(node.min_x, node.max_x, r.origin.x, r.inv_dir.x);
    let (near_y, far_y) = slab(node.min_y, node.max_y, r.origin.y, r.inv_dir.y);
    let (near_z, far_z) = slab(node.min_z, node.max_z, r.origin.z, r.inv_dir.z);
    let near = near_x.max(near_y).max(near_z.max(Vec4::ZERO));
    let far = far_x.min(far_y).min(far_z) * BOX_SLACK;
    let present = BVec4A::from_array(node.count.map(|c| c != WIDE_EMPTY_CHILD));
    let hit = near.cmple(far.min(Vec4::splat(widened(t_max)))) & present;
    Vec4::select(hit, near, Vec4::splat(NO_HIT))
}

/// The four slots ordered by their entry distance `t`, farthest first (misses, at `NO_HIT`,
/// before all): a sorting network over keys holding t's bits with the slot in the low two,
/// which t ≥ 0 orders as floats. Only the visit order rests on it, never a decision.
pub fn farthest_first(t: Vec4) -> [u32; 4] {
    let key = |s: usize| (t[s].to_bits() & !3) | s as u32;
    let (k0, k1, k2, k3) = (key(0), key(1), key(2), key(3));
    let (a, b) = (k0.max(k1), k0.min(k1));
    let (c, d) = (k2.max(k3), k2.min(k3));
    let (a, c) = (a.max(c), a.min(c));
    let (b, d) = (b.max(d), b.min(d));
    let (b, c) = (b.max(c), b.min(c));
    [a & 3, b & 3, c & 3, d & 3]
}

/// `bvh_traverse` (src/cpu/traverse/bvh.rs) through the wide tree: the same results, bit for bit.
pub fn wide_traverse(
    geometry: &Geometry,
    r: &BvhRay,
    t_max: f32,
    t_prune: f32,
    max_reference: u32,
    shadow_target: u32,
) -> ClosestPrimitive {
    let nodes = geometry.bvh_wide_nodes;
    let mut best = ClosestPrimitive {
        t: t_max,
        primitive: PRIMITIVE_QUAD,
        index: 0,
        instance: NO_INSTANCE,
    };
    let mut best_reference = max_reference;
    let mut prune = t_prune;
    let mut found = false;
    // Children left for later: their first and count (0 for an inner node), and where the ray
    // enters their box. The root is entered from 0: its children's boxes are tested instead.
    let mut stack = [(0u32, 0u32, 0f32); WIDE_STACK_SIZE];
    let mut top = 1usize;
    while top > 0 {
        top -= 1;
        let (first, count, node_entry) = stack[top];
        if node_entry > widened(prune) {
            continue;
        }
        if count == 0 {
            let node = &nodes[first as usize];
            let t = hit_wide_boxes(node, r, prune);
            for slot in farthest_first(t) {
                let s = slot as usize;
                if t[s] != NO_HIT {
                    stack[top] = (node.first[s], node.count[s], t[s]);
                    top += 1;
                }
            }
            continue;
        }
        for i in first..first + count {
            let reference = geometry.bvh_primitives[i as usize];
            let t = hit_primitive(geometry, reference, r);
            // The target is excluded by name too, as in bvh_traverse.
            if hit_comes_first(t, reference, best.t, best_reference) && reference != shadow_target {
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
    }
    if !found {
        best.t = NO_HIT;
    }
    best
}
