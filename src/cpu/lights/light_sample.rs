//! A light sample, and how much of it counts against BSDF sampling: the MIS weights that
//! every light type and the integrator share (WGSL side: `shaders/lights/light_sample.wgsl`).

use glam::Vec3;

/// A direction towards a light, chosen by next-event estimation (`sampling.rs`, `punctual.rs`).
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub dir: Vec3,
    /// Solid-angle pdf of `dir`; 0 when no light could be sampled.
    pub pdf: f32,
    pub radiance: Vec3,
    pub primitive: u32,
    pub index: u32,
    /// A point, spot or delta sun: no BSDF-sampled ray reaches it, so its MIS weight is 1.
    pub is_delta: bool,
}

/// The MIS weight of a light sample against BSDF sampling, which would have drawn its
/// direction with `bsdf_pdf`: 1 for delta lights, which BSDF sampling cannot reach.
pub fn nee_weight(light: &LightSample, bsdf_pdf: f32) -> f32 {
    if light.is_delta {
        return 1.0;
    }
    power_heuristic(light.pdf, bsdf_pdf)
}

/// Veach's power heuristic (β = 2) for the sample drawn with pdf `a` against pdf `b`:
/// a² / (a² + b²), written with the ratio of the smaller pdf to the larger so that nothing
/// overflows (a light pdf can exceed 10¹⁹, whose square is infinite in f32). Infinite pdfs (a
/// light too small or too grazing to sample) are taken as the largest finite ones.
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    // Written to reject NaN as the WGSL does.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(a > 0.0) {
        return 0.0;
    }
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(b > 0.0) {
        return 1.0;
    }
    let a_max = a.min(f32::MAX);
    let b_max = b.min(f32::MAX);
    if a_max >= b_max {
        let r = b_max / a_max;
        return 1.0 / (1.0 + r * r);
    }
    let r = a_max / b_max;
    let r2 = r * r;
    r2 / (1.0 + r2)
}
