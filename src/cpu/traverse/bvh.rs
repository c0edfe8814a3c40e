//! BVH traversal (WGSL side: `shaders/traverse/bvh.wgsl`). One BVH over every sphere, quad, triangle
//! and instance, built on the host (`src/kernel/bvh/mod.rs`) and flattened into `bvh_nodes`; an
//! instance's leaf entry walks its mesh's own BVH (`src/cpu/traverse/blas.rs`). Both take the walk
//! of `binary_walk.rs`: a fixed stack, the nearer child first, and popped nodes skipped when they
//! start beyond the closest hit so far.
//! Shadow rays stop at the first primitive in front of the one they aim at. Which hit is the
//! closest, and which primitives are in front, is the closest-hit rule's
//! ([`hit_comes_first`]), whatever the order of visits. The tests the walks share are in
//! `bvh_ray.rs`.

use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::hit::{hit_comes_first, ClosestPrimitive, NO_HIT};
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::traverse::binary_walk::{walk_binary_bvh, LeafVisit};
use crate::cpu::traverse::blas::hit_instance;
use crate::cpu::traverse::bvh_ray::{
    bvh_ray, hit_primitive, primitive_box_entry, BvhRay, NO_PRIMITIVE,
};
use crate::cpu::traverse::wide::wide_traverse;
use crate::kernel::types::{
    NO_INSTANCE, PRIMITIVE_INDEX_MASK, PRIMITIVE_INSTANCE, PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD,
    PRIMITIVE_TRIANGLE,
};

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
    let mut best = ClosestPrimitive {
        t: t_max,
        primitive: PRIMITIVE_QUAD,
        index: 0,
        instance: NO_INSTANCE,
    };
    let mut best_reference = max_reference;
    let mut found = false;
    let shadow = shadow_target != NO_PRIMITIVE;
    walk_binary_bvh(
        geometry.bvh_nodes,
        0,
        r,
        t_prune,
        |first, count, node_entry, prune| {
            for i in first..first + count {
                let reference = geometry.bvh_primitives[i as usize];
                if reference >> PRIMITIVE_KIND_SHIFT == PRIMITIVE_INSTANCE {
                    // Its closest triangle that comes before the best so far: at the same t only
                    // if this reference is the lower (the rule, extended by triangle).
                    let instance = reference & PRIMITIVE_INDEX_MASK;
                    let h = hit_instance(
                        geometry,
                        instance,
                        &r.ray,
                        best.t,
                        reference < best_reference,
                        *prune,
                        shadow,
                    );
                    if h.t != NO_HIT {
                        best = ClosestPrimitive {
                            t: h.t,
                            primitive: PRIMITIVE_TRIANGLE,
                            index: h.triangle,
                            instance,
                        };
                        best_reference = reference;
                        *prune = h.prune.max(node_entry);
                        found = true;
                        if shadow {
                            return LeafVisit::Stop;
                        }
                    }
                    continue;
                }
                let t = hit_primitive(geometry, reference, r);
                // The target is excluded by name too, not only by the rule: a shader compiler may
                // round its test here and in `bvh_first_hit_is` differently.
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
                    *prune = t.max(node_entry);
                    found = true;
                    if shadow {
                        return LeafVisit::Stop;
                    }
                }
            }
            LeafVisit::Continue
        },
    );
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
