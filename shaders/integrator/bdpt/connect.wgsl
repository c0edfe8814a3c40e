// Joining a light subpath's first s vertices to a camera subpath's first t (mirror:
// src/cpu/integrator/bdpt/connect.rs), and the power-heuristic weight of that strategy against
// every other (s', t') that could have made the same path (Veach 1997, 10.2; the ratio form of
// pbrt's MISWeight).
//
// Strategies: s = 0, the camera subpath found an emitter (or the sky); s = 1, a camera vertex
// joined to a light point (next-event estimation's, resampled); t = 1, a light vertex seen
// through the camera, splatted into whatever pixel it lands in (light tracing); every other
// (s, t) joins two scattering vertices (surfaces, or points in a medium). t = 0 (a light path that hits the lens) is not a strategy
// here: the lens cannot be hit.
//
// The subpaths are walk.wgsl's camera_path and light_path. Where the CPU passes a strategy's
// own end vertices in other slices (s = 1's light point, t = 1's lens point), these functions
// take the two joined vertices, qs and pt, as arguments, and read the arrays only below them.

// What one strategy adds: radiance for the pixel being rendered, or (t = 1) for the pixel
// `view` lands in, where has_view.
struct Connection {
    radiance: vec3<f32>,
    view: CameraView,
    has_view: bool,
}

fn no_connection() -> Connection {
    var c: Connection;
    c.radiance = vec3<f32>(0.0);
    c.has_view = false;
    return c;
}

// The alpha decisions of the connection (s, t).
fn keyed_connection(id: SampleId, s: u32, t: u32) {
    keyed(id, CONNECTION_SEGMENTS + s * 32u + t);
}

// Whether nothing blocks the segment between two vertices (one may be at infinity): a shadow
// ray from just off the first towards just off the second.
fn segment_clear(a: BdptVertex, b: BdptVertex, id: SampleId, s: u32, t: u32) -> bool {
    keyed_connection(id, s, t);
    let join = join_ray(a, b, direction_between(a, b));
    if is_infinite(b) {
        return escapes(join.ray);
    }
    if join.distance <= 0.0 {
        return false;
    }
    // Short of the far end by a sliver, as pbrt's SpawnRayTo: where a surface's point is exact
    // along its normal (an axis-aligned quad), its error bound and so its offset are 0, and
    // whether the ray meets that surface just before or just after `distance` is down to
    // rounding.
    return unoccluded_before(join.ray, join.distance * (1.0 - SHADOW_EPSILON));
}

// A join's shadow ray, from just off vertex a along dir (direction_between(a, b)): towards
// infinity where b is there, else towards end_point, just off b, distance away (0 where the
// two points meet: no join).
struct JoinRay {
    ray: Ray,
    end_point: vec3<f32>,
    distance: f32,
}

fn join_ray(a: BdptVertex, b: BdptVertex, dir: vec3<f32>) -> JoinRay {
    let start = off_surface(a, dir);
    if is_infinite(b) {
        return JoinRay(Ray(start, dir), start, 0.0);
    }
    let end_point = off_surface(b, -dir);
    let to_end = end_point - start;
    let distance = length(to_end);
    return JoinRay(Ray(start, to_end / distance), end_point, distance);
}

// The fraction of the light that gets from camera-side vertex `a` to vertex `b` (one may be at
// infinity): 0 or 1 without media (segment_clear); with media, the transmittance along the
// join, crossing interfaces with the medium stack following them. It starts from `a`, whose
// stack is the camera subpath's own (so right even where a light subpath's assumed start medium
// is not).
fn segment_through(a: BdptVertex, b: BdptVertex, id: SampleId, s: u32, t: u32) -> vec3<f32> {
    if !HAS_MEDIA || params.medium_count == 0u {
        return select(vec3<f32>(0.0), vec3<f32>(1.0), segment_clear(a, b, id, s, t));
    }
    keyed_connection(id, s, t);
    let dir = direction_between(a, b);
    let join = join_ray(a, b, dir);
    let media = stack_towards(a, dir);
    // To infinity: a join ends where the ray escapes, as a shadow ray to the sky does.
    var end = RayEnd(PRIMITIVE_ENVIRONMENT, 0u, vec3<f32>(0.0), 0.0);
    if !is_infinite(b) {
        if join.distance <= 0.0 {
            return vec3<f32>(0.0);
        }
        // As segment_clear: short of the far end by a sliver of the join's length.
        end = RayEnd(RAY_END_POINT, 0u, join.end_point, join.distance * SHADOW_EPSILON);
    }
    return transmittance_along(join.ray, media, end, id.pixel, id.sample, CONNECTION_TRACKING + s * 32u + t, false);
}

// The media a ray from vertex v along dir starts in: the vertex's, crossed into the medium its
// surface bounds where dir goes through it.
fn stack_towards(v: BdptVertex, dir: vec3<f32>) -> MediumStack {
    if v.kind == VERTEX_SURFACE && dot(dir, v.hit.normal) < 0.0 {
        return medium_crossed(v.media, v.hit.material, v.hit.front_face);
    }
    return v.media;
}

// The first "bounce" of joins' ratio-tracking streams: above both subpaths'.
const CONNECTION_TRACKING: u32 = 131072u;

// The fraction of a join's length left unsearched at its far end (pbrt's ShadowEpsilon).
const SHADOW_EPSILON: f32 = 1e-4;

// A vertex's point moved off its surface towards dir (points without a surface as they are).
fn off_surface(v: BdptVertex, dir: vec3<f32>) -> vec3<f32> {
    if !is_on_surface(v) {
        return v.hit.position;
    }
    let side = select(-v.hit.normal, v.hit.normal, dot(dir, v.hit.normal) >= 0.0);
    return offset_ray_origin(v.hit.position, v.hit.error, side);
}

// s = 1's light point and its unweighted contribution; found is false where nothing arrives.
struct DirectLight {
    vertex: BdptVertex,
    radiance: vec3<f32>,
    found: bool,
}

// s = 1's light point, drawn by next-event estimation's own sampler at camera vertex pt
// (material m_pt) (cones for spheres, the map by luminance; the path tracer's stream for that
// bounce), as pbrt's bidirectional integrator resamples it: far better for direct light than
// the light subpath's first vertex, uniform on the emitter. Returns the light vertex, with the
// density a light path would start there with (the MIS weights compare strategies by that),
// and the unweighted contribution.
fn direct_light(pt: BdptVertex, m_pt: Material, t: u32, id: SampleId) -> DirectLight {
    var out: DirectLight;
    out.found = false;
    var rng = rng_stream(id.pixel, id.sample, stream_id(t - 2u, PURPOSE_LIGHT), params.seed, params.sampler);
    let probe = off_surface(pt, pt.dir);
    let light = sample_light(pt.hit.position, probe, &rng);
    if !(light.pdf > 0.0) {
        return out;
    }
    let f = radiance_f_cos(pt, m_pt, pt.dir, light.dir);
    if all(f == vec3<f32>(0.0)) {
        return out;
    }
    var v = blank_vertex();
    v.kind = VERTEX_LIGHT;
    let p = pt.hit.position;
    if emitter_is_light(light.primitive) {
        let l = lights[light.index];
        v.hit.index = light.index;
        if l.kind == LIGHT_SUN {
            v.dir = -light.dir;
            if l.sun_one_minus_cos > 0.0 {
                v.emitter = EMITTER_INFINITE;
                v.pdf_fwd = infinite_light_pdf(light.dir);
            } else {
                v.emitter = EMITTER_DELTA_DIRECTION;
                v.pdf_fwd = l.light_probability;
            }
        } else {
            v.emitter = EMITTER_POINT;
            v.hit.position = l.position;
            v.pdf_fwd = l.light_probability;
        }
    } else if emitter_is_environment(light.primitive) {
        v.emitter = EMITTER_INFINITE;
        v.dir = -light.dir;
        v.pdf_fwd = infinite_light_pdf(light.dir);
    } else {
        // The point the direction meets on the emitter, and its normal, facing pt.
        let e = emitter_point(light.primitive, light.index, p, probe, light.dir);
        if !e.found {
            return out;
        }
        v.emitter = EMITTER_AREA;
        v.hit.position = p + e.distance * light.dir;
        v.hit.normal = select(-e.normal, e.normal, dot(e.normal, light.dir) < 0.0);
        v.hit.primitive = light.primitive;
        v.hit.index = light.index;
        v.pdf_fwd = area_origin_pdf(light.primitive, light.index);
    }
    keyed_connection(id, 1u, t);
    let origin = off_surface(pt, light.dir);
    let shadow = Ray(origin, light.dir);
    var through = vec3<f32>(1.0);
    if HAS_MEDIA && params.medium_count > 0u {
        // Through the media as the path tracer's next-event estimation sees them.
        let media = stack_towards(pt, light.dir);
        let end = RayEnd(light.primitive, light.index, vec3<f32>(0.0), 0.0);
        through = transmittance_along(shadow, media, end, id.pixel, id.sample, CONNECTION_TRACKING + 32u + t, false);
        if all(through == vec3<f32>(0.0)) {
            return out;
        }
    } else if !light_visible(shadow, light) {
        return out;
    }
    out.vertex = v;
    out.radiance = pt.beta * f * through * light.radiance / light.pdf;
    out.found = true;
    return out;
}

// Where a ray from p along dir meets an area emitter: its distance and the emitter's outward
// normal there; found is false where it does not.
struct EmitterPoint {
    distance: f32,
    normal: vec3<f32>,
    found: bool,
}

// Where a ray from p along dir meets the area emitter (primitive, index).
fn emitter_point(primitive: u32, index: u32, p: vec3<f32>, probe: vec3<f32>, dir: vec3<f32>) -> EmitterPoint {
    var out = EmitterPoint(0.0, vec3<f32>(0.0), false);
    if emitter_is_triangle(primitive) {
        let tri = triangles[index];
        out.normal = triangle_normal(tri);
        out.distance = triangle_plane_distance(tri, out.normal, p, dir);
    } else if emitter_is_quad(primitive) {
        let q = quads[index];
        out.normal = q.normal;
        out.distance = (q.plane_offset - dot(q.normal, p)) / dot(q.normal, dir);
    } else {
        let s = spheres[index];
        // From inside (as light sampling decides it, by probe), the chord's far end: p itself
        // may lie on the sphere.
        var t: f32;
        if sphere_contains(s, probe) {
            t = sphere_chord(s, p, dir).t;
        } else {
            t = hit_sphere(s, Ray(p, dir));
        }
        if t == NO_HIT {
            return out;
        }
        out.distance = t;
        out.normal = (p + t * dir - s.center) / s.radius;
    }
    // Positive and finite, by its bits (a compiler may assume floats are never NaN or infinite).
    let bits = bitcast<u32>(out.distance);
    out.found = bits > 0u && bits < 0x7f800000u;
    return out;
}

// The radiance strategy (s, t) adds, unweighted; t = 1 also says where it lands, and sets
// *lens to its lens vertex. m_pt and m_qs are the materials of the joined surface vertices
// (connect's, where they are surfaces). Written with one call each of the adjoint BSDF and
// the join's transmittance for light tracing and the other joins alike (the CPU has two of
// each): lavapipe inlines every call, and its compile time grows with the copies.
fn unweighted(s: u32, t: u32, id: SampleId, lens: ptr<function, BdptVertex>, m_pt: Material, m_qs: Material) -> Connection {
    var out = no_connection();
    if s == 0u {
        // The camera subpath ends on an emitter or in the sky.
        let pt = camera_path[t - 1u];
        if pt.kind == VERTEX_LIGHT {
            out.radiance = pt.beta * infinite_light_radiance(-pt.dir);
            return out;
        }
        out.radiance = pt.beta * m_pt.emission;
        return out;
    }
    let qs = light_path[s - 1u];
    // Where the light vertex sends its light, and the other end of the shadow ray.
    var toward: vec3<f32>;
    var other: BdptVertex;
    var f_pt = vec3<f32>(0.0);
    var view: CameraView;
    if t == 1u {
        // Light tracing: the light vertex seen through the lens.
        if qs.delta || params.projection == PROJECTION_ORTHOGRAPHIC || !scatters(qs) {
            return out;
        }
        var lens_rng = rng_stream(id.pixel, id.sample, stream_id(LIGHT_SUBPATH + s, PURPOSE_LIGHT), params.seed, params.sampler);
        let lens_u = vec2<f32>(rng_next(&lens_rng), rng_next(&lens_rng));
        view = camera_view(qs.hit.position, lens_u);
        if !view.visible {
            return out;
        }
        var camera = blank_vertex();
        camera.kind = VERTEX_CAMERA;
        camera.hit.position = view.lens_point;
        camera.beta = vec3<f32>(1.0);
        camera.media = medium_start();
        *lens = camera;
        toward = -view.dir;
        other = camera;
    } else {
        let pt = camera_path[t - 1u];
        if !scatters(pt) || pt.delta {
            return out;
        }
        let to_light = direction_between(pt, qs);
        f_pt = radiance_f_cos(pt, m_pt, pt.dir, to_light);
        if all(f_pt == vec3<f32>(0.0)) {
            return out;
        }
        // s >= 2 (s = 1 is next-event estimation's, in connect).
        if qs.delta || !scatters(qs) {
            return out;
        }
        toward = -to_light;
        other = pt;
    }
    let f_qs = adjoint_f_cos(qs, m_qs, qs.dir, toward);
    var radiance: vec3<f32>;
    if t == 1u {
        if all(f_qs == vec3<f32>(0.0)) {
            return out;
        }
        // W_e over the lens point's density, times the geometry term, with |cos| at the vertex
        // in f_qs: 1 / (A cos^3 d^2), the same for a pinhole and a thin lens.
        let importance = view.pdf_direction / (view.distance * view.distance);
        radiance = qs.beta * f_qs * importance;
    } else {
        let d = qs.hit.position - other.hit.position;
        radiance = qs.beta * f_qs * f_pt * other.beta / dot(d, d);
        if all(radiance == vec3<f32>(0.0)) {
            return out;
        }
    }
    // The join, traced from the camera side (the lens, or the camera vertex), as the CPU's.
    let through = segment_through(other, qs, id, s, t);
    if all(through == vec3<f32>(0.0)) {
        return out;
    }
    out.radiance = radiance * through;
    out.view = view;
    out.has_view = t == 1u;
    return out;
}

// Delta densities are stored as 0 and cancel in the ratios (pbrt's remap0).
fn remap0(pdf: f32) -> f32 {
    return select(1.0, pdf, pdf != 0.0);
}

// The power-heuristic weight of strategy (s, t) for the path it made, against every other
// strategy that could have made it. qs is the light end (light_path[s - 1], or s = 1's light
// point; unused for s = 0) and pt the camera end (camera_path[t - 1], or t = 1's lens vertex),
// with their materials where they are surfaces.
fn mis_weight(s: u32, t: u32, qs: BdptVertex, pt: BdptVertex, m_qs: Material, m_pt: Material) -> f32 {
    if s + t == 2u {
        return 1.0;
    }
    // The densities the connection changes: of the two joined vertices and their predecessors,
    // each as the other subpath would have sampled it.
    var pt_rev: f32;
    var pt_minus_rev = 0.0;
    var qs_rev = 0.0;
    var qs_minus_rev = 0.0;
    if s > 0u {
        let has_qs_minus = s > 1u;
        let qs_minus = light_path[max(s, 2u) - 2u];
        let has_pt_minus = t > 1u;
        let pt_minus = camera_path[max(t, 2u) - 2u];
        // The CPU's four calls of density_to, as one call in a loop over them: lavapipe inlines
        // every call, and each holds the BSDF's pdf.
        var densities = vec4<f32>(0.0);
        for (var k = 0u; k < opaque_count(4u); k++) {
            // k = 0: pt_rev, from qs; 1: qs_rev, from pt; 2: pt_minus_rev, from pt; 3:
            // qs_minus_rev, from qs.
            let from_pt = k == 1u || k == 2u;
            if (k == 2u && !has_pt_minus) || (k == 3u && !has_qs_minus) {
                continue;
            }
            var v = qs;
            var m = m_qs;
            var prev = qs_minus;
            var has_prev = has_qs_minus;
            var next = pt;
            if from_pt {
                v = pt;
                m = m_pt;
                prev = pt_minus;
                has_prev = has_pt_minus;
                next = qs;
            }
            if k >= 2u {
                // Reversed: from the joined vertex back to its own predecessor.
                let other = prev;
                prev = next;
                has_prev = true;
                next = other;
            }
            densities[k] = density_to(v, m, prev, has_prev, next);
        }
        pt_rev = densities.x;
        qs_rev = densities.y;
        pt_minus_rev = densities.z;
        qs_minus_rev = densities.w;
    } else {
        // The camera subpath's end is an emitter: how a light path would have started there.
        let origin = light_origin_density(pt);
        if origin <= 0.0 {
            // No light path starts on it (a background light sampling does not know): only the
            // camera could have found it.
            return 1.0;
        }
        pt_rev = origin;
        if t > 1u {
            var as_light = pt;
            if pt.kind == VERTEX_SURFACE {
                as_light.kind = VERTEX_LIGHT;
                as_light.emitter = EMITTER_AREA;
            }
            pt_minus_rev = light_direction_density(as_light, camera_path[t - 2u]);
        }
    }
    var sum = 0.0;
    // Camera side: strategies with fewer camera vertices.
    var ratio = 1.0;
    for (var i = t - 1u; i >= 1u; i--) {
        var rev: f32;
        var fwd: f32;
        var delta_here = false;
        if i == t - 1u {
            rev = pt_rev;
            fwd = pt.pdf_fwd;
        } else {
            if i + 2u == t {
                rev = pt_minus_rev;
            } else {
                rev = camera_path[i].pdf_rev;
            }
            fwd = camera_path[i].pdf_fwd;
            delta_here = camera_path[i].delta;
        }
        ratio *= remap0(rev) / remap0(fwd);
        if !delta_here && !camera_path[i - 1u].delta {
            sum += ratio * ratio;
        }
    }
    // Light side: strategies with fewer light vertices.
    ratio = 1.0;
    for (var j = s; j >= 1u; j--) {
        let i = j - 1u;
        var rev: f32;
        var fwd: f32;
        var delta_here = false;
        if i == s - 1u {
            rev = qs_rev;
            fwd = qs.pdf_fwd;
        } else {
            if i + 2u == s {
                rev = qs_minus_rev;
            } else {
                rev = light_path[i].pdf_rev;
            }
            fwd = light_path[i].pdf_fwd;
            delta_here = light_path[i].delta;
        }
        ratio *= remap0(rev) / remap0(fwd);
        var delta_before: bool;
        if i > 0u {
            delta_before = light_path[i - 1u].delta;
        } else if s == 1u {
            delta_before = is_delta_light(qs);
        } else {
            delta_before = is_delta_light(light_path[0]);
        }
        if !delta_here && !delta_before {
            sum += ratio * ratio;
        }
    }
    let weight = 1.0 / (1.0 + sum);
    // Finite, by its bits (a compiler may assume floats are never NaN or infinite).
    if (bitcast<u32>(weight) & 0x7f800000u) == 0x7f800000u {
        return 0.0;
    }
    return weight;
}

// Strategy (s, t)'s contribution, weighted unless `weighted` is false (the CPU's tests of the
// strategies one by one). The joined surface vertices' materials are made here, once each, and
// the weight is computed at one place for s = 1 and the rest (lavapipe inlines every call).
fn connect(s: u32, t: u32, id: SampleId, weighted: bool) -> Connection {
    var out = no_connection();
    var pt = camera_path[t - 1u];
    var qs = light_path[max(s, 1u) - 1u];
    // Materials only where a strategy reads them: a camera surface vertex (its emission for
    // s = 0, its BSDF otherwise unless it is delta), a light surface vertex joined by s >= 2.
    var m_pt: Material;
    var m_qs: Material;
    if t >= 2u && pt.kind == VERTEX_SURFACE && (s == 0u || !pt.delta) {
        m_pt = vertex_material(pt);
    }
    if s >= 2u && qs.kind == VERTEX_SURFACE && !qs.delta {
        m_qs = vertex_material(qs);
    }
    var radiance: vec3<f32>;
    if s == 1u {
        if !scatters(pt) || pt.delta {
            return out;
        }
        let direct = direct_light(pt, m_pt, t, id);
        if !direct.found {
            return out;
        }
        radiance = direct.radiance;
        // The light point is the light end (a light vertex has no material: nothing reads
        // m_qs for it).
        qs = direct.vertex;
    } else {
        var lens = camera_path[0];
        let c = unweighted(s, t, id, &lens, m_pt, m_qs);
        if all(c.radiance == vec3<f32>(0.0)) {
            return out;
        }
        radiance = c.radiance;
        out.view = c.view;
        out.has_view = c.has_view;
        if t == 1u {
            pt = lens;
        }
    }
    var weight = 1.0;
    if weighted {
        weight = mis_weight(s, t, qs, pt, m_qs, m_pt);
    }
    out.radiance = radiance * weight;
    return out;
}
