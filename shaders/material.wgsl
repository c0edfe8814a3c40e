// BSDF sampling (mirror: src/cpu/material.rs).

const PI: f32 = 3.14159265358979;

// Orthonormal basis around a unit n (Duff et al., "Building an Orthonormal Basis, Revisited", 2017).
fn basis_tangent(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
}

fn basis_bitangent(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(b, s + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction about n: pdf = cos(theta) / pi. With the Lambertian BRDF albedo / pi
// the path weight brdf * cos / pdf is exactly the albedo.
fn sample_cosine_hemisphere(n: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let x = r * cos(phi);
    let y = r * sin(phi);
    let z = sqrt(max(0.0, 1.0 - u.x));
    return normalize(x * basis_tangent(n) + y * basis_bitangent(n) + z * n);
}

struct Scatter {
    dir: vec3<f32>,
    weight: vec3<f32>,
}

// Samples the next direction at a hit. `n` faces the incoming direction `wi`.
fn scatter(m: Material, wi: vec3<f32>, n: vec3<f32>, rng: ptr<function, u32>) -> Scatter {
    var out: Scatter;
    if m.kind == MATERIAL_SPECULAR {
        out.dir = reflect(wi, n);
        out.weight = m.albedo;
        return out;
    }
    let u = vec2<f32>(rng_next(rng), rng_next(rng));
    out.dir = sample_cosine_hemisphere(n, u);
    out.weight = m.albedo;
    return out;
}
