// The wide traversal's entry point in every kernel variant but the wide one
// (shaders/traverse/wide.wgsl), where BVH_WIDE is false and bvh.wgsl never calls it: the
// variant needs no wide tree's bindings, and this costs nothing.

fn wide_traverse(r: BvhRay, t_max: f32, t_prune: f32, max_reference: u32, shadow_target: u32) -> ClosestPrimitive {
    return ClosestPrimitive(NO_HIT, PRIMITIVE_QUAD, 0u, NO_INSTANCE);
}
