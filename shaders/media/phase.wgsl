// The Henyey-Greenstein phase function (mirror: src/cpu/media/phase.rs). cos_theta is the
// cosine between the direction light travelled before scattering and the one it leaves in.

// (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2)).
fn hg_phase(g: f32, cos_theta: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * PI * denom * sqrt(max(denom, 0.0)));
}

// A direction with density hg_phase(g, dot(dir, result)): cos theta by inversion (uniform
// where |g| is too small for the closed form's division by g).
fn sample_hg(g: f32, dir: vec3<f32>, u1: f32, u2: f32) -> vec3<f32> {
    var cos_theta = 1.0 - 2.0 * u1;
    if abs(g) >= 1e-3 {
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
        cos_theta = clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
    }
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let phi = 2.0 * PI * u2;
    return from_local(vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta), dir);
}
