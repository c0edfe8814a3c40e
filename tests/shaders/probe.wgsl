// Test-only entry points that run the kernel's sampling routines and write the samples out,
// so the χ² tests check the WGSL itself, not only its CPU mirror. Appended to the kernel's
// parts (shaders/*.wgsl), it sees every function the kernel has.

struct ProbeParams {
    normal: vec3<f32>,
    count: u32,
    seed: u32,
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
