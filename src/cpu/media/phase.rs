//! The Henyey–Greenstein phase function (WGSL side: `shaders/media/phase.wgsl`).
//!
//! `cos_theta` is the cosine between the direction light travelled before scattering and the
//! one it leaves in, so g > 0 scatters forwards.

use crate::cpu::core::frame::{from_local, PI};
use glam::Vec3;

/// Henyey–Greenstein's density per steradian: (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}).
pub fn hg_phase(g: f32, cos_theta: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denom * denom.max(0.0).sqrt())
}

/// A direction drawn with density `hg_phase(g, dir · result)` from two uniform numbers, by
/// inverting the distribution of cos θ (uniform where |g| is too small for the closed form's
/// division by g to be accurate).
pub fn sample_hg(g: f32, dir: Vec3, u1: f32, u2: f32) -> Vec3 {
    let cos_theta = if g.abs() < 1e-3 {
        1.0 - 2.0 * u1
    } else {
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
        ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
    };
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    from_local(
        Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta),
        dir,
    )
}
