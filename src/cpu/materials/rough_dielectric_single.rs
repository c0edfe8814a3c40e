//! Rough glass's single-scattering lobe: Walter et al. 2007's GGX microfacet BSDF, light
//! reflected or refracted once by one microfacet (WGSL side:
//! `shaders/materials/rough_dielectric_single.wgsl`). `rough_dielectric.rs` adds the energy
//! that lobe loses (its formulas and local frame are described there), and
//! `crate::tables::dielectric` integrates this lobe's albedo into the table that the
//! compensation reads, so the table and the lobe cannot differ. That is why this file imports
//! no table: the generator depends on it, not it on the generator.

use crate::cpu::materials::dielectric::fresnel_dielectric;
use crate::cpu::materials::microfacet::{ggx_d, ggx_lambda, sample_ggx_visible_normal};
use glam::Vec3;

/// A sampled direction in the local frame, and f · |cos θi| / pdf (0 when the path is
/// absorbed: a reflection below the surface, a refraction above it).
#[derive(Clone, Copy, Debug)]
pub struct RoughDielectricSample {
    pub wi: Vec3,
    pub weight: f32,
    pub refracted: bool,
}

/// The microfacet normal that takes wo to wi (facing +z), or None where there is none: wi in
/// the plane of the surface, a degenerate half vector, or a microfacet seen from behind.
pub fn half_vector(etap: f32, wo: Vec3, wi: Vec3) -> Option<Vec3> {
    if wo.z <= 0.0 || wi.z == 0.0 {
        return None;
    }
    let reflected = wi.z > 0.0;
    let h = if reflected { wo + wi } else { wo + etap * wi };
    let length2 = h.dot(h);
    if length2 <= 1e-20 {
        return None;
    }
    let m = h / length2.sqrt();
    let m = if m.z < 0.0 { -m } else { m };
    // Both directions on the sides of the microfacet that their side of the surface implies.
    if wo.dot(m) <= 0.0 || wi.dot(m) * wi.z <= 0.0 {
        return None;
    }
    Some(m)
}

/// The single-scattering lobe's f · |cos θi| for light arriving from wi and leaving towards
/// wo, both in the local frame.
pub fn single_scattering_eval(alpha: f32, etap: f32, wo: Vec3, wi: Vec3) -> f32 {
    let Some(m) = half_vector(etap, wo, wi) else {
        return 0.0;
    };
    let f = fresnel_dielectric(wo.dot(m), 1.0 / etap);
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
    let d = ggx_d(m.z, alpha);
    if wi.z > 0.0 {
        return f * d * g2 / (4.0 * wo.z);
    }
    let denominator = wi.dot(m) + wo.dot(m) / etap;
    (1.0 - f) * d * g2 * (wi.dot(m) * wo.dot(m)).abs()
        / (wo.z * denominator * denominator * etap * etap)
}

/// The solid-angle pdf with which [`single_scattering_sample`] returns wi.
pub fn single_scattering_pdf(alpha: f32, etap: f32, wo: Vec3, wi: Vec3) -> f32 {
    let Some(m) = half_vector(etap, wo, wi) else {
        return 0.0;
    };
    let f = fresnel_dielectric(wo.dot(m), 1.0 / etap);
    // The density of visible normals, G1(wo) D(m) (wo·m) / cos θo.
    let visible = ggx_d(m.z, alpha) * wo.dot(m) / ((1.0 + ggx_lambda(wo, alpha)) * wo.z);
    if wi.z > 0.0 {
        return f * visible / (4.0 * wo.dot(m));
    }
    let denominator = wi.dot(m) + wo.dot(m) / etap;
    (1.0 - f) * visible * wi.dot(m).abs() / (denominator * denominator)
}

/// A direction of the single-scattering lobe for light leaving towards wo (local frame,
/// wo.z > 0): `u` picks the visible microfacet normal, `choice` reflection (probability F) or
/// refraction.
pub fn single_scattering_sample(
    alpha: f32,
    etap: f32,
    wo: Vec3,
    u: (f32, f32),
    choice: f32,
) -> RoughDielectricSample {
    let m = sample_ggx_visible_normal(wo, alpha, u);
    let eta = 1.0 / etap;
    if choice < fresnel_dielectric(wo.dot(m), eta) {
        reflection_about(alpha, wo, m)
    } else {
        refraction_about(alpha, eta, wo, m)
    }
}

/// The reflection of wo about the microfacet normal m, weighted G2/G1.
fn reflection_about(alpha: f32, wo: Vec3, m: Vec3) -> RoughDielectricSample {
    let wi = (2.0 * wo.dot(m) * m - wo).normalize();
    let g1 = 1.0 / (1.0 + ggx_lambda(wo, alpha));
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
    RoughDielectricSample {
        wi,
        weight: if wi.z > 0.0 { g2 / g1 } else { 0.0 },
        refracted: false,
    }
}

/// The refraction of wo through the microfacet normal m (η = η_wo / η_wi, F < 1 so no total
/// internal reflection), weighted G2/G1 times the radiance scaling η².
fn refraction_about(alpha: f32, eta: f32, wo: Vec3, m: Vec3) -> RoughDielectricSample {
    let cos_o = wo.dot(m);
    let sin2_t = eta * eta * (1.0 - cos_o * cos_o).max(0.0);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let wi = (-eta * wo + (eta * cos_o - cos_t) * m).normalize();
    let g1 = 1.0 / (1.0 + ggx_lambda(wo, alpha));
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
    RoughDielectricSample {
        wi,
        weight: if wi.z < 0.0 {
            g2 / g1 * (eta * eta)
        } else {
            0.0
        },
        refracted: true,
    }
}

/// The single-scattering lobe's expected energy weight for the visible normal that `u` picks:
/// F times the reflection's weight plus (1 − F) times the refraction's, η² taken out. Its mean
/// over u is E(cos θo); `crate::tables::dielectric` integrates it.
pub fn single_scattering_albedo_sample(alpha: f32, etap: f32, wo: Vec3, u: (f32, f32)) -> f32 {
    let m = sample_ggx_visible_normal(wo, alpha, u);
    let eta = 1.0 / etap;
    let f = fresnel_dielectric(wo.dot(m), eta);
    let reflected = f * reflection_about(alpha, wo, m).weight;
    if f >= 1.0 {
        return reflected;
    }
    reflected + (1.0 - f) * refraction_about(alpha, eta, wo, m).weight * etap * etap
}
