// Point, spot and directional (sun) lights (mirror: src/cpu/lights/punctual.rs; built in
// src/scene/light.rs). Point and spot lights, and suns without a disk, are delta lights: only
// next-event estimation reaches them (a BSDF-sampled ray never hits them), so their samples
// carry an MIS weight of 1. A sun with a disk is a cone of directions at infinity, sampled
// uniformly in its solid angle and seen by rays that escape into it, with MIS like the
// environment map's. Compiled in only for scenes with such lights (HAS_LIGHTS, HAS_SUN_DISKS);
// a storage buffer in every scene layout.

@group(0) @binding(24) var<storage, read> lights: array<Light>;

// glTF's spot falloff towards the unit direction from_light (light -> point):
// clamp(cos * scale + offset, 0, 1)^2. Point lights have scale 0 and offset 1: no falloff.
fn spot_falloff(l: Light, from_light: vec3<f32>) -> f32 {
    let cd = dot(l.direction, from_light);
    let a = clamp(cd * l.spot_scale + l.spot_offset, 0.0, 1.0);
    return a * a;
}

// 1 - cos of the angle between two unit vectors, as |a - b|^2 / 2: accurate for the small
// angles of a sun's disk, where 1 - dot(a, b) cancels.
fn one_minus_cos_between(a: vec3<f32>, b: vec3<f32>) -> f32 {
    let d = a - b;
    return 0.5 * dot(d, d);
}

// A direction towards light `index` from p, picked with `probability`. A sample with no light
// (outside a spot's cone, or at its very position) has pdf 0.
fn sample_punctual(index: u32, probability: f32, p: vec3<f32>, u: vec2<f32>) -> LightSample {
    let l = lights[index];
    var out: LightSample;
    out.pdf = 0.0;
    out.primitive = PRIMITIVE_LIGHT;
    out.index = index;
    out.is_delta = true;
    if l.kind == LIGHT_SUN {
        let axis = -l.direction;
        out.radiance = l.emitted;
        if l.sun_one_minus_cos == 0.0 {
            out.dir = axis;
            out.pdf = probability;
            return out;
        }
        // Uniform in the disk's cone of directions.
        let one_minus_cos = u.x * l.sun_one_minus_cos;
        let cos_theta = 1.0 - one_minus_cos;
        let sin_theta = sqrt(max(0.0, one_minus_cos * (2.0 - one_minus_cos)));
        let phi = 2.0 * PI * u.y;
        out.dir = normalize(sin_theta * cos(phi) * basis_tangent(axis) + sin_theta * sin(phi) * basis_bitangent(axis) + cos_theta * axis);
        out.pdf = probability / (2.0 * PI * l.sun_one_minus_cos);
        out.is_delta = false;
        return out;
    }
    let to_light = l.position - p;
    let distance2 = dot(to_light, to_light);
    if distance2 <= 0.0 {
        return out;
    }
    out.dir = to_light / sqrt(distance2);
    let falloff = spot_falloff(l, -out.dir);
    if falloff <= 0.0 {
        return out;
    }
    out.radiance = l.emitted * (falloff / distance2);
    out.pdf = probability;
    return out;
}

// Whether nothing blocks `shadow` (leaving the shading point along light.dir) before light
// light.index: the light's position for a point or spot, the sky for a sun.
fn punctual_visible(shadow: Ray, light: LightSample) -> bool {
    let l = lights[light.index];
    if l.kind == LIGHT_SUN {
        return escapes(shadow);
    }
    let t_light = dot(l.position - shadow.origin, shadow.dir);
    return unoccluded_before(shadow, t_light);
}

// Radiance of the sun disks a ray escaping along dir looks into. With `mis`, each is weighted
// against next-event estimation, which could have sampled the same direction, as the
// environment map is; bsdf_pdf is the ray's own pdf.
fn sun_disks_radiance(dir: vec3<f32>, bsdf_pdf: f32, mis: bool) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < params.light_count; i++) {
        let l = lights[i];
        if l.kind != LIGHT_SUN || l.sun_one_minus_cos == 0.0 {
            continue;
        }
        if one_minus_cos_between(dir, -l.direction) > l.sun_one_minus_cos {
            continue;
        }
        var weight = 1.0;
        if mis {
            let light_pdf = l.light_probability / (2.0 * PI * l.sun_one_minus_cos);
            weight = power_heuristic(bsdf_pdf, light_pdf);
        }
        sum += l.emitted * weight;
    }
    return sum;
}
