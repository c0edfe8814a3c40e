// The Lambertian lobe (mirror: src/cpu/materials/diffuse.rs).

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

// f * cos(theta_i) of a Lambertian surface of `albedo`; cos_i > 0.
fn diffuse_eval(albedo: vec3<f32>, cos_i: f32) -> vec3<f32> {
    return albedo * (cos_i / PI);
}

fn diffuse_sample(albedo: vec3<f32>, n: vec3<f32>, u: vec2<f32>) -> BsdfSample {
    var out: BsdfSample;
    out.is_delta = false;
    out.dir = sample_cosine_hemisphere(n, u);
    out.weight = albedo;
    out.pdf = max(dot(out.dir, n), 0.0) / PI;
    return out;
}
