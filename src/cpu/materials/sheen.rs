//! KHR_materials_sheen's "Charlie" sheen (WGSL side: `shaders/materials/sheen.wgsl`): Estevez and
//! Kulla 2017's distribution D = (2 + 1/α) sin^(1/α) θh / (2π), α = sheen roughness², with the
//! extension's fitted visibility V (`crate::tables::sheen`), f = sheen colour · D · V.
//!
//! The layers below are scaled as the extension says, by
//! min(1 − max(colour) E(μo), 1 − max(colour) E(μi)), E the white lobe's albedo
//! (`sheen_energy.rs`): reciprocal, and never creating energy, but not conserving it either
//! (see README.md for what a white furnace measures).
//!
//! Sampled uniformly over the hemisphere: the distribution has no closed-form sampler, and a
//! sheen reflects most towards grazing angles, where a cosine lobe (the mixture's other
//! broad strategy) samples least; a uniform lobe gives them as much density as the pole.

use crate::cpu::core::frame::PI;
use crate::cpu::materials::sheen_energy::sheen_albedo;
use crate::tables::sheen::SHEEN_MIN_ROUGHNESS;
use glam::Vec3;

/// What the sheen needs at one shading point, from its colour, roughness and μo.
#[derive(Clone, Copy, Debug)]
pub struct SheenLobe {
    /// Black: no sheen.
    pub color: Vec3,
    roughness: f32,
    alpha: f32,
    /// 1 − max(colour) E(μo): the most the layers below keep.
    scale_o: f32,
    /// The mean over the channels of colour · E(μo): the weight of sampling the lobe.
    pub albedo_o: f32,
}

/// No sheen: black, the layers below keep everything.
pub const NO_SHEEN: SheenLobe = SheenLobe {
    color: Vec3::ZERO,
    roughness: 1.0,
    alpha: 1.0,
    scale_o: 1.0,
    albedo_o: 0.0,
};

pub fn sheen_lobe(color: Vec3, roughness: f32, mu_o: f32) -> SheenLobe {
    let roughness = roughness.max(SHEEN_MIN_ROUGHNESS as f32);
    let e_o = sheen_albedo(mu_o, roughness);
    SheenLobe {
        color,
        roughness,
        alpha: roughness * roughness,
        scale_o: 1.0 - color.max_element() * e_o,
        albedo_o: (color.x + color.y + color.z) * (1.0 / 3.0) * e_o,
    }
}

/// The share of light from wo that the sheen leaves to the layers below.
pub fn sheen_transmitted_o(l: &SheenLobe) -> f32 {
    l.scale_o
}

/// The extension's fit L(x), its coefficients interpolated by (1 − α)².
fn lambda_fit(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let a = 21.5473 + (25.3245 - 21.5473) * t;
    let b = 3.82987 + (3.32435 - 3.82987) * t;
    let c = 0.19823 + (0.16801 - 0.19823) * t;
    let d = -1.97760 + (-1.27393 + 1.97760) * t;
    let e = -4.32054 + (-4.85967 + 4.32054) * t;
    a / (1.0 + b * x.powf(c)) + d * x + e
}

fn charlie_lambda(cos: f32, alpha: f32) -> f32 {
    if cos < 0.5 {
        lambda_fit(cos, alpha).exp()
    } else {
        (2.0 * lambda_fit(0.5, alpha) - lambda_fit(1.0 - cos, alpha)).exp()
    }
}

/// (f · cos θi of the sheen, the scale of the layers below) for wo, wi in the local frame,
/// both above the surface.
pub fn sheen_eval(l: &SheenLobe, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
    let h = (wo + wi).normalize();
    let inv = 1.0 / l.alpha;
    let sin2 = (1.0 - h.z * h.z).max(0.0);
    let d = (2.0 + inv) * sin2.powf(0.5 * inv) / (2.0 * PI);
    let v = 1.0
        / ((1.0 + charlie_lambda(wo.z, l.alpha) + charlie_lambda(wi.z, l.alpha))
            * (4.0 * wo.z * wi.z));
    let v = v.clamp(0.0, 1.0);
    let e_i = sheen_albedo(wi.z, l.roughness);
    let below = l.scale_o.min(1.0 - l.color.max_element() * e_i);
    (l.color * (d * v * wi.z), below)
}

/// The density of [`sample_uniform_hemisphere`].
pub const UNIFORM_HEMISPHERE_PDF: f32 = 1.0 / (2.0 * PI);

/// A direction in the local frame, uniform over the upper hemisphere.
pub fn sample_uniform_hemisphere(u: (f32, f32)) -> Vec3 {
    let z = u.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.1;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}
