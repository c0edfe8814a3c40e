// Rough glass: Walter et al. 2007's GGX microfacet BSDF, reflection and refraction, through the
// surface both ways (rough_dielectric_single.wgsl), with Kulla and Conty 2017's energy compensation (mirror:
// src/cpu/materials/rough_dielectric.rs, which gives the formulas and why). Local frame with n = +z on
// wo's side; etap = eta(wi's side when refracted) / eta(wo's side). Refraction carries the
// radiance scaling 1/etap^2, as the smooth dielectric's eta^2.

// Kulla and Conty's compensation at one shading point: E at mu_o on wo's side, E_avg on wo's
// side and on the other, and the share t of the compensation lobe that goes through.
struct Compensation {
    albedo_o: f32,
    average_o: f32,
    average_other: f32,
    transmitted: f32,
}

fn compensation(alpha: f32, etap: f32, mu_o: f32) -> Compensation {
    var c: Compensation;
    c.average_o = dielectric_albedo_average(alpha, etap);
    c.average_other = dielectric_albedo_average(alpha, 1.0 / etap);
    let transmittance = smooth_transmittance_average(etap);
    c.transmitted = 0.0;
    if etap >= 1.0 {
        c.transmitted = transmittance;
    } else if c.average_o < 1.0 {
        // Reciprocity with the other side, whose share is the smooth transmittance.
        c.transmitted = min(etap * etap * transmittance * (1.0 - c.average_other) / (1.0 - c.average_o), 1.0);
    }
    c.albedo_o = dielectric_albedo(mu_o, alpha, etap);
    return c;
}

// The probability of sampling the single-scattering lobe (its share of the albedo, >= 0.1).
fn compensation_single_probability(c: Compensation) -> f32 {
    return clamp(c.albedo_o, 0.1, 1.0);
}

// The compensation lobe's f |cos theta_i| (wo.z > 0, wi.z != 0).
fn compensation_eval(c: Compensation, alpha: f32, etap: f32, wi: vec3<f32>) -> f32 {
    let lost_o = max(1.0 - c.albedo_o, 0.0);
    if wi.z > 0.0 {
        if c.average_o >= 1.0 {
            return 0.0;
        }
        let lost_i = max(1.0 - dielectric_albedo(wi.z, alpha, etap), 0.0);
        return (1.0 - c.transmitted) * lost_o * lost_i * wi.z / (PI * (1.0 - c.average_o));
    }
    if c.average_other >= 1.0 {
        return 0.0;
    }
    let lost_i = max(1.0 - dielectric_albedo(-wi.z, alpha, 1.0 / etap), 0.0);
    return c.transmitted * lost_o * lost_i * -wi.z / (PI * (1.0 - c.average_other) * etap * etap);
}

// The density of the compensation lobe's sampler: a cosine lobe below with probability t.
fn compensation_pdf(c: Compensation, wi: vec3<f32>) -> f32 {
    let share = select(c.transmitted, 1.0 - c.transmitted, wi.z > 0.0);
    return share * abs(wi.z) / PI;
}

// f |cos theta_i| for light arriving from wi and leaving towards wo, both in the local frame.
fn rough_dielectric_eval(alpha: f32, etap: f32, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if wo.z <= 0.0 || wi.z == 0.0 {
        return 0.0;
    }
    let c = compensation(alpha, etap, wo.z);
    return single_scattering_eval(alpha, etap, wo, wi) + compensation_eval(c, alpha, etap, wi);
}

// The solid-angle pdf with which rough_dielectric_sample returns wi.
fn rough_dielectric_pdf(alpha: f32, etap: f32, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if wo.z <= 0.0 || wi.z == 0.0 {
        return 0.0;
    }
    let c = compensation(alpha, etap, wo.z);
    let p = compensation_single_probability(c);
    return p * single_scattering_pdf(alpha, etap, wo, wi) + (1.0 - p) * compensation_pdf(c, wi);
}

// A direction for light leaving towards wo (local frame, wo.z > 0): choice picks the
// single-scattering lobe or the compensation lobe and, within it, reflection or refraction;
// u the direction.
fn rough_dielectric_sample(alpha: f32, etap: f32, wo: vec3<f32>, u: vec2<f32>, choice: f32) -> RoughDielectricSample {
    let c = compensation(alpha, etap, wo.z);
    let p = compensation_single_probability(c);
    if choice < p {
        var s = single_scattering_sample(alpha, etap, wo, u, choice / p);
        if s.weight == 0.0 || p >= 1.0 {
            return s;
        }
        // The mixture's f / pdf from the lobe's own weight, finite where pdf_s is not (ior 1).
        let pdf_single = single_scattering_pdf(alpha, etap, wo, s.wi);
        if pdf_single > 0.0 && pdf_single < 3.0e38 {
            s.weight = (s.weight + compensation_eval(c, alpha, etap, s.wi) / pdf_single)
                / (p + (1.0 - p) * compensation_pdf(c, s.wi) / pdf_single);
        } else {
            s.weight = s.weight / p;
        }
        return s;
    }
    var out: RoughDielectricSample;
    out.refracted = (choice - p) / (1.0 - p) < c.transmitted;
    out.wi = sample_cosine_hemisphere(select(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0, 0.0, -1.0), out.refracted), u);
    let pdf = p * single_scattering_pdf(alpha, etap, wo, out.wi) + (1.0 - p) * compensation_pdf(c, out.wi);
    let f = single_scattering_eval(alpha, etap, wo, out.wi) + compensation_eval(c, alpha, etap, out.wi);
    out.weight = select(0.0, f / pdf, pdf > 0.0);
    return out;
}
