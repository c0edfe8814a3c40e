// BVH traversal (mirror: src/cpu/traverse/bvh.rs). One BVH over every sphere, quad, triangle and
// instance, built on the host (src/kernel/bvh/mod.rs) and flattened into bvh_nodes; an instance's
// leaf entry walks its mesh's own BVH (shaders/traverse/blas.wgsl). A fixed stack, the nearer child
// first, and popped nodes skipped when they start beyond the closest hit so far. Shadow rays
// stop at the first primitive in front of the one they aim at. Which hit is the closest, and
// which primitives are in front, is the closest-hit rule's (hit_comes_first), whatever the
// order of visits.

// The traversal stack's length, BVH_STACK_SIZE, comes from the host with the scene's layout:
// enough for this scene's tree (kernel_stack_size in src/kernel/bvh/mod.rs).

// A ray with what the box and triangle tests share across nodes.
struct BvhRay {
    ray: Ray,
    // 1 / dir, with zero components replaced by a tiny value of the same sign, so the slab
    // test never multiplies 0 by infinity.
    inv_dir: vec3<f32>,
    tri: TriangleRay,
}

fn bvh_ray(ray: Ray) -> BvhRay {
    let tiny = select(vec3<f32>(-1e-20), vec3<f32>(1e-20), ray.dir >= vec3<f32>(0.0));
    let dir = select(ray.dir, tiny, abs(ray.dir) < vec3<f32>(1e-20));
    return BvhRay(ray, 1.0 / dir, triangle_ray(ray));
}

// 1 + 2 gamma(3), a little more than the relative rounding error of a slab distance or a
// triangle's t (Ize, "Robust BVH Ray Traversal", 2013).
const BOX_SLACK: f32 = 1.0000004;

// t widened by BOX_SLACK; NO_HIT stays NO_HIT rather than overflowing.
fn widened(t: f32) -> f32 {
    return select(t * BOX_SLACK, t, t > 1e38);
}

// Where the ray enters a node's box (0 when it starts inside), or NO_HIT when it misses the box
// or enters it beyond t_max. The exit distance and t_max are widened by BOX_SLACK, so rounding
// never drops a box the ray grazes, nor one whose primitive is hit within an ulp of the best
// hit so far (as at a vertex many triangles share): the primitive tests decide those.
fn hit_box(node: BvhNode, r: BvhRay, t_max: f32) -> f32 {
    let t0 = (node.min - r.ray.origin) * r.inv_dir;
    let t1 = (node.max - r.ray.origin) * r.inv_dir;
    let near = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    let far = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z)) * BOX_SLACK;
    if near <= min(far, widened(t_max)) {
        return near;
    }
    return NO_HIT;
}

// Node i, from the uniform copy of the top of the tree when it is there: lavapipe loads from a
// uniform buffer with one gather, from a storage buffer with a loop over the lanes (see
// bvh_uniform_nodes in src/kernel/variant.rs). The values are the same, so the paths are too.
fn bvh_node(i: u32) -> BvhNode {
    if i < BVH_UNIFORM_NODES {
        return bvh_top_nodes[i];
    }
    return bvh_nodes[i];
}

fn hit_primitive(reference: u32, r: BvhRay) -> f32 {
    let kind = reference >> PRIMITIVE_KIND_SHIFT;
    let index = reference & PRIMITIVE_INDEX_MASK;
    if kind == PRIMITIVE_TRIANGLE {
        return hit_scene_triangle(index, r.tri);
    }
    if kind == PRIMITIVE_QUAD {
        return hit_quad(quads[index], r.ray);
    }
    return hit_sphere(spheres[index], r.ray);
}

// Where r enters the box of the primitive `reference` (the box the host builds the BVH over:
// primitive_boxes in src/kernel/bvh/mod.rs, the same arithmetic), or NO_HIT.
fn primitive_box_entry(reference: u32, r: BvhRay) -> f32 {
    let kind = reference >> PRIMITIVE_KIND_SHIFT;
    let index = reference & PRIMITIVE_INDEX_MASK;
    var bounds: BvhNode;
    if kind == PRIMITIVE_TRIANGLE {
        let t = triangles[index];
        bounds.min = min(min(t.v0, t.v1), t.v2);
        bounds.max = max(max(t.v0, t.v1), t.v2);
    } else if kind == PRIMITIVE_QUAD {
        let q = quads[index];
        let pu = q.corner + q.edge_u;
        let pv = q.corner + q.edge_v;
        let puv = pu + q.edge_v;
        bounds.min = min(min(q.corner, pu), min(pv, puv));
        bounds.max = max(max(q.corner, pu), max(pv, puv));
    } else {
        let s = spheres[index];
        bounds.min = s.center - vec3<f32>(s.radius);
        bounds.max = s.center + vec3<f32>(s.radius);
    }
    return hit_box(bounds, r, NO_HIT);
}

// The closest primitive through the BVH that comes before the bound (t_max, max_reference) by
// the closest-hit rule (hit_comes_first); a closest-hit search passes (NO_HIT, 0), which no
// miss comes before. With `shadow_target` not NO_PRIMITIVE, it is a shadow ray's test instead:
// the bound is the target's hit, and the first other primitive before it ends the search
// (returned with its t); none found returns t = NO_HIT.
//
// Boxes are skipped when the ray enters them beyond t_prune (at least t_max), and once a hit is
// found, beyond its t or, if later, where the ray enters the box of the leaf it is in. Rounding
// can put a primitive's t a few ulps before its own box's entry, so a copy of it (hit at the
// same t, and coming before it by the rule) in a box of its own, the same box, must be compared
// against that entry, not the t, or it would be skipped.
const NO_PRIMITIVE: u32 = 0xffffffffu;

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
