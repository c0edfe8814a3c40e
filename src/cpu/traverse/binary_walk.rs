//! The walk of a binary BVH that both levels of the two-level structure take: the top level
//! (`bvh.rs`) and an instance's own BVH (`blas.rs`). A fixed stack, the nearer child first,
//! and popped nodes skipped when they start beyond the bound. What a leaf does is the caller's.
//! The kernel has no closures, so `shaders/traverse/binary_walk.wgsl` gives its callers the
//! walk's steps (start, descend, pop) and each keeps its leaf's visit in its own loop; their
//! decisions are this one's.

use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::traverse::bvh_ray::{hit_box, widened, BvhRay};
use crate::kernel::bvh::BVH_STACK_SIZE;
use crate::kernel::types::BvhNode;

/// What a leaf's visit asks of the walk.
pub enum LeafVisit {
    Continue,
    /// The search is over (a shadow ray found something in front of its target).
    Stop,
}

/// Walks the binary BVH in `nodes` from `root`, visiting boxes that the ray enters no later
/// than the bound `prune` (popped ones against it widened by the box slack). `leaf(first,
/// count, entry, &mut prune)` is called for each leaf reached, with its primitives' range and
/// where the ray enters its box, and may tighten `prune` as it finds hits.
pub fn walk_binary_bvh(
    nodes: &[BvhNode],
    root: usize,
    r: &BvhRay,
    mut prune: f32,
    mut leaf: impl FnMut(u32, u32, f32, &mut f32) -> LeafVisit,
) {
    let root = &nodes[root];
    // Where the ray enters the node being entered.
    let mut node_entry = hit_box(root, r, prune);
    if node_entry == NO_HIT {
        return;
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
            if let LeafVisit::Stop = leaf(first, count, node_entry, &mut prune) {
                return;
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
        // Pop the next node that may still hold something before the bound.
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
            return;
        }
    }
}
