// The bottom level of the two-level structure (mirror: src/cpu/traverse/blas.rs): an instance
// in the top-level BVH (shaders/traverse/bvh.wgsl) is hit by walking its mesh's own BVH, laid out in
// bvh_nodes after the top level's, with the ray in the mesh's coordinates
// (shaders/geometry/instance.wgsl). The walk is bvh_traverse's (binary_walk.wgsl), over
// triangles only.

// An instance's closest triangle: its t (NO_HIT for none), its index in the triangle arrays,
// and how far the walk still looked once it had it (max of t and the entry into its leaf).
struct InstanceHit {
    t: f32,
    triangle: u32,
    prune: f32,
}

// The closest of instance `instance`'s triangles along ray (in the scene's coordinates) that
// comes before the best hit so far, at t_max: at t_max itself only when `ties_win` (the
// instance's reference is below the best's), and then the lowest triangle, so the rule holds
// lexicographically on (t, top-level reference, triangle). Boxes beyond t_prune are skipped, as
// in bvh_traverse; `any_hit` returns the first such triangle found (shadow rays).
fn hit_instance(instance: u32, ray: Ray, t_max: f32, ties_win: bool, t_prune: f32, any_hit: bool) -> InstanceHit {
    let inst = instances[instance];
    let r = bvh_ray(object_ray(inst, ray));
    var best = InstanceHit(t_max, 0u, t_prune);
    var best_reference = select(0u, 0xffffffffu, ties_win);
    var found = false;
    var walk: BinaryWalk;
    if !binary_walk_start(&walk, inst.blas_root, r, t_prune) {
        return InstanceHit(NO_HIT, 0u, t_prune);
    }
    loop {
        let node = bvh_node(walk.node_index);
        if node.count > 0u {
            for (var i = 0u; i < node.count; i++) {
                let reference = bvh_primitives[node.first + i];
                let triangle = reference & PRIMITIVE_INDEX_MASK;
                let t = hit_scene_triangle(triangle, r.tri);
                if hit_comes_first(t, reference, best.t, best_reference) {
                    best = InstanceHit(t, triangle, max(t, walk.node_entry));
                    best_reference = reference;
                    found = true;
                    if any_hit {
                        return best;
                    }
                }
            }
        } else if binary_walk_descend(&walk, node, r, best.prune) {
            continue;
        }
        if !binary_walk_pop(&walk, r, best.prune) {
            break;
        }
    }
    if !found {
        best.t = NO_HIT;
    }
    return best;
}
