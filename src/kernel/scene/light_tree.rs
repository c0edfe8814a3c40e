//! The light tree next-event estimation picks finite emitters with (Conty Estevez and Kulla
//! 2018, as pbrt-v4's `BVHLightSampler` builds it): a binary tree over the emitting spheres,
//! quads, triangles and point and spot lights, each node bounding its emitters' positions,
//! power and normals, split where pbrt's cost (power × solid angle of the normals × surface
//! area) is least. The samplers walk it with `src/cpu/lights/light_tree.rs` and
//! `shaders/lights/light_tree.wgsl`; the environment map and suns stay outside it, with the
//! alias table's probabilities.
//!
//! Built in f64 and stored in f32: the bounds need only be conservative, and both devices
//! read the same stored numbers.

use super::emitter_table::Power;
use crate::kernel::types::{
    LightTreeNode, PRIMITIVE_LIGHT, PRIMITIVE_QUAD, PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE,
};
use crate::scene::light::LightKind;
use crate::scene::Scene;
use glam::DVec3;
use std::f64::consts::PI;

/// The most finite emitters the tree takes: its trails hold 64 levels, and past depth
/// [`BALANCED_DEPTH`] the build splits in halves, so 2²³ emitters stay within them.
pub const MAX_TREE_EMITTERS: usize = 1 << 23;

/// From this depth on, subtrees split by count, so no trail passes 64 levels.
const BALANCED_DEPTH: u32 = 40;

/// pbrt's `LightBounds`: a box, the power in it, the cone around the emitters' normals (axis
/// and cos θo), how far past a normal they emit (cos θe), and whether any emits both ways.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    lo: DVec3,
    hi: DVec3,
    phi: f64,
    axis: DVec3,
    cos_o: f64,
    cos_e: f64,
    two_sided: bool,
}

impl Bounds {
    fn centroid(&self) -> DVec3 {
        0.5 * (self.lo + self.hi)
    }

    fn surface_area(&self) -> f64 {
        let d = self.hi - self.lo;
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// pbrt's `Union` of light bounds: an empty (powerless) side adds nothing.
    fn union(a: Option<Bounds>, b: &Bounds) -> Bounds {
        let Some(a) = a else { return *b };
        if a.phi == 0.0 {
            return *b;
        }
        if b.phi == 0.0 {
            return a;
        }
        let (axis, cos_o) = cone_union(a.axis, a.cos_o, b.axis, b.cos_o);
        Bounds {
            lo: a.lo.min(b.lo),
            hi: a.hi.max(b.hi),
            phi: a.phi + b.phi,
            axis,
            cos_o,
            cos_e: a.cos_e.min(b.cos_e),
            two_sided: a.two_sided || b.two_sided,
        }
    }

    /// pbrt's `EvaluateCost`: power × the solid angle the normal cone and emission spread
    /// reach (M_Ω) × surface area, times the box's aspect along `dim` (`whole`'s longest side
    /// over its side along dim), which keeps splits from making slivers.
    fn cost(&self, whole: &Bounds, dim: usize) -> f64 {
        let theta_o = self.cos_o.clamp(-1.0, 1.0).acos();
        let theta_e = self.cos_e.clamp(-1.0, 1.0).acos();
        let theta_w = (theta_o + theta_e).min(PI);
        let sin_o = (1.0 - self.cos_o * self.cos_o).max(0.0).sqrt();
        let m_omega = 2.0 * PI * (1.0 - self.cos_o)
            + PI / 2.0
                * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                    + self.cos_o);
        let d = whole.hi - whole.lo;
        let kr = d.max_element() / d[dim];
        self.phi * m_omega * kr * self.surface_area()
    }
}

/// pbrt's `DirectionCone` union: the smallest cone (axis, cos θ) holding both.
fn cone_union(a: DVec3, cos_a: f64, b: DVec3, cos_b: f64) -> (DVec3, f64) {
    let theta_a = cos_a.clamp(-1.0, 1.0).acos();
    let theta_b = cos_b.clamp(-1.0, 1.0).acos();
    let theta_d = a.dot(b).clamp(-1.0, 1.0).acos();
    if (theta_d + theta_b).min(PI) <= theta_a {
        return (a, cos_a);
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return (b, cos_b);
    }
    let theta_o = (theta_a + theta_d + theta_b) / 2.0;
    let whole = (DVec3::Z, -1.0);
    if theta_o >= PI {
        return whole;
    }
    let theta_r = theta_o - theta_a;
    let wr = a.cross(b);
    if wr.length_squared() < 1e-24 {
        return whole;
    }
    let axis = glam::DQuat::from_axis_angle(wr.normalize(), theta_r) * a;
    (axis.normalize(), theta_o.cos())
}

/// The tree's nodes, depth first, and each sphere's, quad's and triangle's path to its leaf
/// (bit k: the second child at depth k; pbrt's bit trail), in that order, as low and high
/// 32 bits: `trails[sphere_count + quad_count + i]` is triangle i's.
#[derive(Clone, Debug, Default)]
pub(super) struct LightTree {
    pub(super) nodes: Vec<LightTreeNode>,
    pub(super) trails: Vec<[u32; 2]>,
}

/// A finite emitter in the tree.
#[derive(Clone, Copy)]
struct Leaf {
    primitive: u32,
    index: u32,
    bounds: Bounds,
}

impl Scene {
    /// The light tree over `powers`' finite emitters (all but the environment map and suns);
    /// empty with fewer than two of them (picking one costs nothing) or more than
    /// [`MAX_TREE_EMITTERS`].
    pub(super) fn light_tree(&self, powers: &[Power]) -> LightTree {
        let mut leaves: Vec<Leaf> = powers
            .iter()
            .filter_map(|&(primitive, index, power)| {
                let bounds = self.emitter_bounds(primitive, index, power)?;
                Some(Leaf {
                    primitive,
                    index,
                    bounds,
                })
            })
            .collect();
        if leaves.len() < 2 || leaves.len() > MAX_TREE_EMITTERS {
            return LightTree::default();
        }
        let mut tree = LightTree {
            nodes: Vec::with_capacity(2 * leaves.len()),
            trails: vec![[0, 0]; self.trail_count(&leaves)],
        };
        let offsets = [0, self.spheres.len(), self.spheres.len() + self.quads.len()];
        build(&mut tree, &offsets, &mut leaves, 0, 0);
        tree
    }

    /// Trails up to the last emitting primitive's (lights need none: no ray hits them).
    fn trail_count(&self, leaves: &[Leaf]) -> usize {
        let offset = |primitive: u32| match primitive {
            PRIMITIVE_SPHERE => 0,
            PRIMITIVE_QUAD => self.spheres.len(),
            _ => self.spheres.len() + self.quads.len(),
        };
        leaves
            .iter()
            .filter(|l| l.primitive != PRIMITIVE_LIGHT)
            .map(|l| offset(l.primitive) + l.index as usize + 1)
            .max()
            .unwrap_or(0)
    }

    /// pbrt's bounds of one emitter: area emitters face their normal and emit from both
    /// sides up to 90° from it; spheres and point lights every way; a spot within its outer
    /// angle. `None` for suns, which are not in the tree.
    fn emitter_bounds(&self, primitive: u32, index: u32, phi: f64) -> Option<Bounds> {
        let facing = |lo: DVec3, hi: DVec3, normal: DVec3| Bounds {
            lo,
            hi,
            phi,
            axis: normal.normalize(),
            cos_o: 1.0,
            cos_e: 0.0,
            two_sided: true,
        };
        let everywhere = |lo: DVec3, hi: DVec3| Bounds {
            lo,
            hi,
            phi,
            axis: DVec3::Z,
            cos_o: -1.0,
            cos_e: 0.0,
            two_sided: false,
        };
        match primitive {
            PRIMITIVE_SPHERE => {
                let s = &self.spheres[index as usize];
                let (c, r) = (s.center.as_dvec3(), s.radius as f64);
                Some(everywhere(c - r, c + r))
            }
            PRIMITIVE_QUAD => {
                let q = &self.quads[index as usize];
                let (o, u, v) = (q.corner.as_dvec3(), q.u.as_dvec3(), q.v.as_dvec3());
                let corners = [o, o + u, o + v, o + u + v];
                let lo = corners.iter().fold(DVec3::INFINITY, |m, c| m.min(*c));
                let hi = corners.iter().fold(DVec3::NEG_INFINITY, |m, c| m.max(*c));
                Some(facing(lo, hi, u.cross(v)))
            }
            PRIMITIVE_TRIANGLE => {
                let [a, b, c] = self.triangles[index as usize]
                    .vertices
                    .map(|v| v.as_dvec3());
                Some(facing(
                    a.min(b).min(c),
                    a.max(b).max(c),
                    (b - a).cross(c - a),
                ))
            }
            _ => self.punctual_bounds(index, phi),
        }
    }

    fn punctual_bounds(&self, index: u32, phi: f64) -> Option<Bounds> {
        match self.lights[index as usize].kind {
            LightKind::Point { position, .. } => {
                let p = position.as_dvec3();
                Some(Bounds {
                    lo: p,
                    hi: p,
                    phi,
                    axis: DVec3::Z,
                    cos_o: -1.0,
                    cos_e: 0.0,
                    two_sided: false,
                })
            }
            LightKind::Spot {
                position,
                direction,
                inner_angle,
                outer_angle,
            } => {
                // It emits nothing past the outer angle: θo + θe reaches it.
                let outer = (outer_angle as f64).to_radians();
                let inner = (inner_angle as f64).to_radians().min(outer);
                let p = position.as_dvec3();
                Some(Bounds {
                    lo: p,
                    hi: p,
                    phi,
                    axis: direction.as_dvec3().normalize(),
                    cos_o: inner.cos(),
                    cos_e: (outer - inner).cos(),
                    two_sided: false,
                })
            }
            LightKind::Directional { .. } => None,
        }
    }
}

/// Builds the subtree over `leaves` at `depth`, reached by `trail`, and returns its root's
/// index.
fn build(tree: &mut LightTree, offsets: &[usize; 3], leaves: &mut [Leaf], depth: u32, trail: u64) {
    let here = tree.nodes.len();
    if leaves.len() == 1 {
        let l = leaves[0];
        tree.nodes
            .push(kernel_node(&l.bounds, 0, l.primitive, l.index));
        if l.primitive != PRIMITIVE_LIGHT {
            let slot = offsets[l.primitive as usize] + l.index as usize;
            tree.trails[slot] = [trail as u32, (trail >> 32) as u32];
        }
        return;
    }
    let bounds = leaves
        .iter()
        .fold(None, |b, l| Some(Bounds::union(b, &l.bounds)))
        .expect("two or more leaves");
    let mid = split(leaves, &bounds, depth);
    tree.nodes.push(kernel_node(&bounds, 0, 0, 0));
    let (first, second) = leaves.split_at_mut(mid);
    build(tree, offsets, first, depth + 1, trail);
    let second_index = tree.nodes.len() as u32;
    build(tree, offsets, second, depth + 1, trail | (1u64 << depth));
    tree.nodes[here].child = second_index;
}

/// Reorders `leaves` into two non-empty halves and returns where the second begins: pbrt's
/// split, the least cost over 12 buckets of centroids along each axis, else (no axis to
/// split, or past [`BALANCED_DEPTH`]) halves by count along the centroids' longest axis.
fn split(leaves: &mut [Leaf], bounds: &Bounds, depth: u32) -> usize {
    const BUCKETS: usize = 12;
    let (lo, hi) = leaves
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), l| {
            (lo.min(l.bounds.centroid()), hi.max(l.bounds.centroid()))
        });
    let bucket = |l: &Leaf, dim: usize| {
        let offset = (l.bounds.centroid()[dim] - lo[dim]) / (hi[dim] - lo[dim]);
        ((BUCKETS as f64 * offset) as usize).min(BUCKETS - 1)
    };
    let mut best: Option<(f64, usize, usize)> = None;
    for dim in 0..3 {
        if depth >= BALANCED_DEPTH || hi[dim] <= lo[dim] {
            continue;
        }
        let mut buckets: [Option<Bounds>; BUCKETS] = [None; BUCKETS];
        for l in leaves.iter() {
            let b = bucket(l, dim);
            buckets[b] = Some(Bounds::union(buckets[b], &l.bounds));
        }
        for i in 0..BUCKETS - 1 {
            let below = buckets[..=i]
                .iter()
                .flatten()
                .fold(None, |b, x| Some(Bounds::union(b, x)));
            let above = buckets[i + 1..]
                .iter()
                .flatten()
                .fold(None, |b, x| Some(Bounds::union(b, x)));
            let (Some(below), Some(above)) = (below, above) else {
                continue;
            };
            let cost = below.cost(bounds, dim) + above.cost(bounds, dim);
            if cost > 0.0 && best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, dim, i));
            }
        }
    }
    if let Some((_, dim, i)) = best {
        let mut mid = 0;
        for k in 0..leaves.len() {
            if bucket(&leaves[k], dim) <= i {
                leaves.swap(k, mid);
                mid += 1;
            }
        }
        if mid > 0 && mid < leaves.len() {
            return mid;
        }
    }
    let dim = (hi - lo).max_position();
    let mid = leaves.len() / 2;
    leaves.select_nth_unstable_by(mid, |a, b| {
        a.bounds.centroid()[dim].total_cmp(&b.bounds.centroid()[dim])
    });
    mid
}

/// A node as the kernel reads it: f32 bounds rounded outward, so rounding cannot shrink
/// them (the cones' cosines down, the box's corners away from it).
fn kernel_node(b: &Bounds, child: u32, primitive: u32, index: u32) -> LightTreeNode {
    LightTreeNode {
        lo: b.lo.to_array().map(round_down),
        phi: b.phi.min(f32::MAX as f64) as f32,
        hi: b.hi.to_array().map(|x| -round_down(-x)),
        cos_theta_o: round_down(b.cos_o).max(-1.0),
        axis: b.axis.as_vec3().into(),
        cos_theta_e: round_down(b.cos_e).max(-1.0),
        child,
        primitive,
        index,
        two_sided: b.two_sided as u32,
    }
}

/// The largest f32 at most x.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        f.next_down()
    } else {
        f
    }
}
