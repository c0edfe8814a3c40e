// The scene's objects in uniform buffers, sized for one scene: the host prepends the counts
// (SPHERE_COUNT, QUAD_COUNT, MATERIAL_COUNT, EMITTER_COUNT) as constants, see src/kernel/variant.rs.
// Why: every lane of a SIMD group tests the same primitive at the same time, and a uniform
// buffer indexed by a constant loop counter lets the compiler load it once for all lanes (and
// unroll the loops), where a storage buffer costs a gather per lane on lavapipe. Arrays hold at
// least one element, since WGSL has no empty arrays.

@group(0) @binding(1) var<uniform> spheres: array<Sphere, max(SPHERE_COUNT, 1u)>;
@group(0) @binding(2) var<uniform> quads: array<Quad, max(QUAD_COUNT, 1u)>;
@group(0) @binding(3) var<uniform> materials: array<Material, max(MATERIAL_COUNT, 1u)>;
@group(0) @binding(6) var<uniform> emitters: array<Emitter, max(EMITTER_COUNT, 1u)>;
// Meshes always go through storage buffers (and the BVH): the uniform layout is for scenes
// without triangles, where these hold one unused element.
@group(0) @binding(8) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(9) var<storage, read> triangle_normals: array<TriangleNormals>;
@group(0) @binding(12) var<storage, read> bvh_nodes: array<BvhNode>;
// The first BVH_UNIFORM_NODES of bvh_nodes again, in a uniform buffer (shaders/traverse/bvh.wgsl).
@group(0) @binding(23) var<uniform> bvh_top_nodes: array<BvhNode, BVH_UNIFORM_NODES>;
@group(0) @binding(13) var<storage, read> bvh_primitives: array<u32>;

fn sphere_count() -> u32 {
    return SPHERE_COUNT;
}

fn quad_count() -> u32 {
    return QUAD_COUNT;
}

fn emitter_count() -> u32 {
    return EMITTER_COUNT;
}

fn triangle_count() -> u32 {
    return 0u;
}
