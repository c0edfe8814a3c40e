// The two subpaths of bidirectional path tracing (mirror: src/cpu/integrator/bdpt/walk.rs): one
// random walk, from the camera or from a light, recording each vertex with its throughput and
// its densities both ways.
//
// The camera subpath draws the path tracer's own numbers (its camera stream, and per bounce its
// BSDF and roulette streams); the light subpath draws streams of its own, numbered from
// LIGHT_SUBPATH. Light carried from a light is importance, not radiance: at each vertex the
// light subpath weights by the adjoint BSDF, f(wo = the next direction, wi = the previous), with
// Veach's correction for shading normals, and without the eta^2 that refraction applies to
// radiance. In a scene with media each segment first samples a free flight through the medium
// it is in (the path tracer's sample_flight, from the segment's own stream): a scattering there
// is a medium vertex, whose next direction the phase function draws.

// The most scattering events a bidirectional path may have (max_bounces is refused above it):
// the subpaths live in fixed arrays.
const BDPT_MAX_BOUNCES: u32 = 24u;
// Vertices of a camera subpath: the camera, and a surface per bounce and one more (an emitter,
// or the sky).
const CAMERA_VERTICES: u32 = 26u;
// Vertices of a light subpath: the light and a surface per bounce.
const LIGHT_VERTICES: u32 = 25u;

// The first "bounce" of the light subpath's streams: far above any camera bounce.
const LIGHT_SUBPATH: u32 = 65536u;
// The alpha-test segments of light subpaths and of connections (below them: the camera
// subpath's, numbered as the path tracer numbers its own).
const LIGHT_SEGMENTS: u32 = 256u;
const CONNECTION_SEGMENTS: u32 = 512u;

// The invocation's two subpaths (the CPU's arrays in bdpt_sample): private memory, reused by
// each sample, which reads only the vertices its own walks wrote.
var<private> camera_path: array<BdptVertex, CAMERA_VERTICES>;
var<private> light_path: array<BdptVertex, LIGHT_VERTICES>;

// Which pixel sample a walk belongs to, for its random numbers and alpha decisions.
struct SampleId {
    pixel: u32,
    px: u32,
    py: u32,
    sample: u32,
}

fn blank_vertex() -> BdptVertex {
    var v: BdptVertex;
    v.kind = VERTEX_SURFACE;
    v.emitter = EMITTER_AREA;
    v.hit = empty_hit();
    v.coat_normal = vec3<f32>(0.0, 0.0, 1.0);
    v.dir = vec3<f32>(0.0, 0.0, 1.0);
    v.beta = vec3<f32>(0.0);
    v.pdf_fwd = 0.0;
    v.pdf_rev = 0.0;
    v.delta = false;
    v.media = MediumStack();
    return v;
}

fn empty_hit() -> Hit {
    var hit = blank_hit();
    hit.t = NO_HIT;
    return hit;
}

// Vertex i of the light subpath (from_light) or of the camera subpath.
fn path_vertex(from_light: bool, i: u32) -> BdptVertex {
    if from_light {
        return light_path[i];
    }
    return camera_path[i];
}

fn set_path_vertex(from_light: bool, i: u32, v: BdptVertex) {
    if from_light {
        light_path[i] = v;
    } else {
        camera_path[i] = v;
    }
}

// This segment's alpha decisions (alpha.wgsl): segment `segment` of this sample.
fn keyed(id: SampleId, segment: u32) {
    if HAS_ALPHA {
        alpha_key = alpha_segment_key(id.pixel, id.sample, segment);
    }
}

// A walk's state between vertices: the ray leaving the last vertex, drawn with solid-angle
// density pdf_dir, the throughput, the media the ray is in, and the segments traced so far
// (each has its own random streams and alpha key; an interface crossed is a segment without a
// vertex, so without media the count is the vertex's bounce).
struct Walk {
    ray: Ray,
    beta: vec3<f32>,
    pdf_dir: f32,
    media: MediumStack,
    segment: u32,
}

// How the walk leaves a vertex (the CPU's continue_walk's `next`): along `ray` in `media`, with
// throughput factor `weight`, drawn with solid-angle density pdf_dir (0: a delta lobe), the
// density back being pdf_rev; ends is true where the walk ends at the vertex instead.
struct Scatter {
    ray: Ray,
    media: MediumStack,
    weight: vec3<f32>,
    pdf_dir: f32,
    pdf_rev: f32,
    is_delta: bool,
    ends: bool,
}

// Follows the walk from vertex count - 1 of its subpath, adding vertices until max_vertices,
// an escape or an absorption; returns the number of vertices. from_light: a light subpath
// (importance). In a scene with media each segment first samples a free flight through its
// medium: a scattering there is a medium vertex (the CPU's random_walk, scatter_at_surface,
// scatter_in_medium and continue_walk, as one loop: lavapipe inlines every call).
fn random_walk(walk_in: Walk, count_in: u32, max_vertices: u32, from_light: bool, id: SampleId, aov: ptr<function, PathAov>) -> u32 {
    var walk = walk_in;
    var count = count_in;
    let media_on = HAS_MEDIA && params.medium_count > 0u;
    let first_bounce = select(0u, LIGHT_SUBPATH, from_light);
    loop {
        if count >= max_vertices || walk.segment >= segment_limit(max_vertices) {
            break;
        }
        // Segment b leaves vertex count - 1 (the camera or the light: b = 0) where no interface
        // was crossed.
        let bounce = walk.segment;
        walk.segment += 1u;
        let ray = walk.ray;
        keyed(id, select(bounce, LIGHT_SEGMENTS + bounce, from_light));
        var hit = intersect_scene(ray);
        segments += 1u;
        let prev = path_vertex(from_light, count - 1u);
        var v = blank_vertex();
        var m: Material;
        var in_medium = false;
        if media_on {
            var flight_rng = rng_stream(id.pixel, id.sample, stream_id(first_bounce + bounce, PURPOSE_FREE_FLIGHT), params.seed, params.sampler);
            let flight = sample_flight(current_medium(walk.media), ray, hit.t, &flight_rng);
            walk.beta *= flight.weight;
            if all(walk.beta == vec3<f32>(0.0)) {
                break;
            }
            in_medium = flight.scattered;
            if in_medium {
                v.kind = VERTEX_MEDIUM;
                v.hit.position = ray.origin + flight.t * ray.dir;
            }
        }
        if !in_medium {
            if hit.t == NO_HIT {
                if !from_light {
                    // The sky: a light vertex at infinity, for the camera subpath to end on.
                    if aovs_on() {
                        *aov = aov_record_miss(*aov, infinite_light_radiance(ray.dir));
                    }
                    v = blank_vertex();
                    v.kind = VERTEX_LIGHT;
                    v.emitter = EMITTER_INFINITE;
                    v.dir = -ray.dir;
                    v.beta = walk.beta;
                    v.pdf_fwd = walk.pdf_dir;
                    v.media = walk.media;
                    camera_path[count] = v;
                    count += 1u;
                }
                break;
            }
            m = vertex_colored(material_at(materials[hit.material], hit.uv), hit);
            let coat_normal = apply_normal_maps(m, &hit, -ray.dir);
            if !from_light && aovs_on() {
                *aov = aov_record_hit(*aov, bounce, hit, m);
            }
            if HAS_VOLUME && !hit.front_face {
                walk.beta *= volume_transmittance(m, hit.t);
            }
            if media_on && is_interface(m) {
                // Not a vertex: the walk goes on in the medium beyond, its direction, density
                // and previous vertex unchanged (the path tracer's cross_interface).
                walk.media = medium_crossed(walk.media, hit.material, hit.front_face);
                walk.ray = Ray(offset_ray_origin(hit.position, hit.error, -hit.normal), ray.dir);
                continue;
            }
            v.kind = VERTEX_SURFACE;
            v.hit = hit;
            v.coat_normal = coat_normal;
        }
        v.dir = -ray.dir;
        v.beta = walk.beta;
        v.media = walk.media;
        v.pdf_fwd = first_vertex_density(prev, v, walk.pdf_dir);
        set_path_vertex(from_light, count, v);
        count += 1u;
        if count >= max_vertices {
            break;
        }
        var next: Scatter;
        if in_medium {
            next = scatter_in_medium(v, walk.media, first_bounce + bounce, id);
        } else {
            next = scatter_at_surface(v, m, walk.media, from_light, first_bounce + bounce, id);
        }
        if next.ends {
            break;
        }
        if next.is_delta {
            if from_light {
                light_path[count - 1u].delta = true;
            } else {
                camera_path[count - 1u].delta = true;
            }
        }
        var next_beta = walk.beta * next.weight;
        if all(next_beta == vec3<f32>(0.0)) {
            break;
        }
        if bounce >= params.roulette_start {
            var roulette_rng = rng_stream(id.pixel, id.sample, stream_id(first_bounce + bounce, PURPOSE_ROULETTE), params.seed, params.sampler);
            let q = min(max(next_beta.x, max(next_beta.y, next_beta.z)), 0.95);
            if rng_next(&roulette_rng) >= q {
                break;
            }
            next_beta /= q;
        }
        // The density of sampling the previous vertex from here, light flowing the other way.
        let prev_pdf_rev = to_area_density(next.pdf_rev, v, prev);
        if from_light {
            light_path[count - 2u].pdf_rev = prev_pdf_rev;
        } else {
            camera_path[count - 2u].pdf_rev = prev_pdf_rev;
        }
        walk.beta = next_beta;
        walk.pdf_dir = next.pdf_dir;
        walk.ray = next.ray;
        walk.media = next.media;
    }
    return count;
}

// Samples the BSDF at surface vertex v (material m), reached in `media`, for the walk's next
// ray; stream_bounce numbers its stream.
fn scatter_at_surface(v: BdptVertex, m: Material, media: MediumStack, from_light: bool, stream_bounce: u32, id: SampleId) -> Scatter {
    var out: Scatter;
    out.ends = true;
    let hit = v.hit;
    let wo = v.dir;
    var bsdf_rng = rng_stream(id.pixel, id.sample, stream_id(stream_bounce, PURPOSE_BSDF), params.seed, params.sampler);
    let s = bsdf_sample(m, wo, hit.shading_normal, v.coat_normal, hit.front_face, &bsdf_rng);
    if all(s.weight == vec3<f32>(0.0)) || crosses_shading_side(s.dir, hit) {
        return out;
    }
    out.weight = s.weight;
    if from_light {
        out.weight = adjoint_weight(v, m, wo, s.dir, s.weight, s.pdf, s.is_delta);
    }
    out.is_delta = s.is_delta;
    out.pdf_rev = 0.0;
    if s.is_delta {
        out.pdf_dir = 0.0;
    } else {
        out.pdf_dir = s.pdf;
        let f = facing(v, s.dir);
        out.pdf_rev = bsdf_pdf(m, s.dir, wo, f.n, f.coat_n, f.front_face);
    }
    let through = !(dot(s.dir, hit.normal) >= 0.0);
    out.media = media;
    if HAS_MEDIA && through {
        // Through the surface: into or out of the medium it bounds.
        out.media = medium_crossed(media, hit.material, hit.front_face);
    }
    let side = select(hit.normal, -hit.normal, through);
    out.ray = Ray(offset_ray_origin(hit.position, hit.error, side), s.dir);
    out.ends = false;
    return out;
}

// Samples the phase function at medium vertex v, in `media`, for the walk's next ray; exact
// sampling: the weight is 1, and the density back equals the density forth.
fn scatter_in_medium(v: BdptVertex, media: MediumStack, stream_bounce: u32, id: SampleId) -> Scatter {
    var phase_rng = rng_stream(id.pixel, id.sample, stream_id(stream_bounce, PURPOSE_PHASE), params.seed, params.sampler);
    let u1 = rng_next(&phase_rng);
    let u2 = rng_next(&phase_rng);
    let travelled = -v.dir;
    let g = medium_g(v);
    let dir = sample_hg(g, travelled, u1, u2);
    let pdf = hg_phase(g, dot(travelled, dir));
    return Scatter(Ray(v.hit.position, dir), media, vec3<f32>(1.0), pdf, pdf, false, false);
}

// The area density of a subpath's vertex v sampled from prev with solid-angle density pdf_dir;
// from a light at infinity, the density across its beam, as pbrt has it.
fn first_vertex_density(prev: BdptVertex, v: BdptVertex, pdf_dir: f32) -> f32 {
    if is_infinite(prev) {
        return light_direction_density(prev, v);
    }
    if prev.kind == VERTEX_CAMERA && params.projection == PROJECTION_ORTHOGRAPHIC {
        // A camera vertex has no material: density_to does not read it.
        return density_to(prev, materials[0], prev, false, v);
    }
    return to_area_density(pdf_dir, prev, v);
}

// The throughput weight of a light subpath's scattering at v (material m), which sampled wi for
// light arriving from wo (the way it came) with bsdf_sample's `weight` and `pdf`: the adjoint
// BSDF f(wi, wo) |wi.ns|, corrected for shading normals by |wi.ng| |wo.ns| / (|wo.ng| |wi.ns|)
// (Veach 1997, 5.3), over the pdf. Delta lobes keep the sample's weight, without the radiance
// scaling eta^2 their refraction applies.
fn adjoint_weight(v: BdptVertex, m: Material, wo: vec3<f32>, wi: vec3<f32>, weight: vec3<f32>, pdf: f32, is_delta: bool) -> vec3<f32> {
    let ng = v.hit.normal;
    let cos_o_geometric = abs(dot(wo, ng));
    if cos_o_geometric == 0.0 {
        return vec3<f32>(0.0);
    }
    if is_delta {
        let f = facing(v, wo);
        if dot(wi, ng) * dot(wo, ng) < 0.0 {
            // Refraction: the sample's weight carries (eta_o / eta_i)^2 for radiance; importance
            // does not scale.
            let ior = m.ior;
            let eta = select(ior, 1.0 / ior, f.front_face);
            return weight / (eta * eta);
        }
        return weight;
    }
    if pdf <= 0.0 {
        return vec3<f32>(0.0);
    }
    let f_cos_wo = adjoint_f_cos(v, m, wo, wi);
    return f_cos_wo / pdf;
}

// f(wo = toward, wi = arriving) |toward . ns| of a light subpath's surface vertex (material m),
// with Veach's shading-normal correction: what light (importance) arriving from `arriving`
// sends towards `toward`, as a throughput factor (at a medium vertex, the phase function). (The
// CPU's `from`: a reserved word in WGSL.)
fn adjoint_f_cos(v: BdptVertex, m: Material, arriving: vec3<f32>, toward: vec3<f32>) -> vec3<f32> {
    if HAS_MEDIA && v.kind == VERTEX_MEDIUM {
        return vec3<f32>(hg_phase(medium_g(v), -dot(arriving, toward)));
    }
    let ng = v.hit.normal;
    let cos_from_geometric = abs(dot(arriving, ng));
    if cos_from_geometric == 0.0 {
        return vec3<f32>(0.0);
    }
    let f = facing(v, toward);
    // bsdf_eval gives f(toward, arriving) |arriving . ns|.
    let f_cos_from = bsdf_eval(m, toward, arriving, f.n, f.coat_n, f.front_face);
    return f_cos_from * (abs(dot(toward, ng)) / cos_from_geometric);
}

// f(wo, wi) |wi . ns| of a camera subpath's surface vertex (material m): radiance from wi sent
// to wo (at a medium vertex, the phase function).
fn radiance_f_cos(v: BdptVertex, m: Material, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if HAS_MEDIA && v.kind == VERTEX_MEDIUM {
        return vec3<f32>(hg_phase(medium_g(v), -dot(wo, wi)));
    }
    let f = facing(v, wo);
    return bsdf_eval(m, wo, wi, f.n, f.coat_n, f.front_face);
}

// n, as a number no compiler can know: params.sample_count is at most MAX_SPP (2^30), so the
// shift is 0. A loop of n iterations then stays a loop: lavapipe (whose compile time grows
// with the code it inlines) would otherwise unroll it into n copies of its body.
fn opaque_count(n: u32) -> u32 {
    return n + (params.sample_count >> 31u);
}

// Where a subpath's walk starts: its first vertex is written, and the walk goes on while it
// has fewer than max_vertices. count is the vertices it has (1; 0 where there is no light to
// start from).
struct WalkStart {
    walk: Walk,
    count: u32,
    max_vertices: u32,
}

// The camera subpath's start (the CPU's camera_subpath before its walk): the camera vertex, and
// a walk to up to max_bounces + 1 surfaces (or the sky).
fn camera_subpath_start(id: SampleId) -> WalkStart {
    var camera_rng = rng_stream(id.pixel, id.sample, 0u, params.seed, params.sampler);
    let jitter = vec2<f32>(rng_next(&camera_rng), rng_next(&camera_rng));
    let lens = vec2<f32>(rng_next(&camera_rng), rng_next(&camera_rng));
    let ray = camera_ray(id.px, id.py, jitter, lens);
    var camera = blank_vertex();
    camera.kind = VERTEX_CAMERA;
    camera.hit.position = ray.origin;
    camera.beta = vec3<f32>(1.0);
    // An orthographic camera's direction is fixed: light tracing cannot reach it.
    camera.delta = params.projection == PROJECTION_ORTHOGRAPHIC;
    camera.media = medium_start();
    camera_path[0] = camera;
    var pdf_dir: f32;
    if params.projection == PROJECTION_ORTHOGRAPHIC {
        pdf_dir = 1.0 / film_area();
    } else {
        pdf_dir = camera_direction_pdf(ray.dir);
    }
    let max_vertices = min(params.max_bounces + 2u, CAMERA_VERTICES);
    return WalkStart(Walk(ray, vec3<f32>(1.0), pdf_dir, camera.media, 0u), 1u, max_vertices);
}

// The light subpath's start (the CPU's light_subpath before its walk): a light vertex, and a
// walk to up to max_bounces surfaces; no vertex (count 0) when the scene has no light to start
// from.
fn light_subpath_start(id: SampleId) -> WalkStart {
    var out: WalkStart;
    out.count = 0u;
    var origin_rng = rng_stream(id.pixel, id.sample, stream_id(LIGHT_SUBPATH, PURPOSE_LIGHT), params.seed, params.sampler);
    let origin = sample_light_origin(&origin_rng);
    if origin.pdf_position <= 0.0 || origin.pdf_direction <= 0.0 || all(origin.emitted == vec3<f32>(0.0)) {
        return out;
    }
    var light = blank_vertex();
    light.kind = VERTEX_LIGHT;
    light.emitter = origin.kind;
    light.hit = origin.hit;
    light.dir = origin.dir;
    // At infinity, the density of the direction (for a sun without a disk, its selection):
    // what connecting to it divides by, and what a camera path escaping there compares.
    let at_infinity = origin.kind == EMITTER_INFINITE || origin.kind == EMITTER_DELTA_DIRECTION;
    if at_infinity {
        light.pdf_fwd = origin.pdf_direction;
    } else {
        light.pdf_fwd = origin.pdf_position;
    }
    var cos_origin = 1.0;
    if origin.kind == EMITTER_AREA {
        cos_origin = abs(dot(origin.hit.normal, origin.dir));
    }
    light.beta = origin.emitted / origin.pdf_position;
    var start = origin.hit.position;
    if origin.kind == EMITTER_AREA {
        start = offset_ray_origin(origin.hit.position, origin.hit.error, origin.hit.normal);
    }
    // A finite emitter starts in the media of the objects around it; light from infinity in
    // the global medium.
    if HAS_MEDIA && params.medium_count > 0u && !at_infinity {
        light.media = media_around(start);
    }
    light_path[0] = light;
    out.count = 1u;
    out.max_vertices = min(params.max_bounces + 1u, LIGHT_VERTICES);
    if out.max_vertices < 2u {
        return out;
    }
    let beta = origin.emitted * (cos_origin / (origin.pdf_position * origin.pdf_direction));
    let ray = Ray(start, origin.dir);
    out.walk = Walk(ray, beta * light_media_transmittance(origin.kind), origin.pdf_direction, light.media, 0u);
    return out;
}

// Light from infinity starts its subpath in the global medium (an empty stack; a finite emitter
// in the media around it, media_around). It crosses a homogeneous global medium of infinite extent, as the path
// tracer's shadow rays to it do: its transmittance is 0 in every channel that attenuates.
fn light_media_transmittance(kind: u32) -> vec3<f32> {
    if !HAS_MEDIA || params.medium_count == 0u || (kind != EMITTER_INFINITE && kind != EMITTER_DELTA_DIRECTION) {
        return vec3<f32>(1.0);
    }
    let slot = current_medium(MediumStack());
    if slot == NO_MEDIUM || params.media[slot].grid != NO_GRID {
        return vec3<f32>(1.0);
    }
    return transmittance(params.media[slot].sigma_t, NO_HIT);
}

// The two subpaths of pixel sample id, in camera_path and light_path: the CPU's camera_subpath
// and light_subpath. Returns their vertex counts (camera, light). Both walks are one call of
// random_walk, in a loop over the two subpaths (the CPU calls it from each): lavapipe inlines
// every call, so two calls would compile the walk, its traversal, textures and BSDF twice.
fn subpaths(id: SampleId, aov: ptr<function, PathAov>) -> vec2<u32> {
    var counts = vec2<u32>(0u);
    for (var side = 0u; side < opaque_count(2u); side++) {
        let from_light = side == 1u;
        var start: WalkStart;
        if from_light {
            start = light_subpath_start(id);
        } else {
            start = camera_subpath_start(id);
        }
        var count = start.count;
        if count > 0u && count < start.max_vertices {
            count = random_walk(start.walk, count, start.max_vertices, from_light, id, aov);
        }
        if from_light {
            counts.y = count;
        } else {
            counts.x = count;
        }
    }
    return counts;
}
