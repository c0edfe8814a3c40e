// Rough glass's single-scattering lobe: Walter et al. 2007's GGX microfacet BSDF, light
// reflected or refracted once by one microfacet (mirror: src/cpu/materials/rough_dielectric_single.rs).
// rough_dielectric.wgsl adds the energy it loses. Local frame with n = +z on wo's side;
// etap = eta(wi's side when refracted) / eta(wo's side).

struct RoughDielectricSample {
    wi: vec3<f32>,
    // f |cos theta_i| / pdf; 0 when the path is absorbed.
    weight: f32,
    refracted: bool,
}

// The microfacet normal that takes wo to wi (facing +z), or zero where there is none.
fn rough_dielectric_half_vector(etap: f32, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if wo.z <= 0.0 || wi.z == 0.0 {
        return vec3<f32>(0.0);
    }
    let reflected = wi.z > 0.0;
    let h = select(wo + etap * wi, wo + wi, reflected);
    let length2 = dot(h, h);
    if length2 <= 1e-20 {
        return vec3<f32>(0.0);
    }
    var m = h / sqrt(length2);
    if m.z < 0.0 {
        m = -m;
    }
    // Both directions on the sides of the microfacet that their side of the surface implies.
    if dot(wo, m) <= 0.0 || dot(wi, m) * wi.z <= 0.0 {
        return vec3<f32>(0.0);
    }
    return m;
}

// The single-scattering lobe's f |cos theta_i|.
fn single_scattering_eval(alpha: f32, etap: f32, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let m = rough_dielectric_half_vector(etap, wo, wi);
    if m.z <= 0.0 {
        return 0.0;
    }
    let f = fresnel_dielectric(dot(wo, m), 1.0 / etap);
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
    let d = ggx_d(m.z, alpha);
    if wi.z > 0.0 {
        return f * d * g2 / (4.0 * wo.z);
    }
    let denominator = dot(wi, m) + dot(wo, m) / etap;
    return (1.0 - f) * d * g2 * abs(dot(wi, m) * dot(wo, m))
        / (wo.z * denominator * denominator * etap * etap);
}

// The solid-angle pdf with which single_scattering_sample returns wi.
fn single_scattering_pdf(alpha: f32, etap: f32, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let m = rough_dielectric_half_vector(etap, wo, wi);
    if m.z <= 0.0 {
        return 0.0;
    }
    let f = fresnel_dielectric(dot(wo, m), 1.0 / etap);
    // The density of visible normals, G1(wo) D(m) (wo.m) / cos theta_o.
    let visible = ggx_d(m.z, alpha) * dot(wo, m) / ((1.0 + ggx_lambda(wo, alpha)) * wo.z);
    if wi.z > 0.0 {
        return f * visible / (4.0 * dot(wo, m));
    }
    let denominator = dot(wi, m) + dot(wo, m) / etap;
    return (1.0 - f) * visible * abs(dot(wi, m)) / (denominator * denominator);
}

// A direction of the single-scattering lobe for light leaving towards wo (local frame,
// wo.z > 0): u picks the visible microfacet normal, choice reflection (probability F) or
// refraction.
fn single_scattering_sample(alpha: f32, etap: f32, wo: vec3<f32>, u: vec2<f32>, choice: f32) -> RoughDielectricSample {
    var out: RoughDielectricSample;
    let m = sample_ggx_visible_normal(wo, alpha, u);
    let cos_o = dot(wo, m);
    let eta = 1.0 / etap;
    let f = fresnel_dielectric(cos_o, eta);
    let g1 = 1.0 / (1.0 + ggx_lambda(wo, alpha));
    if choice < f {
        out.wi = normalize(2.0 * cos_o * m - wo);
        let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(out.wi, alpha));
        out.weight = select(0.0, g2 / g1, out.wi.z > 0.0);
        out.refracted = false;
        return out;
    }
    // Snell's law about m (F < 1, so no total internal reflection).
    let sin2_t = eta * eta * max(0.0, 1.0 - cos_o * cos_o);
    let cos_t = sqrt(max(0.0, 1.0 - sin2_t));
    out.wi = normalize(-eta * wo + (eta * cos_o - cos_t) * m);
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(out.wi, alpha));
    out.weight = select(0.0, g2 / g1 * (eta * eta), out.wi.z < 0.0);
    out.refracted = true;
    return out;
}
