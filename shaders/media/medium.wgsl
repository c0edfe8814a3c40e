// Homogeneous media along a path (mirror: src/cpu/media/medium.rs, which says how the stack
// follows boundaries and how free flights are sampled: spectral MIS over the three channels).

const MEDIUM_STACK_SIZE: u32 = 4u;
const MAX_SHADOW_CROSSINGS: u32 = 8u;
const MAX_SURROUNDING_SURFACES: u32 = 16u;
// Any fixed direction, skewed off the axes so that it does not graze axis-aligned walls.
const SURROUNDINGS_DIRECTION: vec3<f32> = vec3<f32>(0.26726124, 0.8017837, 0.5345225);

// Segments a path or subpath of at most max_vertices vertices traces at most: its scattering
// events' and the interfaces crossed between them, which max_bounces does not count.
fn segment_limit(max_vertices: u32) -> u32 {
    return 4u * max_vertices + 8u;
}

// The media a path is in: slots[0 .. depth], innermost last.
struct MediumStack {
    slots: array<u32, 4>,
    depth: u32,
}

fn medium_start() -> MediumStack {
    var stack = MediumStack(array<u32, 4>(0u, 0u, 0u, 0u), 0u);
    if params.camera_medium < params.medium_count {
        stack.slots[0] = params.camera_medium;
        stack.depth = 1u;
    }
    return stack;
}

fn current_medium(stack_in: MediumStack) -> u32 {
    var stack = stack_in;
    if stack.depth > 0u {
        return stack.slots[stack.depth - 1u];
    }
    if params.global_medium < params.medium_count {
        return params.global_medium;
    }
    return NO_MEDIUM;
}

fn boundary_slot(material: u32) -> u32 {
    for (var i = 0u; i < min(params.medium_count, 8u); i++) {
        if params.media[i].boundary == material {
            return i;
        }
    }
    return NO_MEDIUM;
}

fn medium_crossed(stack_in: MediumStack, material: u32, front_face: bool) -> MediumStack {
    var out = stack_in;
    let slot = boundary_slot(material);
    if slot == NO_MEDIUM {
        return out;
    }
    if front_face {
        if out.depth < MEDIUM_STACK_SIZE {
            out.slots[out.depth] = slot;
            out.depth += 1u;
        }
        return out;
    }
    // The innermost entry of this medium goes; those inside it move down.
    var found = false;
    for (var k = 0u; k < out.depth; k++) {
        let i = out.depth - 1u - k;
        if !found && out.slots[i] == slot {
            found = true;
            for (var j = i; j < MEDIUM_STACK_SIZE - 1u; j++) {
                out.slots[j] = out.slots[j + 1u];
            }
        }
    }
    if found {
        out.depth -= 1u;
    }
    return out;
}

// An index-matched, untinted dielectric (type = "interface").
fn is_interface(m: Material) -> bool {
    return m.kind == MATERIAL_DIELECTRIC && m.ior == 1.0 && all(m.albedo == vec3<f32>(1.0));
}

// exp(-sigma_t d) per channel; 1 where sigma_t is 0 (also over an infinite d).
fn transmittance(sigma_t: vec3<f32>, d: f32) -> vec3<f32> {
    return select(vec3<f32>(1.0), exp(-(sigma_t * d)), sigma_t > vec3<f32>(0.0));
}

// Beer's law in a homogeneous medium, ratio tracking in a grid medium; 1 outside media.
fn segment_transmittance(slot: u32, ray: Ray, t: f32, rng: ptr<function, Rng>) -> vec3<f32> {
    if slot == NO_MEDIUM {
        return vec3<f32>(1.0);
    }
    let m = params.media[slot];
    if HAS_GRID_MEDIA && m.grid != NO_GRID {
        return grid_transmittance(m, ray, t, rng);
    }
    return transmittance(m.sigma_t, t);
}

struct FreeFlight {
    t: f32,
    weight: vec3<f32>,
    // True when it ended in the medium, false at the surface.
    scattered: bool,
}

fn sample_free_flight(m: Medium, t_max: f32, u_channel: f32, u_distance: f32) -> FreeFlight {
    let sigma_t = m.sigma_t;
    let channel = min(u32(u_channel * 3.0), 2u);
    let s = sigma_t[channel];
    var t = NO_HIT;
    if s > 0.0 {
        t = -log(1.0 - u_distance) / s;
    }
    if t < t_max {
        let tr = transmittance(sigma_t, t);
        let pdf = dot(sigma_t * tr, vec3<f32>(1.0 / 3.0));
        return FreeFlight(t, m.sigma_s * tr / pdf, true);
    }
    let tr = transmittance(sigma_t, t_max);
    let survival = dot(tr, vec3<f32>(1.0 / 3.0));
    var weight = vec3<f32>(0.0);
    if survival > 0.0 {
        weight = tr / survival;
    }
    return FreeFlight(t_max, weight, false);
}

// A free flight through medium slot `slot` (NO_MEDIUM: none) along `ray` towards a surface at
// t_hit (NO_HIT: none), from the flight's stream *rng: delta tracking in a grid medium, closed
// form in a homogeneous one. Shared by the path tracer and both of bidirectional's subpaths.
fn sample_flight(slot: u32, ray: Ray, t_hit: f32, rng: ptr<function, Rng>) -> FreeFlight {
    if slot == NO_MEDIUM {
        return FreeFlight(t_hit, vec3<f32>(1.0), false);
    }
    let m = params.media[slot];
    if HAS_GRID_MEDIA && m.grid != NO_GRID {
        return grid_free_flight(m, ray, t_hit, rng);
    }
    let u_channel = rng_next(rng);
    let u_distance = rng_next(rng);
    return sample_free_flight(m, t_hit, u_channel, u_distance);
}

// Where a ray through the media ends (the CPU's `end` closures of transmittance_along): at the
// sampled light (primitive, index) of a shadow ray (PRIMITIVE_ENVIRONMENT also ends a join at
// infinity), or, where primitive is RAY_END_POINT, at `point`, or wherever a surface is met
// within `slack` short of it (bidirectional's joins).
struct RayEnd {
    primitive: u32,
    index: u32,
    point: vec3<f32>,
    slack: f32,
}

const RAY_END_POINT: u32 = 0xffffffffu;

// The distance of the end along this piece of the ray, given its first hit; negative where the
// hit comes first.
fn ray_end_distance(end: RayEnd, ray: Ray, hit: Hit) -> f32 {
    if end.primitive == RAY_END_POINT {
        let t_end = max(dot(end.point - ray.origin, ray.dir), 0.0);
        if hit.t >= t_end - end.slack {
            return t_end;
        }
        return -1.0;
    }
    if end.primitive == PRIMITIVE_ENVIRONMENT {
        if hit.t == NO_HIT {
            return NO_HIT;
        }
    } else if end.primitive == PRIMITIVE_LIGHT {
        let l = lights[end.index];
        if l.kind == LIGHT_SUN {
            if hit.t == NO_HIT {
                return NO_HIT;
            }
        } else {
            let t = dot(l.position - ray.origin, ray.dir);
            if hit.t >= t {
                return t;
            }
        }
    } else if hit.t != NO_HIT && hit.primitive == end.primitive && hit.index == end.index {
        return hit.t;
    }
    return -1.0;
}

// The transmittance from the shadow ray's origin (in the media of stack) to the sampled light,
// through interfaces; zero where anything else blocks it. Uses the alpha key the caller set.
// Grid media's segments are ratio tracked, drawing from the vertex's PURPOSE_TRACKING stream.
fn shadow_transmittance(shadow: Ray, light: LightSample, stack: MediumStack, pixel: u32, sample: u32, bounce: u32) -> vec3<f32> {
    let end = RayEnd(light.primitive, light.index, vec3<f32>(0.0), 0.0);
    return transmittance_along(shadow, stack, end, pixel, sample, bounce, true);
}

// The media whose objects enclose point p (a lamp inside a fogged box), innermost last: a ray
// from p out of the scene, through every surface, leaves each of them through a back face it
// did not enter on the way (up to MAX_SURROUNDING_SURFACES surfaces).
fn media_around(p: vec3<f32>) -> MediumStack {
    // Slots of media that objects bound come first: without one, nothing encloses p (a global
    // fog), and the walk's rays are spared.
    if params.medium_count == 0u || params.media[0].boundary == NO_MEDIUM {
        return MediumStack();
    }
    var ray = Ray(p, SURROUNDINGS_DIRECTION);
    // Media entered on the way out (objects beside p, not around it), and those left.
    var entered = MediumStack();
    var around = MediumStack();
    for (var i = 0u; i < MAX_SURROUNDING_SURFACES; i++) {
        let hit = intersect_scene(ray);
        if hit.t == NO_HIT {
            break;
        }
        let slot = boundary_slot(hit.material);
        if slot != NO_MEDIUM {
            var inside_entered = false;
            for (var j = 0u; j < entered.depth; j++) {
                inside_entered = inside_entered || entered.slots[j] == slot;
            }
            if hit.front_face {
                entered = medium_crossed(entered, hit.material, true);
            } else if inside_entered {
                entered = medium_crossed(entered, hit.material, false);
            } else if around.depth < MEDIUM_STACK_SIZE {
                around.slots[around.depth] = slot;
                around.depth += 1u;
            }
        }
        ray = Ray(offset_ray_origin(hit.position, hit.error, -hit.normal), ray.dir);
    }
    // Found innermost first; the stack holds the outermost first.
    var out = around;
    for (var j = 0u; j < around.depth; j++) {
        out.slots[j] = around.slots[around.depth - 1u - j];
    }
    return out;
}

// The transmittance along `shadow` (from the media of stack) to `end`: interfaces before it are
// crossed (the stack follows them, as a path's would), anything else blocks. Shared by
// next-event estimation's shadow rays and bidirectional's joins; count_segments: the crossings
// count as segments traced (the path tracer's; the CPU's bidirectional joins pass a counter
// they drop). Uses the alpha key the caller set.
fn transmittance_along(shadow: Ray, stack: MediumStack, end: RayEnd, pixel: u32, sample: u32, bounce: u32, count_segments: bool) -> vec3<f32> {
    var tracking: Rng;
    if HAS_GRID_MEDIA {
        tracking = rng_stream(pixel, sample, stream_id(bounce, PURPOSE_TRACKING), params.seed, params.sampler);
    }
    var ray = shadow;
    var media = stack;
    var through = vec3<f32>(1.0);
    for (var i = 0u; i < MAX_SHADOW_CROSSINGS; i++) {
        if i > 0u && count_segments {
            segments += 1u;
        }
        let hit = intersect_scene(ray);
        let t_end = ray_end_distance(end, ray, hit);
        let slot = current_medium(media);
        if t_end >= 0.0 {
            return through * segment_transmittance(slot, ray, t_end, &tracking);
        }
        if hit.t == NO_HIT || !is_interface(materials[hit.material]) {
            return vec3<f32>(0.0);
        }
        through *= segment_transmittance(slot, ray, hit.t, &tracking);
        media = medium_crossed(media, hit.material, hit.front_face);
        ray = Ray(offset_ray_origin(hit.position, hit.error, -hit.normal), ray.dir);
    }
    return vec3<f32>(0.0);
}
