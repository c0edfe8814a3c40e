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
    // The pbr material's transmission, coat (weight, alpha) and white sheen (its colour's
    // value, roughness) (probe_pbr).
    transmission: f32,
    clearcoat: f32,
    clearcoat_alpha: f32,
    sheen: f32,
    sheen_roughness: f32,
    // The coat's own shading normal (probe_pbr); zero: the base's, `normal`.
    coat_normal: vec3<f32>,
}

@group(0) @binding(10) var<uniform> probe: ProbeParams;
@group(0) @binding(11) var<storage, read_write> probe_out: array<vec4<f32>>;

@compute @workgroup_size(256, 1, 1)
fn probe_uniform(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
    probe_out[id.x] = vec4<f32>(rng_next(&rng), rng_next(&rng), rng_next(&rng), rng_next(&rng));
}

// The first four Sobol draws of sample id.x of pixel 7, stream 3 (two 2D points).
@compute @workgroup_size(256, 1, 1)
fn probe_sobol(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_stream(7u, id.x, 3u, probe.seed, SAMPLER_SOBOL);
    probe_out[id.x] = vec4<f32>(rng_next(&rng), rng_next(&rng), rng_next(&rng), rng_next(&rng));
}

@compute @workgroup_size(256, 1, 1)
fn probe_cosine_hemisphere(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
    let u = vec2<f32>(rng_next(&rng), rng_next(&rng));
    probe_out[id.x] = vec4<f32>(sample_cosine_hemisphere(probe.normal, u), 0.0);
}

// Henyey-Greenstein sampling about probe.normal (the direction light travelled) with
// g = probe.alpha: the direction, and the phase function's value for it.
@compute @workgroup_size(256, 1, 1)
fn probe_hg(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
    let u1 = rng_next(&rng);
    let u2 = rng_next(&rng);
    let dir = sample_hg(probe.alpha, probe.normal, u1, u2);
    probe_out[id.x] = vec4<f32>(dir, hg_phase(probe.alpha, dot(probe.normal, dir)));
}

// Light sampling from probe.position in the bound scene: direction and pdf.
@compute @workgroup_size(256, 1, 1)
fn probe_light(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
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
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
    let s = bsdf_sample(probe_material(MATERIAL_METAL), probe.wo, probe.normal, probe.normal, true, &rng);
    probe_out[id.x] = vec4<f32>(s.dir, s.weight.x);
}

// A white dielectric pbr material (metallic 0, specular 1) with probe.transmission.
@compute @workgroup_size(256, 1, 1)
fn probe_pbr(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
    var m = probe_material(MATERIAL_PBR);
    m.specular = 1.0;
    m.specular_color = vec3<f32>(1.0);
    m.transmission = probe.transmission;
    m.clearcoat = probe.clearcoat;
    m.clearcoat_alpha = probe.clearcoat_alpha;
    m.sheen_color = vec3<f32>(probe.sheen);
    m.sheen_roughness = probe.sheen_roughness;
    let coat_normal = select(probe.normal, probe.coat_normal, dot(probe.coat_normal, probe.coat_normal) > 0.0);
    let s = bsdf_sample(m, probe.wo, probe.normal, coat_normal, probe.front_face != 0u, &rng);
    probe_out[id.x] = vec4<f32>(s.dir, s.weight.x);
}

@compute @workgroup_size(256, 1, 1)
fn probe_dielectric(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
    let s = bsdf_sample(probe_material(MATERIAL_DIELECTRIC), probe.wo, probe.normal, probe.normal, probe.front_face != 0u, &rng);
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
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
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
// per entry, in the scene's triangle_uvs[id].uv0 (tests/suite/textures.rs fills them); writes the
// value in xyz.
@compute @workgroup_size(256, 1, 1)
fn probe_texture(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    let uv = interpolated_uv(triangle_uvs[id.x], vec3<f32>(1.0, 0.0, 0.0));
    probe_out[id.x] = vec4<f32>(texture_lookup(probe.seed, both_sets(uv)), 0.0);
}

// The material at a hit: material probe.seed of the bound scene at the texture coordinates of
// triangle_uvs[id / 2].uv0 (tests/suite/gltf_materials.rs fills them); even entries write albedo
// and alpha, odd ones metallic and transmission.
@compute @workgroup_size(256, 1, 1)
fn probe_material_at(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    let m = material_at(materials[probe.seed], triangle_uv(id.x / 2u, vec3<f32>(1.0, 0.0, 0.0)));
    probe_out[id.x] = select(vec4<f32>(m.metallic, m.transmission, 0.0, 0.0), vec4<f32>(m.albedo, m.alpha), id.x % 2u == 0u);
}

// The emitter choice alone (pick_emitter, from the draws sample_light makes first): the
// chosen primitive, its index and the probability reported for it.
@compute @workgroup_size(256, 1, 1)
fn probe_emitter_choice(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
    let u_slot = rng_next(&rng);
    let u_alias = rng_next(&rng);
    let e = pick_emitter(u_slot, u_alias);
    probe_out[id.x] = vec4<f32>(f32(e.primitive), f32(e.index), e.probability, 0.0);
}

// The closest-hit rule (tests/suite/closest_hit.rs): rays from points within probe.alpha / 2 per axis
// of probe.position, aimed at random points of random spheres, quads and triangles (or anywhere),
// each traced by the kernel variant's structure (the BVH, or ray queries in the hardware
// variant) and by the scan of every primitive. Needs the BVH or the hardware kernel variant.
// Writes, per ray, two entries: the BVH's closest hit (t, kind, index, as bits) and flags, then
// the scan's closest hit and 0. The flags: 1 when the BVH's shadow test finds the scan's hit
// first, 2 when it finds a later primitive of its kind (probe.normal[kind] further on: the next
// copy in a scene of copies) first, 4 when the BVH
// finds that the ray escapes.
@compute @workgroup_size(256, 1, 1)
fn probe_closest_hit(@builtin(global_invocation_id) id: vec3<u32>) {
    if 2u * id.x + 1u >= probe.count {
        return;
    }
    var rng = rng_stream(id.x, 0u, 1u, probe.seed, SAMPLER_INDEPENDENT);
    let box = vec3<f32>(rng_next(&rng), rng_next(&rng), rng_next(&rng)) - vec3<f32>(0.5);
    let origin = probe.position + probe.alpha * box;
    let pick = rng_next(&rng);
    let a = rng_next(&rng);
    let b = rng_next(&rng);
    let offset = vec3<f32>(rng_next(&rng), rng_next(&rng), rng_next(&rng)) - vec3<f32>(0.5);
    var aim = probe.position + probe.alpha * offset;
    let kind = id.x % 4u;
    if kind == 1u && sphere_count() > 0u {
        let s = spheres[min(u32(pick * f32(sphere_count())), sphere_count() - 1u)];
        aim = s.center + 2.0 * s.radius * offset;
    } else if kind == 2u && quad_count() > 0u {
        let q = quads[min(u32(pick * f32(quad_count())), quad_count() - 1u)];
        aim = q.corner + a * q.edge_u + b * q.edge_v;
    } else if kind == 3u && triangle_count() > 0u {
        let t = triangles[min(u32(pick * f32(triangle_count())), triangle_count() - 1u)];
        aim = select(mix(t.v0, t.v1, a), t.v2, b < 0.25);
    }
    let ray = Ray(origin, normalize(aim - origin));
    let found = closest_primitive(ray);
    let expected = scan_closest_primitive(ray);
    var flags = 0u;
    // A shadow ray's target is never a triangle hit through an instance (no light is one):
    // there the instance is compared instead, 8 flagging a different one.
    if expected.t != NO_HIT && (expected.instance != NO_INSTANCE || first_hit_is(ray, expected.primitive, expected.index)) {
        flags |= 1u;
    }
    if found.instance != expected.instance {
        flags |= 8u;
    }
    let kind_count = select(select(triangle_count(), quad_count(), expected.primitive == PRIMITIVE_QUAD), sphere_count(), expected.primitive == PRIMITIVE_SPHERE);
    let stride = u32(probe.normal[min(expected.primitive, 2u)]);
    let next = expected.index + stride;
    if expected.t != NO_HIT && expected.instance == NO_INSTANCE && next < kind_count && first_hit_is(ray, expected.primitive, next) {
        flags |= 2u;
    }
    if escapes(ray) {
        flags |= 4u;
    }
    probe_out[2u * id.x] = vec4<f32>(found.t, bitcast<f32>(found.primitive), bitcast<f32>(found.index), f32(flags));
    probe_out[2u * id.x + 1u] = vec4<f32>(expected.t, bitcast<f32>(expected.primitive), bitcast<f32>(expected.index), 0.0);
}

// Normal maps (tests/suite/normal_maps.rs): rays from probe.position to a 16 x 16 grid of points
// (x, y, 0) with x, y = -0.45 + 0.9 (i + 0.5) / 16, each hit's shading normal after its
// material's normal map (as path_step applies it), and t.
@compute @workgroup_size(256, 1, 1)
fn probe_normal_map(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= probe.count {
        return;
    }
    let aim = vec3<f32>(-0.45 + 0.9 * (f32(id.x % 16u) + 0.5) / 16.0, -0.45 + 0.9 * (f32(id.x / 16u) + 0.5) / 16.0, 0.0);
    let ray = Ray(probe.position, normalize(aim - probe.position));
    var hit = intersect_scene(ray);
    if hit.t == NO_HIT {
        probe_out[id.x] = vec4<f32>(0.0, 0.0, 0.0, -1.0);
        return;
    }
    let m = material_at(materials[hit.material], hit.uv);
    if m.normal_texture != NO_TEXTURE && hit.primitive == PRIMITIVE_TRIANGLE {
        hit.shading_normal = normal_mapped(hit, m.normal_texture, m.normal_scale, -ray.dir);
    }
    probe_out[id.x] = vec4<f32>(hit.shading_normal, hit.t);
}
