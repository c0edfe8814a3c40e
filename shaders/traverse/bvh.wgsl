// BVH traversal (mirror: src/cpu/traverse/bvh.rs). One BVH over every sphere, quad, triangle and
// instance, built on the host (src/kernel/bvh/mod.rs) and flattened into bvh_nodes; an instance's
// leaf entry walks its mesh's own BVH (shaders/traverse/blas.wgsl). A fixed stack, the nearer child
// first, and popped nodes skipped when they start beyond the closest hit so far. Shadow rays
// stop at the first primitive in front of the one they aim at. Which hit is the closest, and
// which primitives are in front, is the closest-hit rule's (hit_comes_first), whatever the
// order of visits. The walk itself is binary_walk.wgsl's, the tests the walks share are in
// bvh_ray.wgsl.

// What a search of the scene's primitives has found so far.
struct PrimitiveSearch {
    best: ClosestPrimitive,
    // The top-level reference of the best hit, for the closest-hit rule's ties.
    best_reference: u32,
    // How far the walk still looks: boxes entered beyond it are skipped.
    prune: f32,
    found: bool,
}

fn primitive_search(t_max: f32, t_prune: f32, max_reference: u32) -> PrimitiveSearch {
    return PrimitiveSearch(ClosestPrimitive(t_max, PRIMITIVE_QUAD, 0u, NO_INSTANCE), max_reference, t_prune, false);
}

// The search's result: its best hit, or t = NO_HIT when it found none.
fn search_result(search: PrimitiveSearch) -> ClosestPrimitive {
    var best = search.best;
    if !search.found {
        best.t = NO_HIT;
    }
    return best;
}

// Tests a leaf's primitives, bvh_primitives[first .. first + count], whose box the ray enters
// at node_entry. True when the search is over: a shadow ray found something in front of its
// target.
fn visit_scene_leaf(search: ptr<function, PrimitiveSearch>, first: u32, count: u32, node_entry: f32, r: BvhRay, shadow_target: u32) -> bool {
    for (var i = 0u; i < count; i++) {
        let reference = bvh_primitives[first + i];
        if HAS_INSTANCES && (reference >> PRIMITIVE_KIND_SHIFT) == PRIMITIVE_INSTANCE {
            // Its closest triangle that comes before the best so far: at the same t
            // only if this reference is the lower (the rule, extended by triangle).
            let instance = reference & PRIMITIVE_INDEX_MASK;
            let h = hit_instance(instance, r.ray, (*search).best.t, reference < (*search).best_reference, (*search).prune, shadow_target != NO_PRIMITIVE);
            if h.t != NO_HIT {
                (*search).best = ClosestPrimitive(h.t, PRIMITIVE_TRIANGLE, h.triangle, instance);
                (*search).best_reference = reference;
                (*search).prune = max(h.prune, node_entry);
                (*search).found = true;
                if shadow_target != NO_PRIMITIVE {
                    return true;
                }
            }
            continue;
        }
        let t = hit_primitive(reference, r);
        // The target is excluded by name too, not only by the rule: the compiler may
        // round its test here and in bvh_first_hit_is differently.
        if hit_comes_first(t, reference, (*search).best.t, (*search).best_reference) && reference != shadow_target {
            (*search).best = ClosestPrimitive(t, reference >> PRIMITIVE_KIND_SHIFT, reference & PRIMITIVE_INDEX_MASK, NO_INSTANCE);
            (*search).best_reference = reference;
            (*search).prune = max(t, node_entry);
            (*search).found = true;
            if shadow_target != NO_PRIMITIVE {
                return true;
            }
        }
    }
    return false;
}

fn bvh_traverse(r: BvhRay, t_max: f32, t_prune: f32, max_reference: u32, shadow_target: u32) -> ClosestPrimitive {
    // The wide tree in the wide variant (the GPU's layout: src/kernel/bvh/layout.rs).
    if BVH_WIDE {
        return wide_traverse(r, t_max, t_prune, max_reference, shadow_target);
    }
    var search = primitive_search(t_max, t_prune, max_reference);
    var walk: BinaryWalk;
    if binary_walk_start(&walk, 0u, r, search.prune) {
        loop {
            let node = bvh_node(walk.node_index);
            if node.count > 0u {
                if visit_scene_leaf(&search, node.first, node.count, walk.node_entry, r, shadow_target) {
                    return search.best;
                }
            } else if binary_walk_descend(&walk, node, r, search.prune) {
                continue;
            }
            if !binary_walk_pop(&walk, r, search.prune) {
                break;
            }
        }
    }
    return search_result(search);
}

fn bvh_closest_primitive(ray: Ray) -> ClosestPrimitive {
    return bvh_traverse(bvh_ray(ray), NO_HIT, NO_HIT, 0u, NO_PRIMITIVE);
}

// A shadow target no leaf holds: bvh_escapes' search for any hit. Not a kind's first
// reference (PRIMITIVE_INSTANCE << PRIMITIVE_KIND_SHIFT is instance 0's), but the last one
// below NO_PRIMITIVE, which no scene has that many instances to reach.
const NO_TARGET: u32 = 0xfffffffeu;

// Whether ray hits nothing: a shadow-ray search for any hit, with no target.
fn bvh_escapes(ray: Ray) -> bool {
    return bvh_traverse(bvh_ray(ray), NO_HIT, NO_HIT, 0u, NO_TARGET).t == NO_HIT;
}

fn bvh_first_hit_is(ray: Ray, primitive: u32, index: u32) -> bool {
    let r = bvh_ray(ray);
    let target_ref = (primitive << PRIMITIVE_KIND_SHIFT) | index;
    let t_target = hit_primitive(target_ref, r);
    if t_target == NO_HIT {
        return false;
    }
    // Pruned no earlier than where the ray enters the target's own box: a primitive before it
    // at the same t, a copy of it, is in a box the same as that one.
    let t_prune = max(t_target, primitive_box_entry(target_ref, r));
    return bvh_traverse(r, t_target, t_prune, target_ref, target_ref).t == NO_HIT;
}
