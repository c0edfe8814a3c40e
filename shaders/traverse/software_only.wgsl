// The hardware traversal's entry points in every kernel variant but the hardware one
// (shaders/traverse/hardware.wgsl), where USE_RAY_QUERY is false and intersect.wgsl never
// calls them: the variant compiles without ray queries, and these cost nothing.

fn hardware_closest_primitive(ray: Ray) -> ClosestPrimitive {
    return ClosestPrimitive(NO_HIT, PRIMITIVE_QUAD, 0u, NO_INSTANCE);
}

fn hardware_escapes(ray: Ray) -> bool {
    return true;
}

fn hardware_first_hit_is(ray: Ray, primitive: u32, index: u32) -> bool {
    return false;
}
