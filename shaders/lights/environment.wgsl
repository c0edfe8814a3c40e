// The environment map: its radiance for escaping rays, and importance sampling of it for
// next-event estimation (mirror: src/cpu/lights/environment.rs). The conventions and the exact pdf
// are in src/scene/environment.rs, where the tables are built. Compiled in only for scenes
// with a map (HAS_ENVIRONMENT); storage buffers in every scene layout.

@group(0) @binding(18) var<storage, read> environment_texels: array<EnvironmentTexel>;
@group(0) @binding(19) var<storage, read> environment_alias: array<EnvironmentAlias>;

// A scene direction in the map's frame: turned by -rotate about +y.
fn to_map_frame(d: vec3<f32>) -> vec3<f32> {
    let c = params.environment_cos;
    let s = params.environment_sin;
    return vec3<f32>(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

// A direction in the map's frame in the scene: turned by +rotate about +y.
fn from_map_frame(d: vec3<f32>) -> vec3<f32> {
    let c = params.environment_cos;
    let s = params.environment_sin;
    return vec3<f32>(c * d.x + s * d.z, d.y, c * d.z - s * d.x);
}

// Index of the texel a unit direction (in the scene) looks at. The angles come from the
// polynomial atan2 the textures use (not atan2 and acos, which Vulkan lets be 4096 ulps off),
// so the GPU picks the CPU's texel; theta = atan2(sqrt(x^2 + z^2), y) keeps its precision at
// the poles, where acos(y) loses it.
fn environment_texel_index(dir: vec3<f32>) -> u32 {
    let d = to_map_frame(dir);
    var u = polynomial_atan2(d.x, -d.z) * (0.5 / PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = polynomial_atan2(sqrt(d.x * d.x + d.z * d.z), d.y) * (1.0 / PI);
    let w = params.environment_width;
    let h = params.environment_height;
    let x = min(u32(u * f32(w)), w - 1u);
    let y = min(u32(v * f32(h)), h - 1u);
    return y * w + x;
}

// Radiance arriving from the map along -dir (seen looking along dir).
fn environment_radiance(dir: vec3<f32>) -> vec3<f32> {
    return environment_texels[environment_texel_index(dir)].radiance;
}

// Solid-angle pdf with which sample_environment picks dir (selection excluded).
fn environment_pdf(dir: vec3<f32>) -> f32 {
    return environment_texels[environment_texel_index(dir)].pdf;
}

struct EnvironmentSample {
    dir: vec3<f32>,
    // Solid-angle pdf (selection among emitters excluded).
    pdf: f32,
    radiance: vec3<f32>,
}

// A direction towards the map, drawn in proportion to luminance: a texel by the alias table
// (u.x picks the entry, u.y decides between it and its alias), then uniformly in solid angle
// within it (rng's next two numbers: phi, then cos theta).
fn sample_environment(u: vec2<f32>, rng: ptr<function, Rng>) -> EnvironmentSample {
    let w = params.environment_width;
    let h = params.environment_height;
    let n = w * h;
    let k = min(u32(u.x * f32(n)), n - 1u);
    let entry = environment_alias[k];
    let texel = select(entry.alias_texel, k, u.y < entry.threshold);
    let x = texel % w;
    let y = texel / w;
    let within_phi = rng_next(rng);
    let within_cos = rng_next(rng);
    let phi = 2.0 * PI * (f32(x) + within_phi) / f32(w);
    // cos theta from the texel's top edge down by a uniform share of the row's cos theta
    // extent, 2 sin(theta_c) sin(pi/2H), which keeps its precision near the poles.
    let cos_top = cos(PI * f32(y) / f32(h));
    let extent = 2.0 * sin(PI * (f32(y) + 0.5) / f32(h)) * sin(0.5 * PI / f32(h));
    let cos_theta = clamp(cos_top - within_cos * extent, -1.0, 1.0);
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let local = vec3<f32>(sin_theta * sin(phi), cos_theta, -sin_theta * cos(phi));
    let t = environment_texels[texel];
    return EnvironmentSample(from_map_frame(local), t.pdf, t.radiance);
}
