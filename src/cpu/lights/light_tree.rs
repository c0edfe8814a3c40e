//! Picking a finite emitter with the light tree (`src/kernel/scene/light_tree.rs` builds it;
//! WGSL side: `shaders/lights/light_tree.wgsl`): from the root, each child in proportion to
//! pbrt-v4's bound on what its emitters send to the shading point (`importance`), to a leaf;
//! the product of those choices is the emitter's probability. [`tree_pmf`] follows an
//! emitter's stored trail down the same nodes with the same arithmetic, so multiple
//! importance sampling reads the very probability the pick had.
//!
//! Every step is written out in the order the WGSL computes it, in f32, so both devices pick
//! the same emitter from the same number.

use crate::cpu::scene_refs::SceneRefs;
use crate::kernel::types::{
    LightTreeNode, Params, INTEGRATOR_PATH, PRIMITIVE_QUAD, PRIMITIVE_SPHERE,
};
use glam::Vec3;

/// The largest f32 below 1: where a rescaled number stays.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Whether next-event estimation picks finite emitters with the tree: the scene has one and
/// the integrator is path tracing (bidirectional keeps the choice by power).
pub fn light_tree_active(params: &Params) -> bool {
    params.light_tree_nodes > 0 && params.integrator == INTEGRATOR_PATH
}

/// pbrt-v4's `LightBounds::Importance` without the surface normal's factor (light sampling
/// is not told the normal): power × the largest cosine between a normal in the cone and a
/// direction from the box to `p`, widened by the angle the box subtends from `p`, over the
/// squared distance to the box's centre. 0 where no emitter in the node can light `p`
/// (past θo + θe from every normal). Distances are kept at least the box's half diagonal,
/// so a point inside or beside a box does not see an unbounded importance.
pub fn node_importance(n: &LightTreeNode, p: Vec3) -> f32 {
    let lo = Vec3::from(n.lo);
    let hi = Vec3::from(n.hi);
    let center = 0.5 * (lo + hi);
    let diagonal = hi - lo;
    let radius2 = 0.25 * diagonal.dot(diagonal);
    let to_p = p - center;
    let d2 = to_p.dot(to_p);
    let clamped = d2.max(radius2).max(1e-12);
    if d2 <= radius2 {
        // Inside the box's bounding sphere: every direction may reach an emitter.
        return (n.phi / clamped).min(f32::MAX);
    }
    let wi = to_p / d2.sqrt();
    let mut cos_w = Vec3::from(n.axis).dot(wi);
    if n.two_sided != 0 {
        cos_w = cos_w.abs();
    }
    let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
    let sin2_b = radius2 / d2;
    let cos_b = (1.0 - sin2_b).max(0.0).sqrt();
    let sin_b = sin2_b.sqrt();
    let cos_o = n.cos_theta_o;
    let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
    // θx = max(0, θw − θo), then θ' = max(0, θx − θb), as cosines and sines.
    let (cos_x, sin_x) = if cos_w > cos_o {
        (1.0, 0.0)
    } else {
        (cos_w * cos_o + sin_w * sin_o, sin_w * cos_o - cos_w * sin_o)
    };
    let cos_p = if cos_x > cos_b {
        1.0
    } else {
        cos_x * cos_b + sin_x * sin_b
    };
    if cos_p <= n.cos_theta_e {
        return 0.0;
    }
    (n.phi * cos_p / clamped).clamp(0.0, f32::MAX)
}

/// An interior node's children's importances at `p`: (first, second).
fn children(nodes: &[LightTreeNode], i: usize, p: Vec3) -> (f32, f32) {
    (
        node_importance(&nodes[i + 1], p),
        node_importance(&nodes[nodes[i].child as usize], p),
    )
}

/// A finite emitter picked from the tree at `p` with the number `u`: its (primitive, index)
/// and the probability of picking it; `None` where no emitter can light `p`.
pub fn tree_pick(nodes: &[LightTreeNode], p: Vec3, u: f32) -> Option<(u32, u32, f32)> {
    let mut u = u;
    let mut i = 0usize;
    let mut pmf = 1.0f32;
    for _ in 0..64 {
        let n = &nodes[i];
        if n.child == 0 {
            return Some((n.primitive, n.index, pmf));
        }
        let (c0, c1) = children(nodes, i, p);
        let sum = c0 + c1;
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(sum > 0.0) {
            return None;
        }
        let p0 = c0 / sum;
        if u < p0 {
            u = (u / p0).min(ONE_MINUS_EPSILON);
            pmf *= p0;
            i += 1;
        } else {
            u = ((u - p0) / (1.0 - p0)).min(ONE_MINUS_EPSILON);
            pmf *= c1 / sum;
            i = n.child as usize;
        }
    }
    None
}

/// The slot of an emitting sphere's, quad's or triangle's trail in
/// `KernelScene::light_tree_trails`.
pub fn trail_slot(params: &Params, primitive: u32, index: u32) -> usize {
    let offset = match primitive {
        PRIMITIVE_SPHERE => 0,
        PRIMITIVE_QUAD => params.sphere_count,
        _ => params.sphere_count + params.quad_count,
    };
    (offset + index) as usize
}

/// The probability that [`tree_pick`] at `p` picks the sphere, quad or triangle (primitive,
/// index): the choices down its trail, each computed as the pick computes it.
pub fn tree_pmf(
    nodes: &[LightTreeNode],
    trails: &[[u32; 2]],
    params: &Params,
    p: Vec3,
    primitive: u32,
    index: u32,
) -> f32 {
    let Some(&[low, high]) = trails.get(trail_slot(params, primitive, index)) else {
        return 0.0;
    };
    let mut i = 0usize;
    let mut pmf = 1.0f32;
    for depth in 0..64u32 {
        let n = &nodes[i];
        if n.child == 0 {
            let same = n.primitive == primitive && n.index == index;
            return if same { pmf } else { 0.0 };
        }
        let (c0, c1) = children(nodes, i, p);
        let sum = c0 + c1;
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(sum > 0.0) {
            return 0.0;
        }
        let bit = if depth < 32 {
            (low >> depth) & 1
        } else {
            (high >> (depth - 32)) & 1
        };
        if bit == 0 {
            pmf *= c0 / sum;
            i += 1;
        } else {
            pmf *= c1 / sum;
            i = n.child as usize;
        }
    }
    0.0
}

/// [`tree_pmf`] on a scene's tree, times the probability of picking a finite emitter at
/// all: the probability next-event estimation picks (primitive, index) at `p`.
pub fn tree_selection_probability(scene: &SceneRefs, p: Vec3, primitive: u32, index: u32) -> f32 {
    let pmf = tree_pmf(
        scene.light_tree_nodes,
        scene.light_tree_trails,
        scene.params,
        p,
        primitive,
        index,
    );
    scene.params.light_tree_probability * pmf
}
