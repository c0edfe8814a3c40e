//! Rough metal: single-scattering GGX with Schlick's Fresnel from the colour as F0 (WGSL side:
//! `shaders/materials/conductor.wgsl`), as Mitsuba's roughconductor with the same Fresnel. Below
//! [`MIN_METAL_ALPHA`] it is a perfect mirror.

use crate::cpu::core::frame::{from_local, reflect, to_local};
use crate::cpu::materials::bsdf::BsdfSample;
use crate::cpu::materials::microfacet::{
    fresnel_schlick, ggx_d, ggx_lambda, ggx_reflection_pdf, sample_ggx_visible_normal,
};
use glam::Vec3;

/// Metal below this GGX alpha is a perfect mirror (its lobe is narrower than f32 can resolve).
pub const MIN_METAL_ALPHA: f32 = 1e-4;

/// f · cos θi; wo and wi in the local frame, wi.z > 0.
pub fn conductor_eval(f0: Vec3, alpha: f32, wo_l: Vec3, wi_l: Vec3) -> Vec3 {
    // wo below the normal: sampling never returns such pairs (their pdf is 0), so neither
    // may light sampling (valid_shading_normal keeps wo above it but for rounding).
    if wo_l.z <= 0.0 {
        return Vec3::ZERO;
    }
    let h = (wo_l + wi_l).normalize();
    let g2 = 1.0 / (1.0 + ggx_lambda(wo_l, alpha) + ggx_lambda(wi_l, alpha));
    let f = fresnel_schlick(f0, wo_l.dot(h));
    f * (ggx_d(h.z, alpha) * g2 / (4.0 * wo_l.z))
}

pub fn conductor_sample(f0: Vec3, alpha: f32, wo: Vec3, n: Vec3, u: (f32, f32)) -> BsdfSample {
    if alpha < MIN_METAL_ALPHA {
        return BsdfSample {
            dir: reflect(-wo, n).normalize(),
            weight: fresnel_schlick(f0, wo.dot(n)),
            pdf: 0.0,
            is_delta: true,
        };
    }
    let wo_l = to_local(wo, n);
    let h = sample_ggx_visible_normal(wo_l, alpha, u);
    let wi_l = 2.0 * wo_l.dot(h) * h - wo_l;
    let dir = from_local(wi_l, n).normalize();
    if wi_l.z <= 0.0 || wo_l.z <= 0.0 {
        // Reflected below the surface (or seen from below the normal, which
        // valid_shading_normal prevents but for rounding): the single-scattering model
        // absorbs it.
        return BsdfSample {
            dir,
            weight: Vec3::ZERO,
            pdf: 0.0,
            is_delta: false,
        };
    }
    let g1 = 1.0 / (1.0 + ggx_lambda(wo_l, alpha));
    let g2 = 1.0 / (1.0 + ggx_lambda(wo_l, alpha) + ggx_lambda(wi_l, alpha));
    BsdfSample {
        dir,
        weight: fresnel_schlick(f0, wo_l.dot(h)) * (g2 / g1),
        pdf: ggx_reflection_pdf(wo_l, wi_l, alpha),
        is_delta: false,
    }
}
