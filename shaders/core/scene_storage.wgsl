// The scene's objects in storage buffers: any number of them, with the counts in Params.
// The general layout; scene_uniform.wgsl is the fast one for scenes that fit uniform buffers.

@group(0) @binding(1) var<storage, read> spheres: array<Sphere>;
@group(0) @binding(2) var<storage, read> quads: array<Quad>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
@group(0) @binding(6) var<storage, read> emitters: array<Emitter>;
@group(0) @binding(8) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(9) var<storage, read> triangle_normals: array<TriangleNormals>;
@group(0) @binding(12) var<storage, read> bvh_nodes: array<BvhNode>;
// The first BVH_UNIFORM_NODES of bvh_nodes again, in a uniform buffer (shaders/traverse/bvh.wgsl).
@group(0) @binding(23) var<uniform> bvh_top_nodes: array<BvhNode, BVH_UNIFORM_NODES>;
@group(0) @binding(13) var<storage, read> bvh_primitives: array<u32>;

fn sphere_count() -> u32 {
    return params.sphere_count;
}

fn quad_count() -> u32 {
    return params.quad_count;
}

fn emitter_count() -> u32 {
    return params.emitter_count;
}

fn triangle_count() -> u32 {
    return params.triangle_count;
}
