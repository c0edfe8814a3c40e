// GGX microfacet distribution, shadowing and sampling, and Schlick's Fresnel (mirror:
// src/cpu/materials/microfacet.rs), shared by the lobes built on them.

fn fresnel_schlick(f0: vec3<f32>, cos_theta: f32) -> vec3<f32> {
    let c = clamp(1.0 - cos_theta, 0.0, 1.0);
    return f0 + (vec3<f32>(1.0) - f0) * (c * c * c * c * c);
}

// GGX (Trowbridge-Reitz) normal distribution; m_z is the microfacet normal's cosine.
fn ggx_d(m_z: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = m_z * m_z * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

// Smith's Lambda for GGX, written as x / (2 (1 + sqrt(1 + x))) to avoid cancellation.
fn ggx_lambda(w: vec3<f32>, alpha: f32) -> f32 {
    let x = alpha * alpha * (w.x * w.x + w.y * w.y) / max(w.z * w.z, 1e-20);
    return x / (2.0 * (1.0 + sqrt(1.0 + x)));
}

// A microfacet normal from the distribution of normals visible from wo (Heitz, "Sampling the
// GGX Distribution of Visible Normals", JCGT 2018). Local frame, wo.z > 0.
fn sample_ggx_visible_normal(wo: vec3<f32>, alpha: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(alpha * wo.x, alpha * wo.y, wo.z));
    let len2 = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if len2 > 0.0 {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) / sqrt(len2);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * (r * sin(phi));
    let nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3<f32>(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
}

// pdf of wi = reflect(-wo, m) with m from sample_ggx_visible_normal: G1(wo) D(m) / (4 wo.z).
// Defined for every wi, also below the surface (such samples are absorbed).
fn ggx_reflection_pdf(wo: vec3<f32>, wi: vec3<f32>, alpha: f32) -> f32 {
    let h = wo + wi;
    if dot(h, h) == 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let m = normalize(h);
    if m.z <= 0.0 {
        return 0.0;
    }
    return ggx_d(m.z, alpha) / ((1.0 + ggx_lambda(wo, alpha)) * 4.0 * wo.z);
}
