// The walk of a binary BVH that both levels of the two-level structure take (mirror:
// src/cpu/traverse/binary_walk.rs): the top level (bvh.wgsl) and an instance's own BVH
// (blas.wgsl). A fixed stack, the nearer child first, and popped nodes skipped when they start
// beyond the bound. WGSL has no closures, so the walk is steps its callers' loop takes, and
// what a leaf does stays in that loop:
//
//     if binary_walk_start(&walk, root, r, prune) {
//         loop {
//             let node = bvh_node(walk.node_index);
//             if node.count > 0u {
//                 // the leaf's primitives, node.first .. node.first + node.count
//             } else if binary_walk_descend(&walk, node, r, prune) {
//                 continue;
//             }
//             if !binary_walk_pop(&walk, r, prune) {
//                 break;
//             }
//         }
//     }
//
// That loop makes one iteration per node visited and the pop one per stack entry, as
// loop_iterations_per_ray (src/gpu/loop_budget.rs) counts.

struct BinaryWalk {
    // Node indices only: a popped node's entry distance is recomputed (the same arithmetic,
    // so the same decision), which halves the per-lane stack lavapipe keeps in memory.
    stack: array<u32, BVH_STACK_SIZE>,
    top: u32,
    // The node being entered, and where the ray enters its box.
    node_index: u32,
    node_entry: f32,
}

// Enters root; false when the ray misses its box or enters it beyond the bound prune.
fn binary_walk_start(walk: ptr<function, BinaryWalk>, root: u32, r: BvhRay, prune: f32) -> bool {
    (*walk).top = 0u;
    (*walk).node_index = root;
    (*walk).node_entry = hit_box(bvh_node(root), r, prune);
    return (*walk).node_entry != NO_HIT;
}

// Enters the nearer of inner node `node`'s children whose boxes the ray enters before prune,
// pushing the farther when it enters both; false when it enters neither.
fn binary_walk_descend(walk: ptr<function, BinaryWalk>, node: BvhNode, r: BvhRay, prune: f32) -> bool {
    let left = node.first;
    let t_left = hit_box(bvh_node(left), r, prune);
    let t_right = hit_box(bvh_node(left + 1u), r, prune);
    if t_left != NO_HIT && t_right != NO_HIT {
        let left_first = t_left <= t_right;
        (*walk).stack[(*walk).top] = select(left, left + 1u, left_first);
        (*walk).top += 1u;
        (*walk).node_index = select(left + 1u, left, left_first);
        (*walk).node_entry = min(t_left, t_right);
        return true;
    }
    if t_left != NO_HIT {
        (*walk).node_index = left;
        (*walk).node_entry = t_left;
        return true;
    }
    if t_right != NO_HIT {
        (*walk).node_index = left + 1u;
        (*walk).node_entry = t_right;
        return true;
    }
    return false;
}

// Enters the next node on the stack that may still hold something before the bound prune;
// false when none is left and the walk is over.
fn binary_walk_pop(walk: ptr<function, BinaryWalk>, r: BvhRay, prune: f32) -> bool {
    while (*walk).top > 0u {
        (*walk).top -= 1u;
        let node_index = (*walk).stack[(*walk).top];
        let entry = hit_box(bvh_node(node_index), r, prune);
        if entry != NO_HIT {
            (*walk).node_index = node_index;
            (*walk).node_entry = entry;
            return true;
        }
    }
    return false;
}
