//! 4-wide BVH traversal (WGSL side: `shaders/traverse/wide.wgsl`), over the tree
//! `src/kernel/bvh/wide.rs` collapses from the binary one. The meaning and the arguments are
//! `bvh_traverse`'s (`src/cpu/traverse/bvh.rs`), and so are the leaves' tests and bookkeeping
//! (`hit_primitive`, `hit_comes_first`, the leaf-entry pruning): only the inner nodes differ.
//! A node's four boxes are tested at once, the nearest child hit is entered next and the
//! others pushed farthest first; entries popped beyond the best hit so far are skipped.
//!
//! The CPU's walk differs from the kernel's only in what cannot change a result: it tests a
//! node's boxes and up to four of a leaf's triangles in SIMD lanes (`lanes.rs`: each lane the
//! scalar test's arithmetic), enters the nearest child without pushing it, and visits
//! children in a different order among equal entries. The closest-hit rule
//! ([`hit_comes_first`]) makes the closest hit independent of the order of visits, and a
//! shadow search only asks whether anything is found.

use crate::cpu::geometry::alpha::alpha_skips;
use crate::cpu::geometry::hit::{hit_comes_first, ClosestPrimitive, NO_HIT};
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::traverse::bvh_ray::{hit_primitive, widened, BvhRay, NO_PRIMITIVE};
#[cfg(target_arch = "x86_64")]
use crate::cpu::traverse::lanes::Sse;
use crate::cpu::traverse::lanes::{Portable, WideLanes};
use crate::kernel::bvh::wide::WIDE_STACK_SIZE;
use crate::kernel::types::{
    BvhWideNode, NO_INSTANCE, PRIMITIVE_INDEX_MASK, PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD,
    PRIMITIVE_TRIANGLE,
};
use std::mem::MaybeUninit;

pub use crate::cpu::traverse::lanes::hit_wide_boxes;

/// Which lanes the walk runs its tests on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WideTests {
    /// `glam` and the scalar triangle test, on any target.
    Portable,
    /// SSE2, which every x86-64 CPU has. AVX2 measured no faster: the tests compiled for it
    /// (three-operand forms), and eight triangles per test in 256-bit registers, both took
    /// 1.03-1.08x SSE2's CPU time on the bunny (performance docs, 2026-12-04): a 4-wide tree
    /// gives a box test four lanes, and its leaves hold four triangles most often.
    Sse2,
}

impl WideTests {
    /// The fastest this target has.
    pub fn detected() -> WideTests {
        #[cfg(target_arch = "x86_64")]
        return WideTests::Sse2;
        #[cfg(not(target_arch = "x86_64"))]
        WideTests::Portable
    }

    /// [`WideTests::detected`], or what `GLINT_WIDE_TESTS=portable|sse2` names, for
    /// measuring one against the other; a kind this target lacks, or any other value, is
    /// ignored with a warning.
    pub fn chosen() -> WideTests {
        let detected = WideTests::detected();
        let Ok(name) = std::env::var("GLINT_WIDE_TESTS") else {
            return detected;
        };
        let named = WideTests::available()
            .into_iter()
            .find(|t| t.name() == name);
        named.unwrap_or_else(|| {
            crate::errln!(
                "glint: GLINT_WIDE_TESTS={name} is not one this target runs; using {}",
                detected.name()
            );
            detected
        })
    }

    pub fn name(&self) -> &'static str {
        match self {
            WideTests::Portable => "portable",
            WideTests::Sse2 => "sse2",
        }
    }

    /// Every kind this target runs (for tests that compare them).
    pub fn available() -> Vec<WideTests> {
        let mut out = vec![WideTests::Portable];
        #[cfg(target_arch = "x86_64")]
        out.push(WideTests::Sse2);
        out
    }
}

/// What a search looks for: `bvh_traverse`'s bound and shadow target.
#[derive(Clone, Copy, Debug)]
struct Search {
    t_max: f32,
    t_prune: f32,
    max_reference: u32,
    shadow_target: u32,
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
    static TESTS: std::sync::OnceLock<WideTests> = std::sync::OnceLock::new();
    let tests = *TESTS.get_or_init(WideTests::chosen);
    wide_traverse_with(
        tests,
        geometry,
        r,
        t_max,
        t_prune,
        max_reference,
        shadow_target,
    )
}

/// [`wide_traverse`] on the lanes `tests`, which this target must have
/// ([`WideTests::available`]).
pub fn wide_traverse_with(
    tests: WideTests,
    geometry: &Geometry,
    r: &BvhRay,
    t_max: f32,
    t_prune: f32,
    max_reference: u32,
    shadow_target: u32,
) -> ClosestPrimitive {
    let search = Search {
        t_max,
        t_prune,
        max_reference,
        shadow_target,
    };
    match tests {
        #[cfg(target_arch = "x86_64")]
        WideTests::Sse2 => walk(&Sse::new(r), geometry, r, search),
        _ => walk(&Portable(r), geometry, r, search),
    }
}

/// A stack entry: a child's first and count (0 for an inner node: its index in the wide
/// nodes), and where the ray enters its box.
#[derive(Clone, Copy)]
struct Entry {
    first: u32,
    count: u32,
    t: f32,
}

/// The search's state: the best hit so far by the closest-hit rule and the bound it prunes to.
struct Best {
    hit: ClosestPrimitive,
    reference: u32,
    prune: f32,
    /// `widened(prune)`: popped entries and boxes beyond it are skipped.
    limit: f32,
    found: bool,
}

impl Best {
    /// Takes the primitive `reference`, hit at `t` (`NO_HIT` for a miss), in a leaf the ray
    /// enters at `node_entry`, if it comes first; true when the search is then over (a shadow
    /// search's first find).
    #[inline(always)]
    fn offer(&mut self, t: f32, reference: u32, node_entry: f32, search: &Search) -> bool {
        // The target is excluded by name too, as in bvh_traverse.
        if hit_comes_first(t, reference, self.hit.t, self.reference)
            && reference != search.shadow_target
        {
            self.hit = ClosestPrimitive {
                t,
                primitive: reference >> PRIMITIVE_KIND_SHIFT,
                index: reference & PRIMITIVE_INDEX_MASK,
                instance: NO_INSTANCE,
            };
            self.reference = reference;
            self.prune = t.max(node_entry);
            self.limit = widened(self.prune);
            self.found = true;
            return search.shadow_target != NO_PRIMITIVE;
        }
        false
    }
}

/// Tests a leaf's primitives in order, in groups of four: a group of triangles in lanes, a
/// group with another kind one by one. True when the search is over.
#[inline(always)]
fn visit_leaf<L: WideLanes>(
    lanes: &L,
    geometry: &Geometry,
    r: &BvhRay,
    leaf: Entry,
    best: &mut Best,
    search: &Search,
) -> bool {
    let references =
        &geometry.bvh_primitives[leaf.first as usize..(leaf.first + leaf.count) as usize];
    for group in references.chunks(4) {
        let triangles = group
            .iter()
            .all(|&p| p >> PRIMITIVE_KIND_SHIFT == PRIMITIVE_TRIANGLE);
        if !triangles {
            for &reference in group {
                let t = hit_primitive(geometry, reference, r);
                if best.offer(t, reference, leaf.t, search) {
                    return true;
                }
            }
            continue;
        }
        // A short group repeats its last triangle in the spare lanes, whose results are unused.
        let last = group.len() - 1;
        let index = |k: usize| group[k.min(last)] & PRIMITIVE_INDEX_MASK;
        let tris = [0, 1, 2, 3].map(|k| &geometry.triangles[index(k) as usize]);
        let (t, hits) = lanes.triangles(tris);
        let mut hits = hits & ((1 << group.len()) - 1);
        // `hit_scene_triangle`, its alpha test after the lanes' `hit_triangle`.
        while hits != 0 {
            let k = hits.trailing_zeros() as usize;
            hits &= hits - 1;
            let alpha = &geometry.alpha;
            if alpha.enabled && alpha_skips(alpha, index(k), tris[k], &r.tri) {
                continue;
            }
            if best.offer(t[k], group[k], leaf.t, search) {
                return true;
            }
        }
    }
    false
}

/// The walk, on the lanes `lanes` (of the ray `r`).
#[inline(always)]
fn walk<L: WideLanes>(
    lanes: &L,
    geometry: &Geometry,
    r: &BvhRay,
    search: Search,
) -> ClosestPrimitive {
    let nodes: &[BvhWideNode] = geometry.bvh_wide_nodes;
    let mut best = Best {
        hit: ClosestPrimitive {
            t: search.t_max,
            primitive: PRIMITIVE_QUAD,
            index: 0,
            instance: NO_INSTANCE,
        },
        reference: search.max_reference,
        prune: search.t_prune,
        limit: widened(search.t_prune),
        found: false,
    };
    let finish = |mut best: Best| {
        if !best.found {
            best.hit.t = NO_HIT;
        }
        best.hit
    };
    // Children left for later. Not initialised: every entry read was written first (and zeroing
    // 193 entries for every ray was most of the walk's time).
    let mut stack = [MaybeUninit::<Entry>::uninit(); WIDE_STACK_SIZE];
    let mut top = 0usize;
    // The root is entered from 0: its children's boxes are tested instead.
    if 0.0 > best.limit {
        return finish(best);
    }
    let mut node = 0usize;
    'nodes: loop {
        let inner = &nodes[node];
        let (t, mut hits) = lanes.boxes(inner, best.limit);
        let entry = |s: usize| Entry {
            first: inner.first[s],
            count: inner.count[s],
            t: t[s],
        };
        // The child to enter now: the nearest hit; the others go on the stack, farthest first.
        let next = if hits & hits.wrapping_sub(1) == 0 {
            (hits != 0).then(|| entry(hits.trailing_zeros() as usize))
        } else {
            // Keys that order the hits by entry (t ≥ 0 orders as its bits), the slot in the low
            // two bits; misses last. Only the order of visits rests on it, never a decision.
            let mut key = [u32::MAX; 4];
            let mut n = 0;
            while hits != 0 {
                let s = hits.trailing_zeros();
                hits &= hits - 1;
                key[n] = (t[s as usize].to_bits() & !3) | s;
                n += 1;
            }
            let [k0, k1, k2, k3] = key;
            let (k0, k1) = (k0.min(k1), k0.max(k1));
            let (k2, k3) = (k2.min(k3), k2.max(k3));
            let (k0, k2) = (k0.min(k2), k0.max(k2));
            let (k1, k3) = (k1.min(k3), k1.max(k3));
            let (k1, k2) = (k1.min(k2), k1.max(k2));
            let sorted = [k0, k1, k2, k3];
            for &k in sorted[1..n].iter().rev() {
                stack[top].write(entry((k & 3) as usize));
                top += 1;
            }
            Some(entry((k0 & 3) as usize))
        };
        if let Some(child) = next {
            if child.count == 0 {
                node = child.first as usize;
                continue;
            }
            if visit_leaf(lanes, geometry, r, child, &mut best, &search) {
                return finish(best);
            }
        }
        // Pop the next entry that may still hold something before the bound.
        while top > 0 {
            top -= 1;
            // SAFETY: entries below `top` were written above.
            let e = unsafe { stack[top].assume_init() };
            if e.t > best.limit {
                continue;
            }
            if e.count == 0 {
                node = e.first as usize;
                continue 'nodes;
            }
            if visit_leaf(lanes, geometry, r, e, &mut best, &search) {
                return finish(best);
            }
        }
        return finish(best);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::core::ray::Ray;
    use crate::cpu::core::rng::Rng;
    use crate::cpu::traverse::bvh::{bvh_traverse, NO_TARGET};
    use crate::cpu::traverse::bvh_ray::{bvh_ray, hit_primitive, primitive_box_entry};
    use crate::kernel::bvh;
    use crate::kernel::types::{Sphere, Triangle};
    use crate::scene::stress::StressMesh;
    use glam::Vec3;

    /// Bumpy spheres of triangles, two of them in the same place (coincident triangles, whose
    /// ties the rule breaks), and small spheres among them, so leaves mix kinds.
    fn scene() -> (Vec<Sphere>, Vec<Triangle>) {
        let mesh = StressMesh::new(40, 20);
        let mut triangles = Vec::new();
        for (offset, scale) in [
            (Vec3::ZERO, 1.0),
            (Vec3::new(1.5, 0.2, 0.0), 0.7),
            (Vec3::ZERO, 1.0),
        ] {
            for t in &mesh.indices {
                let [v0, v1, v2] =
                    t.map(|i| (mesh.positions[i as usize] * scale + offset).to_array());
                triangles.push(Triangle {
                    v0,
                    v1,
                    v2,
                    ..Default::default()
                });
            }
        }
        let spheres = (0..64)
            .map(|i| Sphere {
                center: [
                    (i % 4) as f32 * 0.6 - 0.9,
                    (i / 4 % 4) as f32 * 0.6 - 0.9,
                    (i / 16) as f32 * 0.6 - 0.9,
                ],
                radius: 0.05 + 0.01 * (i % 5) as f32,
                ..Default::default()
            })
            .collect();
        (spheres, triangles)
    }

    /// Every kind of lanes this CPU has finds what the binary walk finds: the same closest
    /// hit, bit for bit, and the same answer to every shadow search, for rays from outside
    /// and inside the meshes, through the tree with and without coincident copies.
    #[test]
    fn every_kind_of_lanes_finds_the_binary_walks_hits() {
        let (spheres, triangles) = scene();
        for tree in [
            bvh::build(&spheres, &[], &triangles).unwrap(),
            bvh::build_with_copies(&spheres, &[], &triangles).unwrap(),
        ] {
            let wide = tree.wide_nodes();
            let binary = Geometry {
                triangles: &triangles,
                bvh_nodes: &tree.nodes,
                bvh_primitives: &tree.primitives,
                ..Geometry::new(&spheres, &[])
            };
            let geometry = Geometry {
                bvh_wide_nodes: &wide,
                ..binary
            };
            let mut rng = Rng::new(3, 0, 0, 5);
            let mut point = |spread: f32| {
                Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 * spread
                    - Vec3::splat(spread)
            };
            let mut hits = 0;
            for i in 0..20_000 {
                let origin = point(if i % 2 == 0 { 4.0 } else { 0.5 });
                let dir = (point(1.0) - origin).normalize_or(Vec3::X);
                let r = bvh_ray(&Ray { origin, dir });
                let expected = bvh_traverse(&binary, &r, NO_HIT, NO_HIT, 0, NO_PRIMITIVE);
                let escapes = bvh_traverse(&binary, &r, NO_HIT, NO_HIT, 0, NO_TARGET).t;
                hits += (expected.t != NO_HIT) as u32;
                for tests in WideTests::available() {
                    let found =
                        wide_traverse_with(tests, &geometry, &r, NO_HIT, NO_HIT, 0, NO_PRIMITIVE);
                    assert_eq!(
                        (found.t.to_bits(), found.primitive, found.index),
                        (expected.t.to_bits(), expected.primitive, expected.index),
                        "{tests:?}, ray {i}"
                    );
                    let any =
                        wide_traverse_with(tests, &geometry, &r, NO_HIT, NO_HIT, 0, NO_TARGET);
                    assert_eq!(any.t == NO_HIT, escapes == NO_HIT, "{tests:?}, ray {i}");
                }
                if expected.t == NO_HIT {
                    continue;
                }
                // Shadow searches as `bvh_first_hit_is` makes them: aimed at the hit (nothing
                // in front), and at the first sphere and a triangle (the hit, or what is in
                // front of them).
                let aimed = expected.primitive << PRIMITIVE_KIND_SHIFT | expected.index;
                let triangle = PRIMITIVE_TRIANGLE << PRIMITIVE_KIND_SHIFT | (i % 1000);
                for target in [aimed, 0, triangle] {
                    let t_target = hit_primitive(&binary, target, &r);
                    if t_target == NO_HIT {
                        continue;
                    }
                    let t_prune = t_target.max(primitive_box_entry(&binary, target, &r));
                    let behind = bvh_traverse(&binary, &r, t_target, t_prune, target, target).t;
                    for tests in WideTests::available() {
                        let found = wide_traverse_with(
                            tests, &geometry, &r, t_target, t_prune, target, target,
                        );
                        assert_eq!(found.t == NO_HIT, behind == NO_HIT, "{tests:?}, ray {i}");
                    }
                }
            }
            assert!(hits > 5_000, "{hits}");
        }
    }
}
