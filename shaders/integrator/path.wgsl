// Path tracing kernel (mirror: src/cpu/integrator/path.rs): one invocation per pixel adds
// params.sample_count samples, starting at global sample index params.sample_start.

// Segments this invocation traced; added to `segments_traced` once at the end.
var<private> segments: u32 = 0u;

// A path in flight: what one more segment needs.
struct PathState {
    ray: Ray,
    throughput: vec3<f32>,
    radiance: vec3<f32>,
    // The surface point the current ray left from (light pdfs are evaluated there).
    ray_start: vec3<f32>,
    // How the current ray was sampled, for weighting the emitter it may hit.
    bsdf_pdf_of_ray: f32,
    // Segments traced so far: each has its own random streams and alpha key.
    bounce: u32,
    // Interfaces crossed so far (cross_interface): segments without a scattering event.
    crossings: u32,
    came_from_delta: bool,
    // Albedo, normal and depth for the denoiser (aov.wgsl); untouched unless AOVS.
    aov: PathAov,
    // The participating media the ray is in (media/medium.wgsl); empty without media.
    media: MediumStack,
}

// Scattering events so far, at surfaces and in media: what max_bounces, Russian roulette and
// the firefly clamp count (interfaces crossed are not among them).
// Without media no interface is crossed: the constant keeps the subtraction out.
fn scatterings(path: PathState) -> u32 {
    if HAS_MEDIA {
        return path.bounce - path.crossings;
    }
    return path.bounce;
}

// Firefly clamp (`--clamp`, biased): light that has scattered at least once contributes at
// most params.radiance_clamp in its brightest channel, hue kept; 0 turns it off.
fn firefly_clamp(contribution: vec3<f32>, scatterings: u32) -> vec3<f32> {
    let peak = max(contribution.x, max(contribution.y, contribution.z));
    if scatterings > 0u && params.radiance_clamp > 0.0 && peak > params.radiance_clamp {
        return contribution * (params.radiance_clamp / peak);
    }
    return contribution;
}

fn start_path(pixel: u32, px: u32, py: u32, sample: u32) -> PathState {
    var camera_rng = rng_stream(pixel, sample, 0u, params.seed, params.sampler);
    let jitter = vec2<f32>(rng_next(&camera_rng), rng_next(&camera_rng));
    let lens = vec2<f32>(rng_next(&camera_rng), rng_next(&camera_rng));
    let ray = camera_ray(px, py, jitter, lens);
    return PathState(ray, vec3<f32>(1.0), vec3<f32>(0.0), ray.origin, 0.0, 0u, 0u, true, aov_start(), medium_start());
}

// Traces one segment of the path (and its shadow ray); true when the path has ended.
fn path_step(path: ptr<function, PathState>, pixel: u32, sample: u32) -> bool {
    let ray = (*path).ray;
    let bounce = (*path).bounce;
    let light_sampling = LIGHT_SAMPLING && params.light_sampling != 0u && emitter_count() > 0u;
    if HAS_ALPHA {
        // This segment's alpha decisions (alpha.wgsl): segment `bounce`, the one the ray
        // leaving the previous vertex (or the camera) opened.
        alpha_key = alpha_segment_key(pixel, sample, bounce);
    }
    var hit = intersect_scene(ray);
    segments += 1u;
    if HAS_MEDIA {
        let flight = free_flight(path, hit.t, pixel, sample);
        if flight.scattered {
            return medium_vertex(path, ray.origin + flight.t * ray.dir, light_sampling, pixel, sample);
        }
        if all((*path).throughput == vec3<f32>(0.0)) {
            return true;
        }
    }
    if hit.t == NO_HIT {
        add_escaped_light(path, light_sampling);
        return true;
    }
    let m = vertex_colored(material_at(materials[hit.material], hit.uv), hit);
    let coat_normal = apply_normal_maps(m, &hit, -ray.dir);
    if aovs_on() {
        (*path).aov = aov_record_hit((*path).aov, bounce, hit, m);
    }
    if HAS_VOLUME && !hit.front_face {
        // The segment ran inside the volume this surface bounds (volume.wgsl).
        (*path).throughput *= volume_transmittance(m, hit.t);
    }
    add_hit_emission(path, m, hit, light_sampling);
    // Before the bounce limit: a path that has scattered max_bounces times still leaves
    // through the interfaces around it, to the light beyond.
    if HAS_MEDIA && is_interface(m) {
        return cross_interface(path, hit);
    }
    // max_bounces counts scattering events (scatterings()).
    if scatterings(*path) >= params.max_bounces {
        return true;
    }
    let origin = offset_ray_origin(hit.position, hit.error, hit.normal);
    if light_sampling && !is_delta(m) {
        add_light_sample(path, m, hit, coat_normal, origin, pixel, sample);
    }
    return scatter(path, m, hit, coat_normal, pixel, sample);
}

// The MIS weight of the light that a BSDF-sampled ray reaches on emitter (primitive, index),
// against light sampling from the vertex the ray left: 1 where light sampling is off or could
// not have found the ray (it left a delta lobe).
fn bsdf_ray_mis_weight(path: ptr<function, PathState>, primitive: u32, index: u32, light_sampling: bool) -> f32 {
    if light_sampling && !(*path).came_from_delta {
        let ray = (*path).ray;
        let pdf = light_pdf((*path).ray_start, ray.origin, ray.dir, primitive, index);
        return power_heuristic((*path).bsdf_pdf_of_ray, pdf);
    }
    return 1.0;
}

// The path's ray left the scene: the background or the environment map, and the sun disks,
// weighted against next-event estimation from the previous vertex.
fn add_escaped_light(path: ptr<function, PathState>, light_sampling: bool) {
    let ray = (*path).ray;
    var escaped = params.background;
    if HAS_ENVIRONMENT {
        escaped = environment_radiance(ray.dir);
    }
    if aovs_on() {
        (*path).aov = aov_record_miss((*path).aov, escaped);
    }
    if HAS_ENVIRONMENT {
        // The map is an emitter like the others: a BSDF-sampled ray that reaches it
        // shares its light with next-event estimation from the previous vertex.
        escaped *= bsdf_ray_mis_weight(path, PRIMITIVE_ENVIRONMENT, 0u, light_sampling);
    }
    if HAS_SUN_DISKS {
        let mis = light_sampling && !(*path).came_from_delta;
        escaped += sun_disks_radiance(ray.dir, (*path).bsdf_pdf_of_ray, mis);
    }
    (*path).radiance += firefly_clamp((*path).throughput * escaped, scatterings(*path));
}

// The material's normal maps at a triangle hit: the base's replaces the hit's shading normal;
// returns the pbr coat's own shading normal (KHR_materials_clearcoat): its
// clearcoatNormalTexture, else the unmapped one, since the base's normal map does not reach it.
// That one is normalised again (the same vector but for rounding) so that no kernel variant can
// prove it the base's and merge the coat's arithmetic with the base's: every variant rounds the
// coat alike (tests/suite/scene_binding.rs). Only where a coat is compiled in: nothing else
// reads it.
fn apply_normal_maps(m: Material, hit: ptr<function, Hit>, wo: vec3<f32>) -> vec3<f32> {
    var coat_normal = (*hit).shading_normal;
    if HAS_CLEARCOAT {
        coat_normal = normalize(coat_normal);
    }
    if HAS_TEXTURES && (*hit).primitive == PRIMITIVE_TRIANGLE {
        if HAS_CLEARCOAT && m.clearcoat > 0.0 && m.clearcoat_normal_texture != NO_TEXTURE {
            coat_normal = normal_mapped(*hit, m.clearcoat_normal_texture, m.clearcoat_normal_scale, wo);
        }
        if m.normal_texture != NO_TEXTURE {
            (*hit).shading_normal = normal_mapped(*hit, m.normal_texture, m.normal_scale, wo);
        }
    }
    return coat_normal;
}

// The light the hit surface emits towards the path. An emitter hit by a BSDF-sampled ray
// shares its light with next-event estimation from the previous vertex; camera rays and delta
// bounces count in full.
fn add_hit_emission(path: ptr<function, PathState>, m: Material, hit: Hit, light_sampling: bool) {
    if any(m.emission > vec3<f32>(0.0)) {
        let weight = bsdf_ray_mis_weight(path, hit.primitive, hit.index, light_sampling);
        (*path).radiance += firefly_clamp((*path).throughput * m.emission * weight, scatterings(*path));
    }
}

// Next-event estimation: light arriving after one more scattering event, through a shadow ray
// from `origin`, weighted against BSDF sampling.
fn add_light_sample(
    path: ptr<function, PathState>,
    m: Material,
    hit: Hit,
    coat_normal: vec3<f32>,
    origin: vec3<f32>,
    pixel: u32,
    sample: u32,
) {
    var light_rng = rng_stream(pixel, sample, stream_id((*path).bounce, PURPOSE_LIGHT), params.seed, params.sampler);
    let light = sample_light(hit.position, origin, &light_rng);
    if light.pdf > 0.0 && !crosses_shading_side(light.dir, hit) {
        add_unblocked_light(path, m, hit, coat_normal, origin, light, pixel, sample);
    }
}

// The sampled light's contribution if the BSDF passes it and nothing blocks the shadow ray.
fn add_unblocked_light(
    path: ptr<function, PathState>,
    m: Material,
    hit: Hit,
    coat_normal: vec3<f32>,
    origin: vec3<f32>,
    light: LightSample,
    pixel: u32,
    sample: u32,
) {
    let bounce = (*path).bounce;
    let wo = -(*path).ray.dir;
    let f_cos = bsdf_eval(m, wo, light.dir, hit.shading_normal, coat_normal, hit.front_face);
    if !any(f_cos > vec3<f32>(0.0)) {
        return;
    }
    segments += 1u;
    if HAS_ALPHA {
        // The shadow ray leaves this vertex as the next bounce's ray will: the same segment's
        // key, so both see the same blended triangles.
        alpha_key = alpha_segment_key(pixel, sample, bounce + 1u);
    }
    // A light behind a rough transmissive surface (bsdf_eval passes it only there) is reached
    // through the surface itself: the shadow ray starts on its far side, so that this surface
    // does not block it while every other one (a closed object's far wall) still does.
    var shadow_origin = origin;
    if dot(light.dir, hit.normal) < 0.0 {
        shadow_origin = offset_ray_origin(hit.position, hit.error, -hit.normal);
    }
    // Through participating media the light arrives attenuated, through interfaces too; else
    // it is seen or not, and `through` stays a constant 1 that the compiler folds away.
    var through = vec3<f32>(1.0);
    if HAS_MEDIA {
        var media = (*path).media;
        if dot(light.dir, hit.normal) < 0.0 {
            media = medium_crossed(media, hit.material, hit.front_face);
        }
        through = shadow_transmittance(Ray(shadow_origin, light.dir), light, media, pixel, sample, bounce);
        if !any(through > vec3<f32>(0.0)) {
            return;
        }
    } else if !light_visible(Ray(shadow_origin, light.dir), light) {
        return;
    }
    let pdf = bsdf_pdf(m, wo, light.dir, hit.shading_normal, coat_normal, hit.front_face);
    let weight = nee_weight(light, pdf);
    let contribution = (*path).throughput * f_cos * light.radiance * (weight / light.pdf) * through;
    (*path).radiance += firefly_clamp(contribution, scatterings(*path) + 1u);
}

// Samples the BSDF for the path's next ray, with Russian roulette from params.roulette_start;
// true when the path ends here.
fn scatter(
    path: ptr<function, PathState>,
    m: Material,
    hit: Hit,
    coat_normal: vec3<f32>,
    pixel: u32,
    sample: u32,
) -> bool {
    let bounce = (*path).bounce;
    let p = hit.position;
    let wo = -(*path).ray.dir;
    var bsdf_rng = rng_stream(pixel, sample, stream_id(bounce, PURPOSE_BSDF), params.seed, params.sampler);
    let s = bsdf_sample(m, wo, hit.shading_normal, coat_normal, hit.front_face, &bsdf_rng);
    var throughput = (*path).throughput * s.weight;
    if all(throughput == vec3<f32>(0.0)) || crosses_shading_side(s.dir, hit) {
        return true;
    }
    // A direction through the surface enters or leaves the medium it bounds. Here, not after
    // the new ray below: there, this branch (even on a constant false) kept lavapipe from
    // turning the code that sets the ray into selects, which cost media-free scenes ~1%.
    if HAS_MEDIA && dot(s.dir, hit.normal) < 0.0 {
        (*path).media = medium_crossed((*path).media, hit.material, hit.front_face);
    }
    if scatterings(*path) >= params.roulette_start {
        // Russian roulette: continue with probability q and divide by it, so the estimate
        // stays unbiased while dim paths end early.
        var roulette_rng = rng_stream(pixel, sample, stream_id(bounce, PURPOSE_ROULETTE), params.seed, params.sampler);
        let q = min(max(throughput.x, max(throughput.y, throughput.z)), 0.95);
        if rng_next(&roulette_rng) >= q {
            return true;
        }
        throughput /= q;
    }
    (*path).throughput = throughput;
    (*path).came_from_delta = s.is_delta;
    (*path).bsdf_pdf_of_ray = s.pdf;
    // Leave on the side the new direction goes to.
    let side = select(-hit.normal, hit.normal, dot(s.dir, hit.normal) >= 0.0);
    (*path).ray = Ray(offset_ray_origin(p, hit.error, side), s.dir);
    (*path).ray_start = p;
    (*path).bounce = bounce + 1u;
    return false;
}

// One camera path through pixel (px, py), traced to its end: its radiance, and its AOVs.
fn trace_path(pixel: u32, px: u32, py: u32, sample: u32) -> PathState {
    var path = start_path(pixel, px, py, sample);
    loop {
        if path_step(&path, pixel, sample) {
            break;
        }
    }
    return path;
}

@compute @workgroup_size(8, 8, 1)
fn render(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = invocation_pixel(id);
    if pixel == NO_PIXEL {
        return;
    }
    let px = pixel % params.width;
    let py = pixel / params.width;
    var acc = accumulator_start(params.accumulated_samples, accum_mean[pixel].xyz, accum_m2[pixel].xyz);
    var aov_mean = aov_mean_start();
    // Path regeneration: one loop over segments, and a lane whose path ends starts its next
    // sample at once, instead of idling until the longest path among its SIMD neighbours
    // ends. Each sample's result is the same as trace_path's (the random numbers depend on
    // the sample, not on the schedule), and samples finish in order.
    var done = 0u;
    var path = start_path(pixel, px, py, params.sample_start);
    loop {
        if path_step(&path, pixel, params.sample_start + done) {
            add_sample(&acc, path.radiance, params.sample_start + done);
            if aovs_on() {
                aov_mean_add(&aov_mean, path.aov, done);
            }
            done += 1u;
            if done == params.sample_count {
                break;
            }
            path = start_path(pixel, px, py, params.sample_start + done);
        }
    }
    // lavapipe (llvmpipe's gallivm) silently ends every loop of an invocation once all its
    // loops together have made 65535 iterations; the path loop then stops short. Write
    // nothing and let the host report it (src/gpu/loop_budget.rs keeps batches below it).
    if done < params.sample_count {
        atomicAdd(&accumulate_counters[1], 1u);
        return;
    }
    finish_pixel(pixel, &acc, aov_mean);
}
