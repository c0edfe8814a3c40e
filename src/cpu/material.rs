//! BSDF sampling (WGSL side: `shaders/material.wgsl`).

use super::rng::Rng;
use crate::shader_types::{Material, MATERIAL_DIELECTRIC, MATERIAL_METAL, MATERIAL_SPECULAR};
use glam::Vec3;

/// The same f32 as the WGSL literal `3.14159265358979`.
pub use std::f32::consts::PI;

/// Orthonormal basis around a unit `n` (Duff et al., "Building an Orthonormal Basis, Revisited").
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        Vec3::new(b, s + n.y * n.y * a, -n.y),
    )
}

/// Cosine-weighted direction about `n`: pdf = cos θ / π. With the Lambertian BRDF albedo / π
/// the path weight brdf · cos / pdf is exactly the albedo.
pub fn sample_cosine_hemisphere(n: Vec3, u: (f32, f32)) -> Vec3 {
    let r = u.0.sqrt();
    let phi = 2.0 * PI * u.1;
    let x = r * phi.cos();
    let y = r * phi.sin();
    let z = (1.0 - u.0).max(0.0).sqrt();
    let (t, b) = basis(n);
    (x * t + y * b + z * n).normalize()
}

/// WGSL's `reflect`.
pub fn reflect(wi: Vec3, n: Vec3) -> Vec3 {
    wi - 2.0 * n.dot(wi) * n
}

/// Metal below this GGX alpha is a perfect mirror (its lobe is narrower than f32 can resolve).
pub const MIN_METAL_ALPHA: f32 = 1e-4;

#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub dir: Vec3,
    /// f · cos / pdf, or the reflectance of a delta lobe; zero when the path is absorbed.
    pub weight: Vec3,
    /// Solid-angle pdf of `dir`; 0 for delta lobes.
    pub pdf: f32,
    pub is_delta: bool,
}

/// Mirrors, glass and very smooth metal scatter into single directions.
pub fn is_delta(m: &Material) -> bool {
    m.kind == MATERIAL_SPECULAR
        || m.kind == MATERIAL_DIELECTRIC
        || (m.kind == MATERIAL_METAL && m.alpha < MIN_METAL_ALPHA)
}

pub fn to_local(v: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = basis(n);
    Vec3::new(v.dot(t), v.dot(b), v.dot(n))
}

pub fn from_local(v: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = basis(n);
    v.x * t + v.y * b + v.z * n
}

pub fn fresnel_schlick(f0: Vec3, cos_theta: f32) -> Vec3 {
    let c = (1.0 - cos_theta).clamp(0.0, 1.0);
    f0 + (Vec3::ONE - f0) * (c * c * c * c * c)
}

/// Unpolarised Fresnel reflectance of a dielectric interface; eta = η_incident / η_transmitted,
/// cos_i > 0. Total internal reflection gives 1.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// GGX (Trowbridge-Reitz) normal distribution; m_z is the microfacet normal's cosine.
pub fn ggx_d(m_z: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = m_z * m_z * (a2 - 1.0) + 1.0;
    a2 / (PI * d * d)
}

/// Smith's Λ for GGX, written as x / (2 (1 + √(1 + x))) to avoid cancellation.
pub fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let x = alpha * alpha * (w.x * w.x + w.y * w.y) / (w.z * w.z).max(1e-20);
    x / (2.0 * (1.0 + (1.0 + x).sqrt()))
}

/// A microfacet normal from the distribution of normals visible from wo (Heitz, "Sampling the
/// GGX Distribution of Visible Normals", JCGT 2018). Local frame, wo.z > 0.
pub fn sample_ggx_visible_normal(wo: Vec3, alpha: f32, u: (f32, f32)) -> Vec3 {
    let vh = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u.0.sqrt();
    let phi = 2.0 * PI * u.1;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * (r * phi.sin());
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize()
}

/// pdf of wi = reflect(−wo, m) with m from [`sample_ggx_visible_normal`]: G1(wo) D(m) / (4 wo.z).
/// Defined for every wi, also below the surface (such samples are absorbed).
pub fn ggx_reflection_pdf(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    let h = wo + wi;
    if h.dot(h) == 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let m = h.normalize();
    if m.z <= 0.0 {
        return 0.0;
    }
    ggx_d(m.z, alpha) / ((1.0 + ggx_lambda(wo, alpha)) * 4.0 * wo.z)
}

/// f · cos θi for light arriving from wi and leaving towards wo (n faces wo). Zero for delta
/// lobes and for wi below the surface.
pub fn bsdf_eval(m: &Material, wo: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
    let cos_i = wi.dot(n);
    if cos_i <= 0.0 || is_delta(m) {
        return Vec3::ZERO;
    }
    if m.kind == MATERIAL_METAL {
        let wo_l = to_local(wo, n);
        let wi_l = to_local(wi, n);
        // wo below the normal: sampling never returns such pairs (their pdf is 0), so neither
        // may light sampling (valid_shading_normal keeps wo above it but for rounding).
        if wo_l.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (wo_l + wi_l).normalize();
        let g2 = 1.0 / (1.0 + ggx_lambda(wo_l, m.alpha) + ggx_lambda(wi_l, m.alpha));
        let f = fresnel_schlick(Vec3::from(m.albedo), wo_l.dot(h));
        return f * (ggx_d(h.z, m.alpha) * g2 / (4.0 * wo_l.z));
    }
    Vec3::from(m.albedo) * (cos_i / PI)
}

/// The solid-angle pdf with which [`bsdf_sample`] returns wi.
pub fn bsdf_pdf(m: &Material, wo: Vec3, wi: Vec3, n: Vec3) -> f32 {
    if is_delta(m) {
        return 0.0;
    }
    if m.kind == MATERIAL_METAL {
        return ggx_reflection_pdf(to_local(wo, n), to_local(wi, n), m.alpha);
    }
    wi.dot(n).max(0.0) / PI
}

/// Samples the direction light arrives from, for light leaving towards wo. `n` faces wo;
/// `front_face` says whether that is the outside (for glass).
pub fn bsdf_sample(m: &Material, wo: Vec3, n: Vec3, front_face: bool, rng: &mut Rng) -> BsdfSample {
    let cos_o = wo.dot(n);
    let delta = |dir: Vec3, weight: Vec3| BsdfSample {
        dir,
        weight,
        pdf: 0.0,
        is_delta: true,
    };
    if m.kind == MATERIAL_SPECULAR {
        return delta(reflect(-wo, n).normalize(), Vec3::from(m.albedo));
    }
    if m.kind == MATERIAL_DIELECTRIC {
        // Reflect with the Fresnel probability, else refract: the weights F / F and
        // (1 − F) / (1 − F) cancel, leaving the tint and the radiance scaling η².
        let eta = if front_face { 1.0 / m.ior } else { m.ior };
        let reflectance = fresnel_dielectric(cos_o, eta);
        if rng.next_f32() < reflectance {
            return delta(reflect(-wo, n).normalize(), Vec3::ONE);
        }
        let sin2_t = eta * eta * (1.0 - cos_o * cos_o).max(0.0);
        let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
        let dir = (-eta * wo + (eta * cos_o - cos_t) * n).normalize();
        return delta(dir, Vec3::from(m.albedo) * (eta * eta));
    }
    let u = (rng.next_f32(), rng.next_f32());
    if m.kind == MATERIAL_METAL {
        if m.alpha < MIN_METAL_ALPHA {
            return delta(
                reflect(-wo, n).normalize(),
                fresnel_schlick(Vec3::from(m.albedo), cos_o),
            );
        }
        let wo_l = to_local(wo, n);
        let h = sample_ggx_visible_normal(wo_l, m.alpha, u);
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
        let g1 = 1.0 / (1.0 + ggx_lambda(wo_l, m.alpha));
        let g2 = 1.0 / (1.0 + ggx_lambda(wo_l, m.alpha) + ggx_lambda(wi_l, m.alpha));
        return BsdfSample {
            dir,
            weight: fresnel_schlick(Vec3::from(m.albedo), wo_l.dot(h)) * (g2 / g1),
            pdf: ggx_reflection_pdf(wo_l, wi_l, m.alpha),
            is_delta: false,
        };
    }
    let dir = sample_cosine_hemisphere(n, u);
    BsdfSample {
        dir,
        weight: Vec3::from(m.albedo),
        pdf: dir.dot(n).max(0.0) / PI,
        is_delta: false,
    }
}
