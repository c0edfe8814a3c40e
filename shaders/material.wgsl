// BSDF sampling (mirror: src/cpu/material.rs).

const PI: f32 = 3.14159265358979;

// Orthonormal basis around a unit n (Duff et al., "Building an Orthonormal Basis, Revisited", 2017).
fn basis_tangent(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
}

fn basis_bitangent(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(b, s + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction about n: pdf = cos(theta) / pi. With the Lambertian BRDF albedo / pi
// the path weight brdf * cos / pdf is exactly the albedo.
fn sample_cosine_hemisphere(n: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let x = r * cos(phi);
    let y = r * sin(phi);
    let z = sqrt(max(0.0, 1.0 - u.x));
    return normalize(x * basis_tangent(n) + y * basis_bitangent(n) + z * n);
}

// Metal below this GGX alpha is a perfect mirror (its lobe is narrower than f32 can resolve).
const MIN_METAL_ALPHA: f32 = 1e-4;

struct BsdfSample {
    dir: vec3<f32>,
    // f * cos / pdf, or the reflectance of a delta lobe; zero when the path is absorbed.
    weight: vec3<f32>,
    // Solid-angle pdf of dir; 0 for delta lobes.
    pdf: f32,
    is_delta: bool,
}

// Material kinds a scene lacks are compiled out (HAS_*, see src/shader.rs).
fn is_metal(m: Material) -> bool {
    return HAS_METAL && m.kind == MATERIAL_METAL;
}

fn is_dielectric(m: Material) -> bool {
    return HAS_DIELECTRIC && m.kind == MATERIAL_DIELECTRIC;
}

// Mirrors, glass and very smooth metal scatter into single directions: light sampling cannot
// help there, and emitters they see count in full.
fn is_delta(m: Material) -> bool {
    return m.kind == MATERIAL_SPECULAR || is_dielectric(m)
        || (is_metal(m) && m.alpha < MIN_METAL_ALPHA);
}

fn to_local(v: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(v, basis_tangent(n)), dot(v, basis_bitangent(n)), dot(v, n));
}

fn from_local(v: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return v.x * basis_tangent(n) + v.y * basis_bitangent(n) + v.z * n;
}

fn fresnel_schlick(f0: vec3<f32>, cos_theta: f32) -> vec3<f32> {
    let c = clamp(1.0 - cos_theta, 0.0, 1.0);
    return f0 + (vec3<f32>(1.0) - f0) * (c * c * c * c * c);
}

// Unpolarised Fresnel reflectance of a dielectric interface; eta = eta_incident / eta_transmitted,
// cos_i > 0. Total internal reflection gives 1.
fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
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

// f * cos(theta_i) for light arriving from wi and leaving towards wo (n faces wo). Zero for delta
// lobes and for wi below the surface.
fn bsdf_eval(m: Material, wo: vec3<f32>, wi: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let cos_i = dot(wi, n);
    if cos_i <= 0.0 || is_delta(m) {
        return vec3<f32>(0.0);
    }
    if is_metal(m) {
        let wo_l = to_local(wo, n);
        let wi_l = to_local(wi, n);
        // wo below the normal: sampling never returns such pairs (their pdf is 0), so neither
        // may light sampling (valid_shading_normal keeps wo above it but for rounding).
        if wo_l.z <= 0.0 {
            return vec3<f32>(0.0);
        }
        let h = normalize(wo_l + wi_l);
        let g2 = 1.0 / (1.0 + ggx_lambda(wo_l, m.alpha) + ggx_lambda(wi_l, m.alpha));
        let f = fresnel_schlick(m.albedo, dot(wo_l, h));
        return f * (ggx_d(h.z, m.alpha) * g2 / (4.0 * wo_l.z));
    }
    return m.albedo * (cos_i / PI);
}

// The solid-angle pdf with which bsdf_sample returns wi.
fn bsdf_pdf(m: Material, wo: vec3<f32>, wi: vec3<f32>, n: vec3<f32>) -> f32 {
    if is_delta(m) {
        return 0.0;
    }
    if is_metal(m) {
        return ggx_reflection_pdf(to_local(wo, n), to_local(wi, n), m.alpha);
    }
    return max(dot(wi, n), 0.0) / PI;
}

// Samples the direction light arrives from, for light leaving towards wo. `n` faces wo;
// `front_face` says whether that is the outside (for glass).
fn bsdf_sample(m: Material, wo: vec3<f32>, n: vec3<f32>, front_face: bool, rng: ptr<function, u32>) -> BsdfSample {
    var out: BsdfSample;
    out.pdf = 0.0;
    out.is_delta = true;
    let cos_o = dot(wo, n);
    if m.kind == MATERIAL_SPECULAR {
        out.dir = normalize(reflect(-wo, n));
        out.weight = m.albedo;
        return out;
    }
    if is_dielectric(m) {
        // Reflect with the Fresnel probability, else refract: the weights F / F and
        // (1 - F) / (1 - F) cancel, leaving the tint and the radiance scaling eta^2.
        let eta = select(m.ior, 1.0 / m.ior, front_face);
        let reflectance = fresnel_dielectric(cos_o, eta);
        if rng_next(rng) < reflectance {
            out.dir = normalize(reflect(-wo, n));
            out.weight = vec3<f32>(1.0);
            return out;
        }
        let sin2_t = eta * eta * max(0.0, 1.0 - cos_o * cos_o);
        let cos_t = sqrt(max(0.0, 1.0 - sin2_t));
        out.dir = normalize(-eta * wo + (eta * cos_o - cos_t) * n);
        out.weight = m.albedo * (eta * eta);
        return out;
    }
    let u = vec2<f32>(rng_next(rng), rng_next(rng));
    if is_metal(m) {
        if m.alpha < MIN_METAL_ALPHA {
            out.dir = normalize(reflect(-wo, n));
            out.weight = fresnel_schlick(m.albedo, cos_o);
            return out;
        }
        let wo_l = to_local(wo, n);
        let h = sample_ggx_visible_normal(wo_l, m.alpha, u);
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
        let g1 = 1.0 / (1.0 + ggx_lambda(wo_l, m.alpha));
        let g2 = 1.0 / (1.0 + ggx_lambda(wo_l, m.alpha) + ggx_lambda(wi_l, m.alpha));
        out.weight = fresnel_schlick(m.albedo, dot(wo_l, h)) * (g2 / g1);
        out.pdf = ggx_reflection_pdf(wo_l, wi_l, m.alpha);
        return out;
    }
    out.is_delta = false;
    out.dir = sample_cosine_hemisphere(n, u);
    out.weight = m.albedo;
    out.pdf = max(dot(out.dir, n), 0.0) / PI;
    return out;
}
