//! GGX microfacet distribution, shadowing and sampling, and Schlick's Fresnel (WGSL side:
//! `shaders/materials/microfacet.wgsl`), shared by the lobes built on them.

use crate::cpu::core::frame::PI;
use glam::Vec3;

pub fn fresnel_schlick(f0: Vec3, cos_theta: f32) -> Vec3 {
    let c = (1.0 - cos_theta).clamp(0.0, 1.0);
    f0 + (Vec3::ONE - f0) * (c * c * c * c * c)
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
