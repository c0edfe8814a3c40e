//! The Lambertian lobe (WGSL side: `shaders/materials/diffuse.wgsl`).

use crate::cpu::core::frame::{basis, PI};
use crate::cpu::materials::bsdf::BsdfSample;
use glam::Vec3;

/// Cosine-weighted direction about `n`: pdf = cos θ / π. With the Lambertian BRDF albedo / π
/// the path weight brdf · cos / pdf is exactly the albedo.
pub fn sample_cosine_hemisphere(n: Vec3, u: (f32, f32)) -> Vec3 {
    let r = u.0.sqrt();
    let phi = 2.0 * PI * u.1;
    let x = r * phi.cos();
    let y = r * phi.sin();
    let z = (1.0 - u.0).max(0.0).sqrt();
    let (t, b) = basis(n);
    (x * t + y * b + z * n).normalize()
}

/// f · cos θi of a Lambertian surface of `albedo`; cos_i > 0.
pub fn diffuse_eval(albedo: Vec3, cos_i: f32) -> Vec3 {
    albedo * (cos_i / PI)
}

pub fn diffuse_sample(albedo: Vec3, n: Vec3, u: (f32, f32)) -> BsdfSample {
    let dir = sample_cosine_hemisphere(n, u);
    BsdfSample {
        dir,
        weight: albedo,
        pdf: dir.dot(n).max(0.0) / PI,
        is_delta: false,
    }
}
