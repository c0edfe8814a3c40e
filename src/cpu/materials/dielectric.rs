//! Smooth glass: Fresnel reflection or Snell refraction (WGSL side: `shaders/materials/dielectric.wgsl`).

use crate::cpu::core::frame::reflect;
use crate::cpu::core::rng::Rng;
use crate::cpu::materials::bsdf::BsdfSample;
use glam::Vec3;

/// Unpolarised Fresnel reflectance of a dielectric interface; eta = η_incident / η_transmitted,
/// cos_i > 0. Total internal reflection gives 1.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// `front_face` says whether wo is on the outside; `n` faces wo.
pub fn dielectric_sample(
    tint: Vec3,
    ior: f32,
    wo: Vec3,
    n: Vec3,
    front_face: bool,
    rng: &mut Rng,
) -> BsdfSample {
    let cos_o = wo.dot(n);
    let delta = |dir: Vec3, weight: Vec3| BsdfSample {
        dir,
        weight,
        pdf: 0.0,
        is_delta: true,
    };
    // Reflect with the Fresnel probability, else refract: the weights F / F and
    // (1 − F) / (1 − F) cancel, leaving the tint and the radiance scaling η².
    let eta = if front_face { 1.0 / ior } else { ior };
    let reflectance = fresnel_dielectric(cos_o, eta);
    if rng.next_f32() < reflectance {
        return delta(reflect(-wo, n).normalize(), Vec3::ONE);
    }
    let sin2_t = eta * eta * (1.0 - cos_o * cos_o).max(0.0);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let dir = (-eta * wo + (eta * cos_o - cos_t) * n).normalize();
    delta(dir, tint * (eta * eta))
}
