// Where light paths start, and how densely (mirror: src/cpu/lights/emission.rs): the other half
// of light sampling, which bidirectional path tracing needs. An emitter is chosen by the same
// alias table as for next-event estimation (sampling.wgsl), then a point on it and a direction
// out of it:
// - quads, spheres and triangles: a point uniform in area and a cosine-weighted direction on
//   either side, since every emitter emits from both sides (the scene file's rule);
// - point lights: a direction uniform on the sphere; spots: uniform in the cone of their outer
//   angle, outside which they emit nothing;
// - the environment map and the suns, infinitely far away: a direction as next-event
//   estimation draws it (the light travels the opposite way), and a point uniform on a disk
//   of the scene's radius facing it (Params' scene_center, scene_radius), as in pbrt.
// The densities are those bidirectional path tracing's MIS weights need: the area density of a
// light path's first vertex (selection included) and the solid-angle density of its
// direction, both for a sampled origin and for a point a camera path happens to hit.
// Compiled in only with bidirectional path tracing (KernelFeatures::bdpt).

// A light vertex on a quad, sphere or triangle.
const EMITTER_AREA: u32 = 0u;
// A point or spot light: a position and no area, which no ray can hit.
const EMITTER_POINT: u32 = 1u;
// The environment map and the suns with a disk: directions at infinity.
const EMITTER_INFINITE: u32 = 2u;
// A sun without a disk: one direction at infinity, which no ray can hit.
const EMITTER_DELTA_DIRECTION: u32 = 3u;

// The start of a light path (src/cpu/lights/emission.rs says what each field holds).
struct LightOrigin {
    hit: Hit,
    dir: vec3<f32>,
    emitted: vec3<f32>,
    pdf_position: f32,
    pdf_direction: f32,
    kind: u32,
    material: u32,
}

fn blank_hit() -> Hit {
    let z = vec3<f32>(0.0, 0.0, 1.0);
    return Hit(0.0, vec3<f32>(0.0), vec3<f32>(0.0), z, z, 0u, true, 0u, 0u, vec4<f32>(0.0), vec3<f32>(0.0));
}

// A unit direction and its solid-angle density.
struct EmittedDirection {
    dir: vec3<f32>,
    pdf: f32,
}

// A cosine-weighted direction about n on a side chosen by u_side (both sides emit), and its
// solid-angle density |cos| / (2 pi).
fn two_sided_cosine(n: vec3<f32>, u_side: f32, u: vec2<f32>) -> EmittedDirection {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let z = sqrt(max(1.0 - u.x, 0.0));
    let side = select(-n, n, u_side < 0.5);
    let dir = normalize(from_local(vec3<f32>(r * cos(phi), r * sin(phi), z), side));
    return EmittedDirection(dir, z / (2.0 * PI));
}

// A direction uniform in the cone about `axis` whose 1 - cos(theta_max) is one_minus_cos_max.
fn uniform_cone(axis: vec3<f32>, one_minus_cos_max: f32, u: vec2<f32>) -> vec3<f32> {
    let one_minus_cos = u.x * one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    let sin_theta = sqrt(max(one_minus_cos * (2.0 - one_minus_cos), 0.0));
    let phi = 2.0 * PI * u.y;
    return normalize(sin_theta * cos(phi) * basis_tangent(axis) + sin_theta * sin(phi) * basis_bitangent(axis) + cos_theta * axis);
}

// 1 - cos of a spot's outer angle, beyond which its falloff is 0 (2 for a point light: the
// whole sphere).
fn spot_one_minus_cos_outer(index: u32) -> f32 {
    let l = lights[index];
    if l.kind != LIGHT_SPOT || l.spot_scale <= 0.0 {
        return 2.0;
    }
    return clamp(1.0 + l.spot_offset / l.spot_scale, 0.0, 2.0);
}

// The point on the scene's disk facing `travel` (the way the light goes) at disk coordinates
// u: where a light path from infinitely far starts.
fn disk_entry(travel: vec3<f32>, u: vec2<f32>) -> Hit {
    let radius = params.scene_radius;
    let r = sqrt(u.x) * radius;
    let phi = 2.0 * PI * u.y;
    var hit = blank_hit();
    hit.position = params.scene_center - radius * travel
        + r * (cos(phi) * basis_tangent(travel) + sin(phi) * basis_bitangent(travel));
    hit.normal = travel;
    hit.shading_normal = travel;
    return hit;
}

// The density of directions at infinity, towards the sky along dir, summed over every
// infinite light (the environment map and the suns with a disk), selection included: the
// density with which a light path starts from dir, and the one with which next-event
// estimation reaches it.
fn infinite_light_pdf(dir: vec3<f32>) -> f32 {
    var pdf = 0.0;
    if HAS_ENVIRONMENT && params.environment_width > 0u {
        pdf += params.environment_light_probability * environment_pdf(dir);
    }
    if HAS_SUN_DISKS {
        for (var i = 0u; i < params.light_count; i++) {
            let l = lights[i];
            if l.kind == LIGHT_SUN && l.sun_one_minus_cos > 0.0
                && one_minus_cos_between(dir, -l.direction) <= l.sun_one_minus_cos {
                pdf += l.light_probability / (2.0 * PI * l.sun_one_minus_cos);
            }
        }
    }
    return pdf;
}

// What arrives along -dir from infinity (looking along dir): the background or the
// environment map, and the sun disks there.
fn infinite_light_radiance(dir: vec3<f32>) -> vec3<f32> {
    var radiance = params.background;
    if HAS_ENVIRONMENT && params.environment_width > 0u {
        radiance = environment_radiance(dir);
    }
    if HAS_SUN_DISKS {
        for (var i = 0u; i < params.light_count; i++) {
            let l = lights[i];
            if l.kind == LIGHT_SUN && l.sun_one_minus_cos > 0.0
                && one_minus_cos_between(dir, -l.direction) <= l.sun_one_minus_cos {
                radiance += l.emitted;
            }
        }
    }
    return radiance;
}

// The emission of an area emitter's material at a point of it (its texture and vertex colours
// included), as a camera path hitting it sees it.
fn area_emission(m: Material, hit: Hit) -> vec3<f32> {
    let emission = emission_at(m, hit.uv);
    if HAS_TRIANGLES && hit.primitive == PRIMITIVE_TRIANGLE {
        return vertex_colored_emission(m, hit.index, hit.barycentrics, emission);
    }
    return emission;
}

// Samples the start of a light path. Draws, in order: the emitter (two numbers, as
// sample_light), the point (two), the side of a two-sided emitter (one) and the direction
// (two); the environment map draws two more inside its texel.
fn sample_light_origin(rng: ptr<function, Rng>) -> LightOrigin {
    var out = LightOrigin(blank_hit(), vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0), 0.0, 0.0, EMITTER_AREA, 0u);
    if emitter_count() == 0u {
        return out;
    }
    let u_slot = rng_next(rng);
    let u_alias = rng_next(rng);
    let e = pick_emitter(u_slot, u_alias);
    let u_point = vec2<f32>(rng_next(rng), rng_next(rng));
    let u_side = rng_next(rng);
    let u_dir = vec2<f32>(rng_next(rng), rng_next(rng));
    out.hit.primitive = e.primitive;
    out.hit.index = e.index;
    if emitter_is_environment(e.primitive) {
        let s = sample_environment(u_dir, rng);
        let travel = -s.dir;
        out.hit = disk_entry(travel, u_point);
        out.hit.primitive = PRIMITIVE_ENVIRONMENT;
        out.dir = travel;
        out.emitted = infinite_light_radiance(s.dir);
        out.pdf_position = 1.0 / (PI * params.scene_radius * params.scene_radius);
        out.pdf_direction = infinite_light_pdf(s.dir);
        out.kind = EMITTER_INFINITE;
        return out;
    }
    if emitter_is_light(e.primitive) {
        let l = lights[e.index];
        if l.kind == LIGHT_SUN {
            var travel = l.direction;
            if l.sun_one_minus_cos > 0.0 {
                travel = -uniform_cone(-l.direction, l.sun_one_minus_cos, u_dir);
            }
            out.hit = disk_entry(travel, u_point);
            out.hit.primitive = PRIMITIVE_LIGHT;
            out.hit.index = e.index;
            out.dir = travel;
            out.pdf_position = 1.0 / (PI * params.scene_radius * params.scene_radius);
            if l.sun_one_minus_cos > 0.0 {
                out.emitted = infinite_light_radiance(-travel);
                out.pdf_direction = infinite_light_pdf(-travel);
                out.kind = EMITTER_INFINITE;
            } else {
                out.emitted = l.emitted;
                out.pdf_direction = e.probability;
                out.kind = EMITTER_DELTA_DIRECTION;
            }
            return out;
        }
        let one_minus_cos = spot_one_minus_cos_outer(e.index);
        var axis = vec3<f32>(0.0, 0.0, 1.0);
        if l.kind == LIGHT_SPOT {
            axis = l.direction;
        }
        out.dir = uniform_cone(axis, one_minus_cos, u_dir);
        out.hit.position = l.position;
        out.hit.normal = out.dir;
        out.hit.shading_normal = out.dir;
        out.emitted = l.emitted * spot_falloff(l, out.dir);
        out.pdf_position = e.probability;
        out.pdf_direction = 1.0 / (2.0 * PI * one_minus_cos);
        out.kind = EMITTER_POINT;
        return out;
    }
    var hit = blank_hit();
    hit.primitive = e.primitive;
    hit.index = e.index;
    var area: f32;
    if emitter_is_triangle(e.primitive) {
        let tri = triangles[e.index];
        let b = triangle_sample_barycentrics(u_point);
        let point = triangle_surface_point(tri, b);
        hit.position = point.position;
        hit.error = point.error;
        hit.normal = triangle_normal(tri);
        hit.material = tri.material;
        hit.barycentrics = b;
        if HAS_TEXTURES {
            hit.uv = triangle_uv(e.index, b);
        }
        area = tri.area;
    } else if emitter_is_quad(e.primitive) {
        let q = quads[e.index];
        let point = parametric_point(q.corner, q.edge_u, q.edge_v, u_point.x, u_point.y);
        hit.position = point.position;
        hit.error = point.error;
        hit.normal = q.normal;
        hit.material = q.material;
        hit.uv = vec4<f32>(u_point, u_point);
        area = q.area;
    } else {
        let s = spheres[e.index];
        let z = 1.0 - 2.0 * u_point.x;
        let r = sqrt(max(1.0 - z * z, 0.0));
        let phi = 2.0 * PI * u_point.y;
        let outward = vec3<f32>(r * cos(phi), r * sin(phi), z);
        let point = sphere_point(s.center, s.radius, outward);
        hit.position = point.position;
        hit.error = point.error;
        hit.normal = outward;
        hit.material = s.material;
        hit.uv = both_sets(sphere_uv(outward));
        area = 4.0 * PI * s.radius * s.radius;
    }
    let d = two_sided_cosine(hit.normal, u_side, u_dir);
    // The vertex faces the way its light leaves, as a hit faces the ray that found it.
    hit.front_face = dot(d.dir, hit.normal) >= 0.0;
    if !hit.front_face {
        hit.normal = -hit.normal;
    }
    hit.shading_normal = hit.normal;
    out.emitted = area_emission(materials[hit.material], hit);
    out.material = hit.material;
    out.hit = hit;
    out.dir = d.dir;
    out.pdf_position = e.probability / area;
    out.pdf_direction = d.pdf;
    out.kind = EMITTER_AREA;
    return out;
}

// The area density with which sample_light_origin starts a light path at a point of the area
// emitter (primitive, index), selection included: 0 for one the table never picks.
fn area_origin_pdf(primitive: u32, index: u32) -> f32 {
    if primitive == PRIMITIVE_TRIANGLE {
        if HAS_TRIANGLES && index < arrayLength(&triangles) {
            let tri = triangles[index];
            return tri.light_probability / tri.area;
        }
        return 0.0;
    }
    if primitive == PRIMITIVE_QUAD {
        let q = quads[index];
        return q.light_probability / q.area;
    }
    if primitive == PRIMITIVE_SPHERE {
        let s = spheres[index];
        return s.light_probability / (4.0 * PI * s.radius * s.radius);
    }
    return 0.0;
}

// The solid-angle density with which a point light (`index`) sends its light along dir.
fn point_direction_pdf(index: u32, dir: vec3<f32>) -> f32 {
    let l = lights[index];
    let one_minus_cos = spot_one_minus_cos_outer(index);
    if l.kind == LIGHT_SPOT && one_minus_cos_between(dir, l.direction) > one_minus_cos {
        return 0.0;
    }
    return 1.0 / (2.0 * PI * one_minus_cos);
}

// The scene's disk radius density, 1 / (pi R^2).
fn disk_pdf() -> f32 {
    let r = params.scene_radius;
    return 1.0 / (PI * r * r);
}
