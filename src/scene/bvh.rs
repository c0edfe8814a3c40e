//! The BVH over every primitive (spheres, quads and triangles), built with the `obvhs` crate
//! (PLOC, then reinsertion and leaf collapsing by the surface area heuristic) and flattened
//! into the compact node array that the kernel (`shaders/bvh.wgsl`) and the CPU mirror
//! (`src/cpu/bvh.rs`) traverse.

use crate::cpu::bvh::BVH_STACK_SIZE;
use crate::shader_types::{
    BvhNode, Quad, Sphere, Triangle, PRIMITIVE_INDEX_MASK, PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD,
    PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE,
};
use glam::Vec3;
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::BvhBuildParams;
use std::time::{Duration, Instant};

/// Scenes with at most this many spheres and quads and no triangles keep the linear scan (and
/// the uniform-buffer kernel): for a handful of primitives, testing them all beats any tree.
pub const BVH_MIN_PRIMITIVES: usize = 64;

/// The most primitives a BVH can reference: the index takes the low 30 bits of a reference.
pub const MAX_PRIMITIVES: usize = PRIMITIVE_INDEX_MASK as usize;

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// What the leaves hold: the primitive's kind in the top two bits, its index below.
    pub primitives: Vec<u32>,
    /// Nodes on the longest root-to-leaf path.
    pub depth: usize,
    pub build_seconds: f64,
}

fn aabb(min: Vec3, max: Vec3) -> Aabb {
    Aabb::new(min.to_array().into(), max.to_array().into())
}

fn primitive_boxes(spheres: &[Sphere], quads: &[Quad], triangles: &[Triangle]) -> Vec<Aabb> {
    let mut boxes = Vec::with_capacity(spheres.len() + quads.len() + triangles.len());
    for s in spheres {
        let c = Vec3::from(s.center);
        boxes.push(aabb(c - s.radius, c + s.radius));
    }
    for q in quads {
        let p = Vec3::from(q.corner);
        let (u, v) = (Vec3::from(q.edge_u), Vec3::from(q.edge_v));
        let corners = [p, p + u, p + v, p + u + v];
        let min = corners.iter().fold(Vec3::INFINITY, |a, &b| a.min(b));
        let max = corners.iter().fold(Vec3::NEG_INFINITY, |a, &b| a.max(b));
        boxes.push(aabb(min, max));
    }
    for t in triangles {
        let (a, b, c) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
        boxes.push(aabb(a.min(b).min(c), a.max(b).max(c)));
    }
    boxes
}

/// The reference a leaf stores for the i-th primitive in [`primitive_boxes`]' order.
fn reference(i: usize, spheres: usize, quads: usize) -> u32 {
    let (kind, index) = if i < spheres {
        (PRIMITIVE_SPHERE, i)
    } else if i < spheres + quads {
        (PRIMITIVE_QUAD, i - spheres)
    } else {
        (PRIMITIVE_TRIANGLE, i - spheres - quads)
    };
    (kind << PRIMITIVE_KIND_SHIFT) | index as u32
}

/// The traversal stack's length in the kernel for the tree `nodes` (laid out by [`build`]):
/// one entry per level below the root, which is the most it can hold at once (the entries'
/// levels strictly increase from the bottom of the stack up), rounded up to a multiple of 8 so
/// that few kernels need compiling, and at most the [`BVH_STACK_SIZE`] the host allows.
/// Why not always the maximum: lavapipe keeps the stack in memory per lane, and sized this way
/// it measured 1.4× faster on meshes of 10³ and 10⁵ triangles, 7% on the bunny
/// (BENCHMARKS.md).
pub fn kernel_stack_size(nodes: &[BvhNode]) -> u32 {
    // Breadth first: a node's children come after it, so one pass finds every level.
    let mut level = vec![0u32; nodes.len()];
    let mut deepest = 0;
    for (i, node) in nodes.iter().enumerate() {
        if node.count == 0 {
            let first = node.first as usize;
            level[first] = level[i] + 1;
            level[first + 1] = level[i] + 1;
            deepest = deepest.max(level[i] + 1);
        }
    }
    deepest
        .div_ceil(8)
        .max(1)
        .saturating_mul(8)
        .min(BVH_STACK_SIZE as u32)
}

/// Whether a scene gets a BVH rather than the linear scan.
pub fn wants_bvh(spheres: usize, quads: usize, triangles: usize) -> bool {
    triangles > 0 || spheres + quads > BVH_MIN_PRIMITIVES
}

/// Builds the BVH over all primitives (there must be at least one). Errors name what is over
/// a limit: more primitives than references can hold, or a tree deeper than the kernel's stack.
pub fn build(spheres: &[Sphere], quads: &[Quad], triangles: &[Triangle]) -> Result<Bvh, String> {
    let start = Instant::now();
    let count = spheres.len() + quads.len() + triangles.len();
    if count > MAX_PRIMITIVES {
        return Err(format!(
            "{count} primitives are more than the BVH can reference (at most {MAX_PRIMITIVES})"
        ));
    }
    let boxes = primitive_boxes(spheres, quads, triangles);
    let mut core_time = Duration::ZERO;
    let tree = build_bvh2(&boxes, BvhBuildParams::medium_build(), &mut core_time);
    // Re-laid out breadth first, each inner node's two children side by side: the layout the
    // kernel reads, independent of how the builder stores its nodes.
    let mut nodes: Vec<BvhNode> = Vec::with_capacity(tree.nodes.len());
    let mut primitives: Vec<u32> = Vec::with_capacity(count);
    let mut source: Vec<(usize, usize)> = vec![(0, 1)];
    let mut depth = 0;
    let mut i = 0;
    nodes.push(BvhNode::default());
    while i < source.len() {
        let (from, node_depth) = source[i];
        depth = depth.max(node_depth);
        let node = &tree.nodes[from];
        let mut out = BvhNode {
            min: node.aabb.min.to_array(),
            max: node.aabb.max.to_array(),
            ..Default::default()
        };
        if node.prim_count > 0 {
            out.first = primitives.len() as u32;
            out.count = node.prim_count;
            let range = node.first_index as usize..(node.first_index + node.prim_count) as usize;
            primitives.extend(
                tree.primitive_indices[range]
                    .iter()
                    .map(|&p| reference(p as usize, spheres.len(), quads.len())),
            );
        } else {
            out.first = nodes.len() as u32;
            nodes.push(BvhNode::default());
            nodes.push(BvhNode::default());
            source.push((node.first_index as usize, node_depth + 1));
            source.push((node.first_index as usize + 1, node_depth + 1));
        }
        nodes[i] = out;
        i += 1;
    }
    // The traversal stack holds at most one node per level below the root.
    if depth > BVH_STACK_SIZE {
        return Err(format!(
            "the BVH is {depth} levels deep, more than the kernel's traversal stack ({BVH_STACK_SIZE})"
        ));
    }
    Ok(Bvh {
        nodes,
        primitives,
        depth,
        build_seconds: start.elapsed().as_secs_f64(),
    })
}
