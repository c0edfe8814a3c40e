// BVH traversal (mirror: src/cpu/bvh.rs). One BVH over every sphere, quad and triangle, built
// on the host (src/scene/bvh.rs) and flattened into bvh_nodes. A fixed stack, the nearer child
// first, and popped nodes skipped when they start beyond the closest hit so far. Shadow rays
// stop at the first primitive in front of the one they aim at.

// The traversal stack's length, BVH_STACK_SIZE, comes from the host with the scene's layout:
// enough for this scene's tree (kernel_stack_size in src/scene/bvh.rs).

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
// bvh_uniform_nodes in src/shader.rs). The values are the same, so the paths are too.
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
        return hit_triangle(triangles[index], r.tri);
    }
    if kind == PRIMITIVE_QUAD {
        return hit_quad(quads[index], r.ray);
    }
    return hit_sphere(spheres[index], r.ray);
}

// The closest primitive through the BVH. With `shadow_target` not NO_PRIMITIVE, it is a shadow
// ray's test instead: t_max is the target's distance, and the first other primitive nearer than
// that ends the search (returned with its t); none found returns t = NO_HIT.
const NO_PRIMITIVE: u32 = 0xffffffffu;

fn bvh_traverse(r: BvhRay, t_max: f32, shadow_target: u32) -> ClosestPrimitive {
    var best = ClosestPrimitive(t_max, PRIMITIVE_QUAD, 0u);
    var found = false;
    // Node indices only: a popped node's entry distance is recomputed (the same arithmetic,
    // so the same decision), which halves the per-lane stack lavapipe keeps in memory.
    var stack: array<u32, BVH_STACK_SIZE>;
    var top = 0u;
    var node_index = 0u;
    if hit_box(bvh_node(0u), r, best.t) == NO_HIT {
        return ClosestPrimitive(NO_HIT, PRIMITIVE_QUAD, 0u);
    }
    loop {
        let node = bvh_node(node_index);
        if node.count > 0u {
            for (var i = 0u; i < node.count; i++) {
                let reference = bvh_primitives[node.first + i];
                let t = hit_primitive(reference, r);
                if t < best.t && reference != shadow_target {
                    best = ClosestPrimitive(t, reference >> PRIMITIVE_KIND_SHIFT, reference & PRIMITIVE_INDEX_MASK);
                    found = true;
                    if shadow_target != NO_PRIMITIVE {
                        return best;
                    }
                }
            }
        } else {
            let left = node.first;
            let t_left = hit_box(bvh_node(left), r, best.t);
            let t_right = hit_box(bvh_node(left + 1u), r, best.t);
            if t_left != NO_HIT && t_right != NO_HIT {
                let left_first = t_left <= t_right;
                stack[top] = select(left, left + 1u, left_first);
                top += 1u;
                node_index = select(left + 1u, left, left_first);
                continue;
            }
            if t_left != NO_HIT {
                node_index = left;
                continue;
            }
            if t_right != NO_HIT {
                node_index = left + 1u;
                continue;
            }
        }
        // Pop the next node that may still hold something nearer than the best hit.
        var popped = false;
        while top > 0u {
            top -= 1u;
            if hit_box(bvh_node(stack[top]), r, best.t) != NO_HIT {
                node_index = stack[top];
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
    return bvh_traverse(bvh_ray(ray), NO_HIT, NO_PRIMITIVE);
}

// Whether ray hits nothing: a shadow-ray search for any hit, with no target.
fn bvh_escapes(ray: Ray) -> bool {
    return bvh_traverse(bvh_ray(ray), NO_HIT, PRIMITIVE_ENVIRONMENT << PRIMITIVE_KIND_SHIFT).t == NO_HIT;
}

fn bvh_first_hit_is(ray: Ray, primitive: u32, index: u32) -> bool {
    let r = bvh_ray(ray);
    let target_ref = (primitive << PRIMITIVE_KIND_SHIFT) | index;
    let t_target = hit_primitive(target_ref, r);
    if t_target == NO_HIT {
        return false;
    }
    return bvh_traverse(r, t_target, target_ref).t == NO_HIT;
}
