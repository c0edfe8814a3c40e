// A light sample, and how much of it counts against BSDF sampling: the MIS weights that every
// light type and the integrator share (mirror: src/cpu/lights/light_sample.rs).

// A direction towards a light, chosen by next-event estimation (sampling.wgsl, punctual.wgsl).
struct LightSample {
    dir: vec3<f32>,
    // Solid-angle pdf of `dir`; 0 when no light could be sampled.
    pdf: f32,
    radiance: vec3<f32>,
    primitive: u32,
    index: u32,
    // A point, spot or delta sun: no BSDF-sampled ray reaches it, so its MIS weight is 1.
    is_delta: bool,
}

// The MIS weight of a light sample against BSDF sampling, which would have drawn its direction
// with bsdf_pdf: 1 for delta lights, which BSDF sampling cannot reach.
fn nee_weight(light: LightSample, bsdf_pdf: f32) -> f32 {
    if light.is_delta {
        return 1.0;
    }
    return power_heuristic(light.pdf, bsdf_pdf);
}

// The largest finite f32.
const F32_MAX: f32 = 3.40282347e38;

// Veach's power heuristic (beta = 2) for the sample drawn with pdf `a` against pdf `b`:
// a^2 / (a^2 + b^2), written with the ratio of the smaller pdf to the larger so that nothing
// overflows (a light pdf can exceed 1e19, whose square is infinite in f32). Infinite pdfs
// (a light too small or too grazing to sample) are taken as the largest finite ones.
fn power_heuristic(a: f32, b: f32) -> f32 {
    if !(a > 0.0) {
        return 0.0;
    }
    if !(b > 0.0) {
        return 1.0;
    }
    let a_max = min(a, F32_MAX);
    let b_max = min(b, F32_MAX);
    if a_max >= b_max {
        let r = b_max / a_max;
        return 1.0 / (1.0 + r * r);
    }
    let r = a_max / b_max;
    let r2 = r * r;
    return r2 / (1.0 + r2);
}
