//! Rough glass: Walter et al. 2007's GGX microfacet BSDF, reflection and refraction, through
//! the surface both ways (WGSL side: `shaders/rough_dielectric.wgsl`). pbr.rs uses it as its
//! transmission lobe (KHR_materials_transmission).
//!
//! Local frame with n = +z on wo's side (wo.z > 0); `etap` = η(wi's side when refracted) /
//! η(wo's side): the ior entering, 1/ior leaving. With m the microfacet normal (m.z > 0):
//! - reflection, m = normalize(wo + wi): f = F D G2 / (4 cos θo cos θi);
//! - refraction, m = −normalize(wo + etap wi): f = (1 − F) D G2 |wi·m| |wo·m| /
//!   (cos θo |cos θi| (wi·m + wo·m / etap)²) / etap².
//!
//! The last 1/etap² = (η_wo / η_wi)² is the radiance scaling of refraction: glint traces
//! radiance from the camera, as the smooth dielectric.rs does (its η²). F is dielectric.rs's
//! exact unpolarised Fresnel term at wo·m (1 beyond the critical angle), G2 Smith's
//! height-correlated masking-shadowing. Sampling draws m from the normals visible from wo
//! (microfacet.rs), then reflects with probability F and refracts otherwise, so the weight
//! f cos / pdf is G2/G1 (over etap² when refracted). Single scattering: energy that would
//! scatter between microfacets again is lost (tests/rough_dielectric.rs measures how much).

use super::dielectric::fresnel_dielectric;
use super::microfacet::{ggx_d, ggx_lambda, sample_ggx_visible_normal};
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
fn half_vector(etap: f32, wo: Vec3, wi: Vec3) -> Option<Vec3> {
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

/// f · |cos θi| for light arriving from wi and leaving towards wo, both in the local frame.
pub fn rough_dielectric_eval(alpha: f32, etap: f32, wo: Vec3, wi: Vec3) -> f32 {
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

/// The solid-angle pdf with which [`rough_dielectric_sample`] returns wi.
pub fn rough_dielectric_pdf(alpha: f32, etap: f32, wo: Vec3, wi: Vec3) -> f32 {
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

/// A direction for light leaving towards wo (local frame, wo.z > 0): `u` picks the visible
/// microfacet normal, `choice` reflection (probability F) or refraction.
pub fn rough_dielectric_sample(
    alpha: f32,
    etap: f32,
    wo: Vec3,
    u: (f32, f32),
    choice: f32,
) -> RoughDielectricSample {
    let m = sample_ggx_visible_normal(wo, alpha, u);
    let cos_o = wo.dot(m);
    let eta = 1.0 / etap;
    let f = fresnel_dielectric(cos_o, eta);
    let g1 = 1.0 / (1.0 + ggx_lambda(wo, alpha));
    if choice < f {
        let wi = (2.0 * cos_o * m - wo).normalize();
        let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
        return RoughDielectricSample {
            wi,
            weight: if wi.z > 0.0 { g2 / g1 } else { 0.0 },
            refracted: false,
        };
    }
    // Snell's law about m (F < 1, so no total internal reflection).
    let sin2_t = eta * eta * (1.0 - cos_o * cos_o).max(0.0);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let wi = (-eta * wo + (eta * cos_o - cos_t) * m).normalize();
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
