// Test-only entry points that run the kernel's sampling routines and write the samples out,
// so the χ² tests check the WGSL itself, not only its CPU mirror. Appended to the kernel's
// parts (shaders/*.wgsl), it sees every function the kernel has.

struct ProbeParams {
    normal: vec3<f32>,
    count: u32,
    wo: vec3<f32>,
    seed: u32,
    position: vec3<f32>,
    alpha: f32,
    // `position` moved off the surface to the side light arrives from (see sample_light).
    side_probe: vec3<f32>,
    ior: f32,
    front_face: u32,
}

@group(0) @binding(10) var<uniform> probe: ProbeParams;
@group(0) @binding(11) var<storage, read_write> probe_out: array<vec4<f32>>;

@compute @workgroup_size(256, 1, 1)
fn probe_uniform(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_init(id.x, 0u, 1u, probe.seed);
    probe_out[id.x] = vec4<f32>(rng_next(&rng), rng_next(&rng), rng_next(&rng), rng_next(&rng));
}

@compute @workgroup_size(256, 1, 1)
fn probe_cosine_hemisphere(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_init(id.x, 0u, 1u, probe.seed);
    let u = vec2<f32>(rng_next(&rng), rng_next(&rng));
    probe_out[id.x] = vec4<f32>(sample_cosine_hemisphere(probe.normal, u), 0.0);
}

// Light sampling from probe.position in the bound scene: direction and pdf.
@compute @workgroup_size(256, 1, 1)
fn probe_light(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_init(id.x, 0u, 1u, probe.seed);
    let light = sample_light(probe.position, probe.side_probe, &rng);
    probe_out[id.x] = vec4<f32>(light.dir, light.pdf);
}

// The BSDF sampled for a material built from the probe parameters: direction, and in w the
// sample's weight (x channel) with the sign of `is_delta` folded into a flag: w = weight for
// non-delta samples, -1 - weight for delta ones.
fn probe_material(kind: u32) -> Material {
    var m: Material;
    m.albedo = vec3<f32>(1.0);
    m.kind = kind;
    m.alpha = probe.alpha;
    m.ior = probe.ior;
    return m;
}

@compute @workgroup_size(256, 1, 1)
fn probe_metal(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_init(id.x, 0u, 1u, probe.seed);
    let s = bsdf_sample(probe_material(MATERIAL_METAL), probe.wo, probe.normal, true, &rng);
    probe_out[id.x] = vec4<f32>(s.dir, s.weight.x);
}

@compute @workgroup_size(256, 1, 1)
fn probe_dielectric(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_init(id.x, 0u, 1u, probe.seed);
    let s = bsdf_sample(probe_material(MATERIAL_DIELECTRIC), probe.wo, probe.normal, probe.front_face != 0u, &rng);
    probe_out[id.x] = vec4<f32>(s.dir, s.weight.x);
}

// Watertightness: rays from points near probe.position (inside the bound scene's closed mesh,
// within probe.alpha / 2 per axis) aimed exactly at a triangle's first vertex, the midpoint of
// its first edge, or a random point on that edge; writes the t of the closest hit (NO_HIT for a
// ray that slipped through).
@compute @workgroup_size(256, 1, 1)
fn probe_watertight(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_init(id.x, 0u, 1u, probe.seed);
    let n = params.triangle_count;
    let tri = triangles[min(u32(rng_next(&rng) * f32(n)), n - 1u)];
    let along = rng_next(&rng);
    var aim = tri.v0;
    if id.x % 3u == 1u {
        aim = 0.5 * (tri.v0 + tri.v1);
    } else if id.x % 3u == 2u {
        aim = mix(tri.v0, tri.v1, along);
    }
    let jitter = vec3<f32>(rng_next(&rng), rng_next(&rng), rng_next(&rng)) - vec3<f32>(0.5);
    let origin = probe.position + probe.alpha * jitter;
    probe_out[id.x] = vec4<f32>(closest_primitive(Ray(origin, normalize(aim - origin))).t, 0.0, 0.0, 0.0);
}

// Texture lookups: texture probe.seed of the bound scene at the texture coordinates held, one
// per entry, in the scene's triangle_uvs[id].uv0 (tests/textures.rs fills them); writes the
// value in xyz.
@compute @workgroup_size(256, 1, 1)
fn probe_texture(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    let uv = triangle_uv(id.x, vec3<f32>(1.0, 0.0, 0.0));
    probe_out[id.x] = vec4<f32>(texture_lookup(probe.seed, uv), 0.0);
}

// The material at a hit: material probe.seed of the bound scene at the texture coordinates of
// triangle_uvs[id / 2].uv0 (tests/gltf_materials.rs fills them); even entries write albedo
// and alpha, odd ones metallic.
@compute @workgroup_size(256, 1, 1)
fn probe_material_at(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    let m = material_at(materials[probe.seed], triangle_uv(id.x / 2u, vec3<f32>(1.0, 0.0, 0.0)));
    probe_out[id.x] = select(vec4<f32>(m.metallic, 0.0, 0.0, 0.0), vec4<f32>(m.albedo, m.alpha), id.x % 2u == 0u);
}
