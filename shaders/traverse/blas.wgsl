// The bottom level of the two-level structure (mirror: src/cpu/traverse/blas.rs): an instance
// in the top-level BVH (shaders/traverse/bvh.wgsl) is hit by walking its mesh's own BVH, laid out in
// bvh_nodes after the top level's, with the ray in the mesh's coordinates
// (shaders/geometry/instance.wgsl). The walk is bvh_traverse's, over triangles only: WGSL has no
// recursion nor function parameters, so the loop is written again rather than shared.

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
    var stack: array<u32, BVH_STACK_SIZE>;
    var top = 0u;
    var node_index = inst.blas_root;
    var node_entry = hit_box(bvh_node(node_index), r, t_prune);
    if node_entry == NO_HIT {
        return InstanceHit(NO_HIT, 0u, t_prune);
    }
    loop {
        let node = bvh_node(node_index);
        if node.count > 0u {
            for (var i = 0u; i < node.count; i++) {
                let reference = bvh_primitives[node.first + i];
                let triangle = reference & PRIMITIVE_INDEX_MASK;
                let t = hit_scene_triangle(triangle, r.tri);
                if hit_comes_first(t, reference, best.t, best_reference) {
                    best = InstanceHit(t, triangle, max(t, node_entry));
                    best_reference = reference;
                    found = true;
                    if any_hit {
                        return best;
                    }
                }
            }
        } else {
            let left = node.first;
            let t_left = hit_box(bvh_node(left), r, best.prune);
            let t_right = hit_box(bvh_node(left + 1u), r, best.prune);
            if t_left != NO_HIT && t_right != NO_HIT {
                let left_first = t_left <= t_right;
                stack[top] = select(left, left + 1u, left_first);
                top += 1u;
                node_index = select(left + 1u, left, left_first);
                node_entry = min(t_left, t_right);
                continue;
            }
            if t_left != NO_HIT {
                node_index = left;
                node_entry = t_left;
                continue;
            }
            if t_right != NO_HIT {
                node_index = left + 1u;
                node_entry = t_right;
                continue;
            }
        }
        var popped = false;
        while top > 0u {
            top -= 1u;
            let entry = hit_box(bvh_node(stack[top]), r, best.prune);
            if entry != NO_HIT {
                node_index = stack[top];
                node_entry = entry;
                popped = true;
                break;
            }
        }
        if !popped {
            break;
        }
    }
    if !found {
        best.t = NO_HIT;
    }
    return best;
}
