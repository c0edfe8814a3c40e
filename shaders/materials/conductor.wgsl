// Rough metal: single-scattering GGX with Schlick's Fresnel from the colour as F0 (mirror:
// src/cpu/materials/conductor.rs), as Mitsuba's roughconductor with the same Fresnel. Below
// MIN_METAL_ALPHA it is a perfect mirror.

// Metal below this GGX alpha is a perfect mirror (its lobe is narrower than f32 can resolve).
const MIN_METAL_ALPHA: f32 = 1e-4;

// f * cos(theta_i); wo and wi in the local frame, wi.z > 0.
fn conductor_eval(f0: vec3<f32>, alpha: f32, wo_l: vec3<f32>, wi_l: vec3<f32>) -> vec3<f32> {
    // wo below the normal: sampling never returns such pairs (their pdf is 0), so neither
    // may light sampling (valid_shading_normal keeps wo above it but for rounding).
    if wo_l.z <= 0.0 {
        return vec3<f32>(0.0);
    }
    let h = normalize(wo_l + wi_l);
    let g2 = 1.0 / (1.0 + ggx_lambda(wo_l, alpha) + ggx_lambda(wi_l, alpha));
    let f = fresnel_schlick(f0, dot(wo_l, h));
    return f * (ggx_d(h.z, alpha) * g2 / (4.0 * wo_l.z));
}

fn conductor_sample(f0: vec3<f32>, alpha: f32, wo: vec3<f32>, n: vec3<f32>, u: vec2<f32>) -> BsdfSample {
    var out: BsdfSample;
    out.pdf = 0.0;
    out.is_delta = true;
    if alpha < MIN_METAL_ALPHA {
        out.dir = normalize(reflect(-wo, n));
        out.weight = fresnel_schlick(f0, dot(wo, n));
        return out;
    }
    let wo_l = to_local(wo, n);
    let h = sample_ggx_visible_normal(wo_l, alpha, u);
    let wi_l = 2.0 * dot(wo_l, h) * h - wo_l;
    out.is_delta = false;
    out.dir = normalize(from_local(wi_l, n));
    if wi_l.z <= 0.0 || wo_l.z <= 0.0 {
        // Reflected below the surface (or seen from below the normal, which
        // valid_shading_normal prevents but for rounding): the single-scattering model
        // absorbs it.
        out.weight = vec3<f32>(0.0);
        return out;
    }
    let g1 = 1.0 / (1.0 + ggx_lambda(wo_l, alpha));
    let g2 = 1.0 / (1.0 + ggx_lambda(wo_l, alpha) + ggx_lambda(wi_l, alpha));
    out.weight = fresnel_schlick(f0, dot(wo_l, h)) * (g2 / g1);
    out.pdf = ggx_reflection_pdf(wo_l, wi_l, alpha);
    return out;
}
