// The vertices of bidirectional path tracing's subpaths, and the densities its MIS weights
// compare (mirror: src/cpu/integrator/bdpt/vertex.rs). Every density is per unit area at the
// vertex it leads to, or per unit solid angle where that vertex is at infinity, as in Veach's
// thesis and pbrt's BDPTIntegrator.

// The camera end of a camera subpath (its lens point).
const VERTEX_CAMERA: u32 = 0u;
// A light's end of a light subpath, or where a camera subpath escapes to infinity.
const VERTEX_LIGHT: u32 = 1u;
// A surface a subpath met (an emitter among them: a camera subpath may end on one).
const VERTEX_SURFACE: u32 = 2u;
// A scattering event in a participating medium: its "BSDF" is the medium's phase function
// (f = pdf = phase, no cosine anywhere: a point in a volume has no area).
const VERTEX_MEDIUM: u32 = 3u;

// The CPU's BdptVertex without its three fields that only fill memory: `material` (the
// vertex's material, textures and vertex colours applied) is made again from hit.material,
// hit.uv and the triangle's barycentrics where it is needed (vertex_material: the same numbers,
// so the same material), `g` (a medium vertex's phase asymmetry) from its medium stack
// (medium_g), and `emitted` is written there and never read. A subpath holds up to 26 of these
// per invocation (walk.wgsl), so the 40 words of a material are most of what is saved.
struct BdptVertex {
    // VERTEX_CAMERA, VERTEX_LIGHT, VERTEX_SURFACE or VERTEX_MEDIUM.
    kind: u32,
    // For light vertices: EMITTER_AREA, EMITTER_POINT, EMITTER_INFINITE or
    // EMITTER_DELTA_DIRECTION (lights/emission.wgsl).
    emitter: u32,
    // The surface point: position, error, geometric and shading normal facing the subpath's
    // previous vertex, front_face, material, primitive, index, texture coordinates and
    // barycentrics. Camera and point-light vertices use the position alone.
    hit: Hit,
    // The pbr coat's own shading normal, as the path tracer's apply_normal_maps gives it.
    coat_normal: vec3<f32>,
    // Unit direction towards the previous vertex of the vertex's own subpath; at infinity, the
    // direction the light travels (from the sky into the scene).
    dir: vec3<f32>,
    // The subpath's throughput up to this vertex.
    beta: vec3<f32>,
    // The density with which the vertex's own subpath sampled it, and with which the other
    // subpath's sampling would have produced it.
    pdf_fwd: f32,
    pdf_rev: f32,
    // The vertex scattered by a delta lobe: no connection can end at it.
    delta: bool,
    // The media the subpath's ray arriving at the vertex was in (media/medium.wgsl; one empty
    // word in kernels without media); a join leaving through the surface crosses it first.
    media: MediumStack,
}

// The material at a surface vertex, as the walk that made it found it.
fn vertex_material(v: BdptVertex) -> Material {
    return vertex_colored(material_at(materials[v.hit.material], v.hit.uv), v.hit);
}

fn is_infinite(v: BdptVertex) -> bool {
    return v.kind == VERTEX_LIGHT && (v.emitter == EMITTER_INFINITE || v.emitter == EMITTER_DELTA_DIRECTION);
}

// A surface or medium vertex: one that scatters, where joins can end. (Medium vertices only
// where the kernel has media: elsewhere the test is the surface's alone.)
fn scatters(v: BdptVertex) -> bool {
    return v.kind == VERTEX_SURFACE || (HAS_MEDIA && v.kind == VERTEX_MEDIUM);
}

// A medium vertex's Henyey-Greenstein asymmetry: its medium's, the innermost of its stack.
fn medium_g(v: BdptVertex) -> f32 {
    return params.media[current_medium(v.media)].g;
}

// Whether the vertex has an area (its density converts with the cosine there).
fn is_on_surface(v: BdptVertex) -> bool {
    return v.kind == VERTEX_SURFACE || (v.kind == VERTEX_LIGHT && v.emitter == EMITTER_AREA);
}

// A point or spot light, or a sun without a disk: nothing can hit it.
fn is_delta_light(v: BdptVertex) -> bool {
    return v.kind == VERTEX_LIGHT && (v.emitter == EMITTER_POINT || v.emitter == EMITTER_DELTA_DIRECTION);
}

// The unit direction from vertex `a` to vertex `to` (one of them may be at infinity). (The
// CPU's `from`: a reserved word in WGSL.)
fn direction_between(a: BdptVertex, to: BdptVertex) -> vec3<f32> {
    if is_infinite(to) {
        return -to.dir;
    }
    if is_infinite(a) {
        return a.dir;
    }
    return normalize(to.hit.position - a.hit.position);
}

// A solid-angle density at `a` as a density at `to`: per unit area there (times the cosine at
// `to`, over the squared distance), unchanged for a vertex at infinity.
fn to_area_density(pdf_in: f32, a: BdptVertex, to: BdptVertex) -> f32 {
    if is_infinite(to) {
        return pdf_in;
    }
    let w = to.hit.position - a.hit.position;
    let distance2 = dot(w, w);
    if distance2 <= 0.0 {
        return 0.0;
    }
    var pdf = pdf_in / distance2;
    if is_on_surface(to) {
        pdf *= abs(dot(to.hit.normal, w)) / sqrt(distance2);
    }
    return pdf;
}

// The shading frame of a surface vertex seen from the side of w: shading and coat normals
// facing it, and whether that side is the outside (bsdf_eval's conventions).
struct Facing {
    n: vec3<f32>,
    coat_n: vec3<f32>,
    front_face: bool,
}

fn facing(v: BdptVertex, w: vec3<f32>) -> Facing {
    if dot(w, v.hit.normal) >= 0.0 {
        return Facing(v.hit.shading_normal, v.coat_normal, v.hit.front_face);
    }
    return Facing(-v.hit.shading_normal, -v.coat_normal, !v.hit.front_face);
}

// The solid-angle density of BSDF sampling at surface vertex v (material m) producing wi for
// light leaving along wo (either subpath samples its next direction so).
fn surface_pdf(v: BdptVertex, m: Material, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let f = facing(v, wo);
    return bsdf_pdf(m, wo, wi, f.n, f.coat_n, f.front_face);
}

// The solid-angle density of either subpath's sampling at scattering vertex v (a surface's BSDF
// of material m, a medium's phase function) producing wi for light leaving along wo.
fn scatter_pdf(v: BdptVertex, m: Material, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if HAS_MEDIA && v.kind == VERTEX_MEDIUM {
        // The phase function's cosine is between the travelled and the scattered direction.
        return hg_phase(medium_g(v), -dot(wo, wi));
    }
    return surface_pdf(v, m, wo, wi);
}

// The density with which a light vertex v sends its light to `next`: what the light subpath's
// first segment would have drawn.
fn light_direction_density(v: BdptVertex, next: BdptVertex) -> f32 {
    if is_infinite(v) {
        // Parallel rays through the scene's disk: uniform in area across the beam.
        var pdf = disk_pdf();
        if is_on_surface(next) {
            pdf *= abs(dot(v.dir, next.hit.normal));
        }
        return pdf;
    }
    let w = direction_between(v, next);
    var pdf_dir: f32;
    if v.kind == VERTEX_LIGHT && v.emitter == EMITTER_POINT {
        pdf_dir = point_direction_pdf(v.hit.index, w);
    } else {
        // An area emitter (a light subpath's origin, or a surface a camera path ended on):
        // cosine-weighted on either side.
        pdf_dir = abs(dot(v.hit.normal, w)) / (2.0 * PI);
    }
    return to_area_density(pdf_dir, v, next);
}

// The density with which light paths start at the emitter vertex v (selection included): per
// unit area for area emitters, per unit solid angle (every infinite light's together) at
// infinity. 0 where no light path can start: a background light sampling does not know.
fn light_origin_density(v: BdptVertex) -> f32 {
    if is_infinite(v) {
        return infinite_light_pdf(-v.dir);
    }
    return area_origin_pdf(v.hit.primitive, v.hit.index);
}

// The density with which vertex v (material m, for a surface), reached from `prev` (ignored
// at the subpath's ends, and where has_prev is false), samples `next`: the camera's density, a
// light's emission density, the BSDF's or the phase function's, as a density at `next`.
fn density_to(v: BdptVertex, m: Material, prev: BdptVertex, has_prev: bool, next: BdptVertex) -> f32 {
    if v.kind == VERTEX_CAMERA {
        if params.projection == PROJECTION_ORTHOGRAPHIC {
            // Parallel rays from a film uniform in area (only a camera path's own first vertex
            // asks; light tracing cannot reach an orthographic camera).
            var pdf = 1.0 / film_area();
            if is_on_surface(next) {
                pdf *= abs(dot(params.forward, next.hit.normal));
            }
            return pdf;
        }
        let w = direction_between(v, next);
        return to_area_density(camera_direction_pdf(w), v, next);
    }
    if v.kind == VERTEX_LIGHT {
        return light_direction_density(v, next);
    }
    if !has_prev {
        return 0.0;
    }
    let wo = direction_between(v, prev);
    let wi = direction_between(v, next);
    return to_area_density(scatter_pdf(v, m, wo, wi), v, next);
}
