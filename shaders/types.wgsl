// Data shared by every kernel stage. The Rust side is src/shader_types.rs; the test
// tests/layout.rs checks with naga's layouter that both agree field by field.

struct Params {
    eye: vec3<f32>,
    width: u32,
    // Unit vector from the eye towards the target.
    forward: vec3<f32>,
    height: u32,
    // Image-right and image-up, scaled to half the viewport at unit distance.
    right: vec3<f32>,
    // Samples already in the accumulators: the global index of this batch's first sample.
    sample_start: u32,
    up: vec3<f32>,
    sample_count: u32,
    background: vec3<f32>,
    max_bounces: u32,
    seed: u32,
    sphere_count: u32,
    quad_count: u32,
    material_count: u32,
}

struct Sphere {
    center: vec3<f32>,
    radius: f32,
    material: u32,
}

struct Quad {
    corner: vec3<f32>,
    material: u32,
    edge_u: vec3<f32>,
    area: f32,
    edge_v: vec3<f32>,
    // The plane is dot(normal, p) == plane_offset.
    plane_offset: f32,
    normal: vec3<f32>,
    pad0: f32,
    // edge_u / dot(edge_u, edge_u): dot(u_dual, p - corner) is the position along edge_u in [0, 1].
    u_dual: vec3<f32>,
    pad1: f32,
    v_dual: vec3<f32>,
    pad2: f32,
}

const MATERIAL_DIFFUSE: u32 = 0u;
const MATERIAL_SPECULAR: u32 = 1u;

struct Material {
    albedo: vec3<f32>,
    kind: u32,
    // emission * strength, already multiplied on the host.
    emission: vec3<f32>,
    pad0: f32,
}

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> spheres: array<Sphere>;
@group(0) @binding(2) var<storage, read> quads: array<Quad>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
// Per pixel, over all samples so far: the mean radiance (xyz; w unused) and M2, the sum of
// squared deviations from the mean (xyz), from which the variance follows. Running means and
// M2 stay accurate in f32 over millions of samples, where sums of squares would cancel.
@group(0) @binding(4) var<storage, read_write> accum_mean: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> accum_m2: array<vec4<f32>>;
