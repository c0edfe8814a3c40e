// BVH traversal (mirror: src/cpu/traverse/bvh.rs). One BVH over every sphere, quad, triangle and
// instance, built on the host (src/kernel/bvh/mod.rs) and flattened into bvh_nodes; an instance's
// leaf entry walks its mesh's own BVH (shaders/traverse/blas.wgsl). A fixed stack, the nearer child
// first, and popped nodes skipped when they start beyond the closest hit so far. Shadow rays
// stop at the first primitive in front of the one they aim at. Which hit is the closest, and
// which primitives are in front, is the closest-hit rule's (hit_comes_first), whatever the
// order of visits. The tests the walks share are in bvh_ray.wgsl.

fn bvh_traverse(r: BvhRay, t_max: f32, t_prune: f32, max_reference: u32, shadow_target: u32) -> ClosestPrimitive {
    // The wide tree in the wide variant (the GPU's layout: src/kernel/bvh/layout.rs).
    if BVH_WIDE {
        return wide_traverse(r, t_max, t_prune, max_reference, shadow_target);
    }
    var best = ClosestPrimitive(t_max, PRIMITIVE_QUAD, 0u, NO_INSTANCE);
    var best_reference = max_reference;
    var prune = t_prune;
    var found = false;
    // Node indices only: a popped node's entry distance is recomputed (the same arithmetic,
    // so the same decision), which halves the per-lane stack lavapipe keeps in memory.
    var stack: array<u32, BVH_STACK_SIZE>;
    var top = 0u;
    var node_index = 0u;
    // Where the ray enters the node being entered.
    var node_entry = hit_box(bvh_node(0u), r, prune);
    if node_entry == NO_HIT {
        return ClosestPrimitive(NO_HIT, PRIMITIVE_QUAD, 0u, NO_INSTANCE);
    }
    loop {
        let node = bvh_node(node_index);
        if node.count > 0u {
            for (var i = 0u; i < node.count; i++) {
                let reference = bvh_primitives[node.first + i];
                if HAS_INSTANCES && (reference >> PRIMITIVE_KIND_SHIFT) == PRIMITIVE_INSTANCE {
                    // Its closest triangle that comes before the best so far: at the same t
                    // only if this reference is the lower (the rule, extended by triangle).
                    let instance = reference & PRIMITIVE_INDEX_MASK;
                    let h = hit_instance(instance, r.ray, best.t, reference < best_reference, prune, shadow_target != NO_PRIMITIVE);
                    if h.t != NO_HIT {
                        best = ClosestPrimitive(h.t, PRIMITIVE_TRIANGLE, h.triangle, instance);
                        best_reference = reference;
                        prune = max(h.prune, node_entry);
                        found = true;
                        if shadow_target != NO_PRIMITIVE {
                            return best;
                        }
                    }
                    continue;
                }
                let t = hit_primitive(reference, r);
                // The target is excluded by name too, not only by the rule: the compiler may
                // round its test here and in bvh_first_hit_is differently.
                if hit_comes_first(t, reference, best.t, best_reference) && reference != shadow_target {
                    best = ClosestPrimitive(t, reference >> PRIMITIVE_KIND_SHIFT, reference & PRIMITIVE_INDEX_MASK, NO_INSTANCE);
                    best_reference = reference;
                    prune = max(t, node_entry);
                    found = true;
                    if shadow_target != NO_PRIMITIVE {
                        return best;
                    }
                }
            }
        } else {
            let left = node.first;
            let t_left = hit_box(bvh_node(left), r, prune);
            let t_right = hit_box(bvh_node(left + 1u), r, prune);
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
        // Pop the next node that may still hold something before the best hit.
        var popped = false;
        while top > 0u {
            top -= 1u;
            let entry = hit_box(bvh_node(stack[top]), r, prune);
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
