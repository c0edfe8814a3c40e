//! The bottom level of the two-level structure (WGSL side: `shaders/traverse/blas.wgsl`): an
//! instance in the top-level BVH (`src/cpu/traverse/bvh.rs`) is hit by walking its mesh's own BVH, laid
//! out in `bvh_nodes` after the top level's, with the ray in the mesh's coordinates
//! (`src/cpu/geometry/instance.rs`). The walk is the top level's (`binary_walk.rs`), over triangles
//! only; the kernel writes it out again (WGSL has no closures nor function parameters).

use crate::cpu::core::ray::Ray;
use crate::cpu::geometry::alpha::hit_scene_triangle;
use crate::cpu::geometry::hit::{hit_comes_first, NO_HIT};
use crate::cpu::geometry::instance::object_ray;
use crate::cpu::geometry::scene_geometry::Geometry;
use crate::cpu::traverse::binary_walk::{walk_binary_bvh, LeafVisit};
use crate::cpu::traverse::bvh_ray::bvh_ray;
use crate::kernel::types::PRIMITIVE_INDEX_MASK;

/// An instance's closest triangle: its t (`NO_HIT` for none), its index in the triangle
/// arrays, and how far the walk still looked once it had it (max of t and the entry into its
/// leaf), which the top level keeps looking to, for a coincident instance's copy of the hit.
#[derive(Clone, Copy, Debug)]
pub struct InstanceHit {
    pub t: f32,
    pub triangle: u32,
    pub prune: f32,
}

/// The closest of instance `instance`'s triangles along `ray` (in the scene's coordinates)
/// that comes before the best hit so far, at `t_max`: at `t_max` itself only when `ties_win`
/// (the instance's reference is below the best's), and then the lowest triangle, so the rule
/// holds lexicographically on (t, top-level reference, triangle). Boxes beyond `t_prune` are
/// skipped, as in `bvh_traverse`; `any_hit` returns the first such triangle found (shadow
/// rays).
pub fn hit_instance(
    geometry: &Geometry,
    instance: u32,
    ray: &Ray,
    t_max: f32,
    ties_win: bool,
    t_prune: f32,
    any_hit: bool,
) -> InstanceHit {
    let inst = &geometry.instances[instance as usize];
    let r = bvh_ray(&object_ray(inst, ray));
    let mut best = InstanceHit {
        t: t_max,
        triangle: 0,
        prune: t_prune,
    };
    let mut best_reference = if ties_win { u32::MAX } else { 0 };
    let mut found = false;
    let root = inst.blas_root as usize;
    walk_binary_bvh(
        geometry.bvh_nodes,
        root,
        &r,
        t_prune,
        |first, count, node_entry, prune| {
            for i in first..first + count {
                let reference = geometry.bvh_primitives[i as usize];
                let triangle = reference & PRIMITIVE_INDEX_MASK;
                let tri = &geometry.triangles[triangle as usize];
                let t = hit_scene_triangle(&geometry.alpha, triangle, tri, &r.tri);
                if hit_comes_first(t, reference, best.t, best_reference) {
                    *prune = t.max(node_entry);
                    best = InstanceHit {
                        t,
                        triangle,
                        prune: *prune,
                    };
                    best_reference = reference;
                    found = true;
                    if any_hit {
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
