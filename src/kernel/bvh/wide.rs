//! The 4-wide BVH: the binary tree (`src/kernel/bvh/mod.rs`) collapsed so that each wide node holds
//! up to four boxes, its binary node's descendants, the inner one of largest surface area
//! opened first (Wald et al., "Getting Rid of Packets", 2008). The boxes are the binary tree's
//! own and the leaves keep their ranges of `bvh_primitives`, so both trees hold the same
//! primitives in the same boxes and the box test's slack guarantees carry over. Traversed by
//! `shaders/traverse/wide.wgsl` and `src/cpu/traverse/wide.rs`.

use crate::kernel::bvh::BVH_STACK_SIZE;
use crate::kernel::types::{BvhNode, BvhWideNode, WIDE_EMPTY_CHILD};
use std::collections::VecDeque;

/// Children per wide node.
pub const WIDTH: usize = 4;

/// The traversal stack's length that suffices for every wide tree the host builds: each level
/// leaves at most `WIDTH - 1` entries on the stack below the one it descends into, and a wide
/// tree has at most as many levels as its binary tree ([`BVH_STACK_SIZE`]).
pub const WIDE_STACK_SIZE: usize = (WIDTH - 1) * BVH_STACK_SIZE + 1;

/// The most wide nodes the kernel can address: a leaf on its stack is its parent's index times
/// four plus its slot, below the top bit (shaders/traverse/wide.wgsl). A binding holds far
/// fewer (lavapipe's 128 MiB are 2²⁰ nodes).
pub const MAX_WIDE_NODES: usize = 1 << 29;

fn area(node: &BvhNode) -> f32 {
    let d = [0, 1, 2].map(|k| node.max[k] - node.min[k]);
    d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
}

/// The wide tree over the binary tree `nodes` (laid out by `bvh::build`: breadth first, an
/// inner node's children at `first` and `first + 1`), laid out breadth first too, so that the
/// top of the tree comes first (the kernel's uniform copy). Empty for an empty tree.
pub fn collapse(nodes: &[BvhNode]) -> Vec<BvhWideNode> {
    if nodes.is_empty() {
        return Vec::new();
    }
    let mut wide = vec![BvhWideNode::default()];
    // (binary node, its wide node's index)
    let mut pending = VecDeque::from([(0usize, 0usize)]);
    while let Some((b, w)) = pending.pop_front() {
        // A binary root that is a leaf becomes the one child of the wide root.
        let mut children: Vec<usize> = if nodes[b].count > 0 {
            vec![b]
        } else {
            let first = nodes[b].first as usize;
            vec![first, first + 1]
        };
        while children.len() < WIDTH {
            let widest = children
                .iter()
                .enumerate()
                .filter(|(_, &c)| nodes[c].count == 0)
                .max_by(|(_, &a), (_, &b)| area(&nodes[a]).total_cmp(&area(&nodes[b])))
                .map(|(k, _)| k);
            let Some(k) = widest else { break };
            let first = nodes[children[k]].first as usize;
            children.splice(k..=k, [first, first + 1]);
        }
        let mut out = BvhWideNode {
            count: [WIDE_EMPTY_CHILD; WIDTH],
            ..Default::default()
        };
        for (slot, &c) in children.iter().enumerate() {
            let node = &nodes[c];
            out.min_x[slot] = node.min[0];
            out.min_y[slot] = node.min[1];
            out.min_z[slot] = node.min[2];
            out.max_x[slot] = node.max[0];
            out.max_y[slot] = node.max[1];
            out.max_z[slot] = node.max[2];
            if node.count > 0 {
                (out.first[slot], out.count[slot]) = (node.first, node.count);
            } else {
                (out.first[slot], out.count[slot]) = (wide.len() as u32, 0);
                pending.push_back((c, wide.len()));
                wide.push(BvhWideNode::default());
            }
        }
        wide[w] = out;
    }
    wide
}

/// The most entries the traversal's stack holds for the tree `wide`: the root's, then at each
/// inner child entered, the siblings still on the stack below what that child pushes.
pub fn stack_entries(wide: &[BvhWideNode]) -> usize {
    // Breadth first: children come after their parents, so walking backwards meets them first.
    let mut need = vec![0usize; wide.len()];
    for (i, node) in wide.iter().enumerate().rev() {
        let children = node
            .count
            .iter()
            .filter(|&&c| c != WIDE_EMPTY_CHILD)
            .count();
        need[i] = (0..WIDTH)
            .filter(|&s| node.count[s] == 0)
            .map(|s| children - 1 + need[node.first[s] as usize])
            .fold(children, usize::max);
    }
    need.first().copied().unwrap_or(1).max(1)
}

/// The kernel's stack length for the tree `wide`: [`stack_entries`] rounded up to a multiple
/// of 8, so that few kernels need compiling, and at most [`WIDE_STACK_SIZE`].
pub fn kernel_stack_size(wide: &[BvhWideNode]) -> u32 {
    (stack_entries(wide).div_ceil(8) * 8).min(WIDE_STACK_SIZE) as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::bvh;
    use crate::kernel::types::Sphere;

    fn sphere(center: [f32; 3], radius: f32) -> Sphere {
        Sphere {
            center,
            radius,
            ..Default::default()
        }
    }

    /// Every leaf of the binary tree is a child of exactly one wide node, with the same box,
    /// every inner wide node's box holds its children's, and the stack suffices.
    fn check(tree: &bvh::Bvh) {
        let wide = collapse(&tree.nodes);
        let mut leaves: Vec<(u32, u32)> = wide
            .iter()
            .flat_map(|n| (0..WIDTH).map(move |s| (n.first[s], n.count[s])))
            .filter(|&(_, c)| c != 0 && c != WIDE_EMPTY_CHILD)
            .collect();
        let mut expected: Vec<(u32, u32)> = tree
            .nodes
            .iter()
            .filter(|n| n.count > 0)
            .map(|n| (n.first, n.count))
            .collect();
        leaves.sort_unstable();
        expected.sort_unstable();
        assert_eq!(leaves, expected);
        for node in &wide {
            for s in (0..WIDTH).filter(|&s| node.count[s] == 0) {
                let child = &wide[node.first[s] as usize];
                for c in (0..WIDTH).filter(|&c| child.count[c] != WIDE_EMPTY_CHILD) {
                    assert!(node.min_x[s] <= child.min_x[c] && child.max_x[c] <= node.max_x[s]);
                    assert!(node.min_y[s] <= child.min_y[c] && child.max_y[c] <= node.max_y[s]);
                    assert!(node.min_z[s] <= child.min_z[c] && child.max_z[c] <= node.max_z[s]);
                }
            }
        }
        assert!(stack_entries(&wide) <= WIDE_STACK_SIZE);
        assert!(kernel_stack_size(&wide) as usize >= stack_entries(&wide));
    }

    #[test]
    fn wide_trees_hold_the_binary_trees_leaves() {
        let grid: Vec<Sphere> = (0..1000)
            .map(|i| {
                sphere(
                    [(i % 10) as f32, (i / 10 % 10) as f32, (i / 100) as f32],
                    0.3,
                )
            })
            .collect();
        check(&bvh::build(&grid, &[], &[]).unwrap());
        check(&bvh::build(&grid[..1], &[], &[]).unwrap());
        let nested: Vec<Sphere> = (0..2000)
            .map(|i| sphere([0.5, -0.25, 0.0], 2.0 - i as f32 * 1e-4))
            .collect();
        check(&bvh::build(&nested, &[], &[]).unwrap());
        let copies = vec![sphere([0.0; 3], 1.0); 2000];
        check(&bvh::build_with_copies(&copies, &[], &[]).unwrap());
    }
}
