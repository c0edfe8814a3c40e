// What the BVH walks share (mirror: src/cpu/traverse/bvh_ray.rs): the ray with its reciprocal
// direction, the box test and its rounding slack, and the leaves' primitive tests. The walks
// themselves are binary_walk.wgsl (for bvh.wgsl and blas.wgsl) and wide.wgsl.

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
