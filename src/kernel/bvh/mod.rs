//! The BVH over every primitive (spheres, quads and triangles), built with the `obvhs` crate
//! (PLOC, then reinsertion and leaf collapsing by the surface area heuristic) and flattened
//! into the compact node array that the kernel (`shaders/traverse/bvh.wgsl`) and the CPU mirror
//! (`src/cpu/traverse/bvh.rs`) traverse.

pub mod layout;
pub mod wide;

use crate::kernel::types::{
    BvhNode, Quad, Sphere, Triangle, PRIMITIVE_INDEX_MASK, PRIMITIVE_INSTANCE,
    PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD, PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE,
};
use glam::Vec3;
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::BvhBuildParams;
use std::time::{Duration, Instant};

/// The traversal stack's length on both devices: enough for any tree the host builds, as it
/// bounds every tree's depth by this.
pub const BVH_STACK_SIZE: usize = 64;

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

impl Bvh {
    /// The tree collapsed 4 wide (`bvh_wide.rs`), or none (empty) where it has more nodes than
    /// the wide traversal can address; the binary tree then serves every device.
    pub fn wide_nodes(&self) -> Vec<crate::kernel::types::BvhWideNode> {
        if self.nodes.len() > crate::kernel::bvh::wide::MAX_WIDE_NODES {
            return Vec::new();
        }
        crate::kernel::bvh::wide::collapse(&self.nodes)
    }
}

fn aabb(min: Vec3, max: Vec3) -> Aabb {
    Aabb::new(min.to_array().into(), max.to_array().into())
}

fn primitive_boxes(
    spheres: &[Sphere],
    quads: &[Quad],
    triangles: &[Triangle],
    instances: &[(Vec3, Vec3)],
) -> Vec<Aabb> {
    let mut boxes =
        Vec::with_capacity(spheres.len() + quads.len() + triangles.len() + instances.len());
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
    boxes.extend(instances.iter().map(|&(min, max)| aabb(min, max)));
    boxes
}

/// The reference a leaf stores for the i-th primitive in [`primitive_boxes`]' order.
fn reference(i: usize, spheres: usize, quads: usize, triangles: usize) -> u32 {
    let (kind, index) = if i < spheres {
        (PRIMITIVE_SPHERE, i)
    } else if i < spheres + quads {
        (PRIMITIVE_QUAD, i - spheres)
    } else if i < spheres + quads + triangles {
        (PRIMITIVE_TRIANGLE, i - spheres - quads)
    } else {
        (PRIMITIVE_INSTANCE, i - spheres - quads - triangles)
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

/// The most levels a median split ([`Source::Split`]) makes, its first node included, over
/// fewer than 2³⁰ primitives (the most references can hold): halving 2³⁰ takes 30 splits.
const MEDIAN_SPLIT_LEVELS: usize = 31;

/// A median split's leaves hold at most this many primitives, unless they all share one
/// centroid (then no split separates them).
const MEDIAN_SPLIT_LEAF: usize = 4;

/// What a node of the laid-out tree is made from.
enum Source {
    /// A node of the tree `obvhs` built.
    Tree(usize),
    /// These primitives (indices into the boxes the tree was built over), split at the median
    /// along the widest axis of their centroids: a subtree of bounded depth in place of one of
    /// the builder's that is too deep (as it makes over many coincident primitives).
    Split(Vec<u32>),
}

/// Levels in the subtree under each node of `tree` (1 for a leaf).
fn subtree_levels(tree: &obvhs::bvh2::Bvh2) -> Vec<usize> {
    let mut order = Vec::with_capacity(tree.nodes.len());
    let mut pending = vec![0usize];
    while let Some(n) = pending.pop() {
        order.push(n);
        let node = &tree.nodes[n];
        if node.prim_count == 0 {
            pending.push(node.first_index as usize);
            pending.push(node.first_index as usize + 1);
        }
    }
    // Children after their parents in `order`, so walking it backwards meets them first.
    let mut levels = vec![0usize; tree.nodes.len()];
    for &n in order.iter().rev() {
        let node = &tree.nodes[n];
        levels[n] = if node.prim_count > 0 {
            1
        } else {
            let first = node.first_index as usize;
            1 + levels[first].max(levels[first + 1])
        };
    }
    levels
}

/// The primitives under node `n` of `tree`, as indices into the boxes it was built over.
fn subtree_primitives(tree: &obvhs::bvh2::Bvh2, n: usize) -> Vec<u32> {
    let mut out = Vec::new();
    let mut pending = vec![n];
    while let Some(n) = pending.pop() {
        let node = &tree.nodes[n];
        if node.prim_count > 0 {
            let first = node.first_index as usize;
            out.extend_from_slice(&tree.primitive_indices[first..first + node.prim_count as usize]);
        } else {
            pending.push(node.first_index as usize);
            pending.push(node.first_index as usize + 1);
        }
    }
    out
}

/// The primitives the tree holds, in the closest-hit rule's order (spheres, quads, triangles):
/// all but exact copies, each of which is left out after its first. A copy (the same geometry,
/// bit for bit, whatever its material) is hit at the same t as its first, which comes before it
/// by the rule (`hit_comes_first` in src/cpu/geometry/intersect.rs), so no ray can see it; a shadow
/// ray aimed at one finds the first in front of it. Scenes exported from CAD tools often hold
/// thousands of copies of an object in place, which would otherwise all be tested.
fn distinct_primitives(spheres: &[Sphere], quads: &[Quad], triangles: &[Triangle]) -> Vec<u32> {
    fn bits<const N: usize>(values: [f32; N]) -> [u32; N] {
        values.map(f32::to_bits)
    }
    fn first_copies<K: Eq + std::hash::Hash + Copy>(
        keys: impl Iterator<Item = K>,
        offset: usize,
    ) -> Vec<u32> {
        let mut seen = std::collections::HashSet::new();
        keys.enumerate()
            .filter(|(_, key)| seen.insert(*key))
            .map(|(i, _)| (offset + i) as u32)
            .collect()
    }
    let mut kept = first_copies(
        spheres
            .iter()
            .map(|s| bits([s.center[0], s.center[1], s.center[2], s.radius])),
        0,
    );
    // Everything hit_quad reads, and the edges the box is made of.
    kept.extend(first_copies(
        quads.iter().map(|q| {
            let vectors = [q.corner, q.edge_u, q.edge_v, q.normal, q.u_dual, q.v_dual];
            (vectors.map(bits), q.plane_offset.to_bits())
        }),
        spheres.len(),
    ));
    kept.extend(first_copies(
        triangles.iter().map(|t| [t.v0, t.v1, t.v2].map(bits)),
        spheres.len() + quads.len(),
    ));
    kept
}

/// Builds the BVH over all primitives (there must be at least one), but exact copies
/// ([`distinct_primitives`]). Its depth is at most [`BVH_STACK_SIZE`] for every input: where
/// the builder's tree goes deeper (over many coincident primitives it makes a chain), the
/// subtree is rebuilt by median splits, which stop at a leaf when the primitives' centroids
/// coincide. Errors name what is over a limit: more primitives than references can hold.
pub fn build(spheres: &[Sphere], quads: &[Quad], triangles: &[Triangle]) -> Result<Bvh, String> {
    build_over(spheres, quads, triangles, &[], true)
}

/// The two-level structure's top: [`build`] over the spheres, quads and triangles placed as
/// they are and the instances, given by their boxes in the scene's coordinates (referenced as
/// `PRIMITIVE_INSTANCE`, after the triangles, each by index; every instance is kept, copies
/// too, since coincident instances are for the closest-hit rule to order).
pub fn build_top_level(
    spheres: &[Sphere],
    quads: &[Quad],
    triangles: &[Triangle],
    instances: &[(Vec3, Vec3)],
) -> Result<Bvh, String> {
    build_over(spheres, quads, triangles, instances, true)
}

/// Builds the bottom level of an instanced mesh, whose triangles are
/// `all_triangles[first_triangle..][..triangles.len()]`, and lays it out after `tree`'s nodes
/// and primitives (its node indices and references made absolute), so one node array and one
/// reference array serve both levels. Returns its root's node index.
pub fn append_bottom_level(
    tree: &mut Bvh,
    triangles: &[Triangle],
    first_triangle: u32,
) -> Result<u32, String> {
    let mesh = build(&[], &[], triangles)?;
    let root = tree.nodes.len() as u32;
    let first_primitive = tree.primitives.len() as u32;
    tree.nodes.extend(mesh.nodes.iter().map(|n| BvhNode {
        first: n.first + if n.count == 0 { root } else { first_primitive },
        ..*n
    }));
    // Triangle references: the kind stays, the index moves to the mesh's place.
    tree.primitives
        .extend(mesh.primitives.iter().map(|&r| r + first_triangle));
    tree.depth = tree.depth.max(mesh.depth);
    tree.build_seconds += mesh.build_seconds;
    Ok(root)
}

/// [`build`] with every primitive in the tree, exact copies too: what tests of the traversal
/// use to meet ties between equally near primitives.
pub fn build_with_copies(
    spheres: &[Sphere],
    quads: &[Quad],
    triangles: &[Triangle],
) -> Result<Bvh, String> {
    build_over(spheres, quads, triangles, &[], false)
}

fn build_over(
    spheres: &[Sphere],
    quads: &[Quad],
    triangles: &[Triangle],
    instances: &[(Vec3, Vec3)],
    without_copies: bool,
) -> Result<Bvh, String> {
    let start = Instant::now();
    let count = spheres.len() + quads.len() + triangles.len() + instances.len();
    if count > MAX_PRIMITIVES {
        return Err(format!(
            "{count} primitives are more than the BVH can reference (at most {MAX_PRIMITIVES})"
        ));
    }
    let all_boxes = primitive_boxes(spheres, quads, triangles, instances);
    let kept = if without_copies {
        let mut kept = distinct_primitives(spheres, quads, triangles);
        let first_instance = spheres.len() + quads.len() + triangles.len();
        kept.extend((first_instance..count).map(|i| i as u32));
        kept
    } else {
        (0..count as u32).collect()
    };
    let boxes: Vec<Aabb> = kept.iter().map(|&i| all_boxes[i as usize]).collect();
    let centroids: Vec<Vec3> = boxes
        .iter()
        .map(|b| Vec3::from(b.center().to_array()))
        .collect();
    let mut core_time = Duration::ZERO;
    let tree = build_bvh2(&boxes, BvhBuildParams::medium_build(), &mut core_time);
    let levels = subtree_levels(&tree);
    let reference_of = |p: u32| {
        reference(
            kept[p as usize] as usize,
            spheres.len(),
            quads.len(),
            triangles.len(),
        )
    };
    // Re-laid out breadth first, each inner node's two children side by side: the layout the
    // kernel reads, independent of how the builder stores its nodes.
    let mut nodes: Vec<BvhNode> = Vec::with_capacity(tree.nodes.len());
    let mut primitives: Vec<u32> = Vec::with_capacity(kept.len());
    let mut sources = std::collections::VecDeque::from([(Source::Tree(0), 1usize)]);
    let mut depth = 0;
    nodes.push(BvhNode::default());
    let mut i = 0;
    while let Some((source, node_depth)) = sources.pop_front() {
        depth = depth.max(node_depth);
        // A builder's subtree that would go deeper than the stack is split by median instead,
        // as late as that still fits: from one level further down it might not.
        let source = match source {
            Source::Tree(n)
                if node_depth + levels[n] - 1 > BVH_STACK_SIZE
                    && node_depth + MEDIAN_SPLIT_LEVELS > BVH_STACK_SIZE =>
            {
                Source::Split(subtree_primitives(&tree, n))
            }
            source => source,
        };
        let mut out = BvhNode::default();
        let children = match source {
            Source::Tree(n) => {
                let node = &tree.nodes[n];
                (out.min, out.max) = (node.aabb.min.to_array(), node.aabb.max.to_array());
                if node.prim_count > 0 {
                    let first = node.first_index as usize;
                    let range = first..first + node.prim_count as usize;
                    out.first = primitives.len() as u32;
                    out.count = node.prim_count;
                    primitives.extend(
                        tree.primitive_indices[range]
                            .iter()
                            .map(|&p| reference_of(p)),
                    );
                    None
                } else {
                    let first = node.first_index as usize;
                    Some((Source::Tree(first), Source::Tree(first + 1)))
                }
            }
            Source::Split(mut members) => {
                let union = members
                    .iter()
                    .fold(Aabb::empty(), |a, &p| a.union(&boxes[p as usize]));
                (out.min, out.max) = (union.min.to_array(), union.max.to_array());
                let (low, high) =
                    members
                        .iter()
                        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(low, high), &p| {
                            (
                                low.min(centroids[p as usize]),
                                high.max(centroids[p as usize]),
                            )
                        });
                let extent = high - low;
                if members.len() <= MEDIAN_SPLIT_LEAF || extent.max_element() <= 0.0 {
                    out.first = primitives.len() as u32;
                    out.count = members.len() as u32;
                    primitives.extend(members.iter().map(|&p| reference_of(p)));
                    None
                } else {
                    let axis = extent.max_position();
                    let middle = members.len() / 2;
                    members.select_nth_unstable_by(middle, |&a, &b| {
                        centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
                    });
                    let high_half = members.split_off(middle);
                    Some((Source::Split(members), Source::Split(high_half)))
                }
            }
        };
        if let Some((left, right)) = children {
            out.first = nodes.len() as u32;
            nodes.push(BvhNode::default());
            nodes.push(BvhNode::default());
            sources.push_back((left, node_depth + 1));
            sources.push_back((right, node_depth + 1));
        }
        nodes[i] = out;
        i += 1;
    }
    // The traversal stack holds at most one node per level below the root; the splits above
    // keep every tree within it.
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

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(center: [f32; 3], radius: f32) -> Sphere {
        Sphere {
            center,
            radius,
            ..Default::default()
        }
    }

    /// Checks what every tree must be: within the traversal stack, each primitive referenced
    /// once (of `expected` in all), and each box holding its children's.
    fn check(tree: &Bvh, expected: usize) {
        assert!(tree.depth <= BVH_STACK_SIZE, "{} levels", tree.depth);
        assert!(kernel_stack_size(&tree.nodes) as usize <= BVH_STACK_SIZE);
        let mut references = tree.primitives.clone();
        references.sort_unstable();
        references.dedup();
        assert_eq!(references.len(), expected);
        assert_eq!(tree.primitives.len(), expected);
        let contains = |outer: &BvhNode, inner: &BvhNode| {
            (0..3).all(|k| outer.min[k] <= inner.min[k] && inner.max[k] <= outer.max[k])
        };
        for node in tree.nodes.iter().filter(|n| n.count == 0) {
            let first = node.first as usize;
            assert!(contains(node, &tree.nodes[first]) && contains(node, &tree.nodes[first + 1]));
        }
    }

    /// 2000 copies of one sphere, all in the tree: the builder chains them 1996 levels deep
    /// (measured with obvhs 0.4), and the median split makes one leaf of them, as no split can
    /// separate them.
    #[test]
    fn coincident_copies_make_a_shallow_tree() {
        let mut spheres = vec![sphere([0.0; 3], 1.0); 2000];
        spheres.extend((0..100).map(|i| sphere([i as f32 * 3.0, 5.0, 0.0], 1.0)));
        let tree = build_with_copies(&spheres, &[], &[]).unwrap();
        check(&tree, spheres.len());
        let largest = tree.nodes.iter().map(|n| n.count).max().unwrap();
        assert!(largest >= 1000, "{largest}");
    }

    /// Nested spheres, each a little smaller than the last, and spheres halving in size and
    /// distance: distinct primitives whose trees the builder also makes too deep (497 and 90
    /// levels, measured with obvhs 0.4).
    #[test]
    fn nested_and_shrinking_spheres_make_a_shallow_tree() {
        let nested: Vec<Sphere> = (0..2000)
            .map(|i| sphere([0.5, -0.25, 0.0], 2.0 - i as f32 * 1e-4))
            .collect();
        check(&build(&nested, &[], &[]).unwrap(), nested.len());
        let shrinking: Vec<Sphere> = (0..120)
            .map(|i| {
                let scale = 0.5f32.powi(i);
                sphere([scale, 0.0, 0.0], 0.25 * scale)
            })
            .collect();
        check(&build(&shrinking, &[], &[]).unwrap(), shrinking.len());
    }

    /// Exact copies are left out of the tree: only each first copy remains, whatever the
    /// copies' materials.
    #[test]
    fn exact_copies_are_left_out() {
        let mut spheres = Vec::new();
        for copy in 0..500 {
            for (i, radius) in [1.0, 2.0, 3.0].into_iter().enumerate() {
                spheres.push(Sphere {
                    material: copy % 2,
                    ..sphere([i as f32 * 10.0, 0.0, 0.0], radius)
                });
            }
        }
        let tree = build(&spheres, &[], &[]).unwrap();
        let mut kept = tree.primitives.clone();
        kept.sort_unstable();
        assert_eq!(kept, [0, 1, 2].map(|i| reference(i, spheres.len(), 0, 0)));
    }
}
