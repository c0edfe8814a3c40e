// Auxiliary outputs (AOVs) for the denoiser (mirror: src/cpu/integrator/aov.rs): per camera path, the
// albedo and the shading normal at the first non-specular vertex (mirror and glass chains are
// followed, as Open Image Denoise asks) and the camera distance of the first hit. Averaged per
// pixel like the mean radiance. Compiled in only when asked for (AOVS, src/kernel/variant.rs).

// Depth of a camera ray that leaves the scene: +inf stands for it, as a finite value, so
// running means stay finite.
const BACKGROUND_DEPTH: f32 = 1e30;

// Per pixel, over all samples so far: mean albedo (xyz) and mean depth (w); mean normal (xyz).
@group(0) @binding(10) var<storage, read_write> aov_albedo_depth: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> aov_normal: array<vec4<f32>>;

// Whether this kernel (compiled with AOVS) is asked for AOVs (params.aovs).
fn aovs_on() -> bool {
    return AOVS && params.aovs != 0u;
}

// One path's AOVs, filled in as the path meets its first surfaces.
struct PathAov {
    albedo: vec3<f32>,
    normal: vec3<f32>,
    depth: f32,
    // True once the first non-specular vertex (or an emitter, or the background) is recorded.
    found: bool,
}

fn aov_start() -> PathAov {
    return PathAov(vec3<f32>(0.0), vec3<f32>(0.0), BACKGROUND_DEPTH, false);
}

// The path's ray left the scene: the clamped radiance it sees there (the background, or the
// environment map in its direction) is the albedo. (These take and return values: naga's
// SPIR-V writer fails on pointers to a struct's member.)
fn aov_record_miss(aov: PathAov, escaped: vec3<f32>) -> PathAov {
    var out = aov;
    if !out.found {
        out.albedo = clamp(escaped, vec3<f32>(0.0), vec3<f32>(1.0));
        out.found = true;
    }
    return out;
}

// The ray of segment `bounce` hit material `m`: the first hit gives the depth; the first
// emitter or non-specular surface gives the albedo (an emitter's clamped radiance) and normal.
fn aov_record_hit(aov: PathAov, bounce: u32, hit: Hit, m: Material) -> PathAov {
    var out = aov;
    if bounce == 0u {
        out.depth = hit.t;
    }
    if out.found {
        return out;
    }
    if any(m.emission > vec3<f32>(0.0)) {
        out.albedo = clamp(m.emission, vec3<f32>(0.0), vec3<f32>(1.0));
    } else if !is_delta(m) {
        out.albedo = m.albedo;
    } else {
        return out;
    }
    out.normal = hit.shading_normal;
    out.found = true;
    return out;
}

// Running mean of a batch's path AOVs, as the kernel keeps the radiance's.
struct AovMean {
    albedo: vec3<f32>,
    normal: vec3<f32>,
    depth: f32,
}

fn aov_mean_start() -> AovMean {
    return AovMean(vec3<f32>(0.0), vec3<f32>(0.0), 0.0);
}

// Adds the (done + 1)-th sample of the batch.
fn aov_mean_add(mean: ptr<function, AovMean>, aov: PathAov, done: u32) {
    let w = 1.0 / f32(done + 1u);
    (*mean).albedo += (aov.albedo - (*mean).albedo) * w;
    (*mean).normal += (aov.normal - (*mean).normal) * w;
    (*mean).depth += (aov.depth - (*mean).depth) * w;
}

// Merges the batch's means (n_new samples) into the pixel's (n_old samples before them).
fn aov_merge(pixel: u32, batch: AovMean, n_old: f32, n_new: f32) {
    let w = n_new / (n_old + n_new);
    let old_ad = aov_albedo_depth[pixel];
    let new_ad = vec4<f32>(batch.albedo, batch.depth);
    aov_albedo_depth[pixel] = old_ad + (new_ad - old_ad) * w;
    let old_n = aov_normal[pixel].xyz;
    aov_normal[pixel] = vec4<f32>(old_n + (batch.normal - old_n) * w, 0.0);
}
