//! Rough glass: Walter et al. 2007's GGX microfacet BSDF, reflection and refraction, through
//! the surface both ways, energy-compensated (WGSL side: `shaders/materials/rough_dielectric.wgsl`).
//! pbr.rs uses it as its transmission lobe (KHR_materials_transmission).
//!
//! Local frame with n = +z on wo's side (wo.z > 0); `etap` = η(wi's side when refracted) /
//! η(wo's side): the ior entering, 1/ior leaving. With m the microfacet normal (m.z > 0):
//! - reflection, m = normalize(wo + wi): f = F D G2 / (4 cos θo cos θi);
//! - refraction, m = −normalize(wo + etap wi): f = (1 − F) D G2 |wi·m| |wo·m| /
//!   (cos θo |cos θi| (wi·m + wo·m / etap)²) / etap².
//!
//! The last 1/etap² = (η_wo / η_wi)² is the radiance scaling of refraction: glint traces
//! radiance from the camera, as the smooth dielectric.rs does (its η²). F is dielectric.rs's
//! exact unpolarised Fresnel term at wo·m (1 beyond the critical angle), G2 Smith's
//! height-correlated masking-shadowing. Sampling draws m from the normals visible from wo
//! (microfacet.rs), then reflects with probability F and refracts otherwise, so the weight
//! f cos / pdf is G2/G1 (over etap² when refracted).
//!
//! That single-scattering lobe (`rough_dielectric_single.rs`) loses the energy that would scatter between microfacets again
//! (in a white furnace up to 21% entering and 53% leaving at roughness 1). Kulla and Conty
//! 2017's dielectric compensation gives it back: with E(μ) the lobe's albedo on a side (the
//! energy it keeps, η² taken out; `dielectric_energy.rs`), a for wo's side and b the other,
//! - reflection: (1 − t) (1 − E_a(μo)) (1 − E_a(μi)) / (π (1 − E_avg,a));
//! - refraction: t (1 − E_a(μo)) (1 − E_b(μi)) / (π (1 − E_avg,b)) / etap²;
//!
//! whose albedo is 1 − E_a(μo), so the whole lobe keeps everything from both sides. t, the
//! share that goes through, is 1 − F_avg (a smooth interface's average transmittance) for
//! light entering the denser medium; leaving it, reciprocity f(wi, wo) = f(wo, wi) etap² fixes
//! t_b (1 − E_avg,b) etap_b² = t_a (1 − E_avg,a), which keeps most of the lost energy inside
//! (as total internal reflection does). Kulla–Conty rather than Turquin 2019's scaling by
//! 1/E: the scaled lobe is not reciprocal between the two sides (E_a ≠ E_b), and it would
//! scale the single-scattering lobe's shape by up to 2× from inside; the added lobe is
//! reciprocal by construction and the same method as the rest of pbr.rs. Sampling picks the
//! single-scattering lobe with probability E_a(μo) (at least 0.1), else a cosine lobe below
//! (probability t) or above, and weights by the mixture pdf, which MIS uses too.

use crate::cpu::core::frame::PI;
use crate::cpu::materials::dielectric_energy::{
    dielectric_albedo, dielectric_albedo_average, smooth_transmittance_average,
};
use crate::cpu::materials::diffuse::sample_cosine_hemisphere;
pub use crate::cpu::materials::rough_dielectric_single::RoughDielectricSample;
use crate::cpu::materials::rough_dielectric_single::{
    single_scattering_eval, single_scattering_pdf, single_scattering_sample,
};
use glam::Vec3;
/// Kulla and Conty's compensation at one shading point.
#[derive(Clone, Copy, Debug)]
struct Compensation {
    /// E at μo on wo's side, E_avg on wo's side and on the other.
    albedo_o: f32,
    average_o: f32,
    average_other: f32,
    /// The share t of the compensation lobe that goes through the surface.
    transmitted: f32,
}

fn compensation(alpha: f32, etap: f32, mu_o: f32) -> Compensation {
    let average_o = dielectric_albedo_average(alpha, etap);
    let average_other = dielectric_albedo_average(alpha, 1.0 / etap);
    let transmittance = smooth_transmittance_average(etap);
    let transmitted = if etap >= 1.0 {
        transmittance
    } else if average_o < 1.0 {
        // Reciprocity with the other side, whose share is the smooth transmittance.
        (etap * etap * transmittance * (1.0 - average_other) / (1.0 - average_o)).min(1.0)
    } else {
        0.0
    };
    Compensation {
        albedo_o: dielectric_albedo(mu_o, alpha, etap),
        average_o,
        average_other,
        transmitted,
    }
}

impl Compensation {
    /// The probability of sampling the single-scattering lobe: its share of the albedo, at
    /// least 0.1 so that it is never starved.
    fn single_probability(&self) -> f32 {
        self.albedo_o.clamp(0.1, 1.0)
    }

    /// The compensation lobe's f · |cos θi| (wo.z > 0, wi.z ≠ 0).
    fn eval(&self, alpha: f32, etap: f32, wi: Vec3) -> f32 {
        let lost_o = (1.0 - self.albedo_o).max(0.0);
        if wi.z > 0.0 {
            if self.average_o >= 1.0 {
                return 0.0;
            }
            let lost_i = (1.0 - dielectric_albedo(wi.z, alpha, etap)).max(0.0);
            return (1.0 - self.transmitted) * lost_o * lost_i * wi.z
                / (PI * (1.0 - self.average_o));
        }
        if self.average_other >= 1.0 {
            return 0.0;
        }
        let lost_i = (1.0 - dielectric_albedo(-wi.z, alpha, 1.0 / etap)).max(0.0);
        self.transmitted * lost_o * lost_i * -wi.z / (PI * (1.0 - self.average_other) * etap * etap)
    }

    /// The density of the compensation lobe's sampler: a cosine lobe below with probability
    /// t, above otherwise.
    fn pdf(&self, wi: Vec3) -> f32 {
        let share = if wi.z > 0.0 {
            1.0 - self.transmitted
        } else {
            self.transmitted
        };
        share * wi.z.abs() / PI
    }
}

/// The probability with which [`rough_dielectric_sample`] samples the single-scattering lobe
/// at cos θo = `mu_o`, and the share t of the compensation lobe's samples that go through the
/// surface (tests build the sampler's density from them).
pub fn rough_dielectric_lobe_shares(alpha: f32, etap: f32, mu_o: f32) -> (f32, f32) {
    let c = compensation(alpha, etap, mu_o);
    (c.single_probability(), c.transmitted)
}

/// f · |cos θi| for light arriving from wi and leaving towards wo, both in the local frame.
pub fn rough_dielectric_eval(alpha: f32, etap: f32, wo: Vec3, wi: Vec3) -> f32 {
    if wo.z <= 0.0 || wi.z == 0.0 {
        return 0.0;
    }
    let c = compensation(alpha, etap, wo.z);
    single_scattering_eval(alpha, etap, wo, wi) + c.eval(alpha, etap, wi)
}

/// The solid-angle pdf with which [`rough_dielectric_sample`] returns wi.
pub fn rough_dielectric_pdf(alpha: f32, etap: f32, wo: Vec3, wi: Vec3) -> f32 {
    if wo.z <= 0.0 || wi.z == 0.0 {
        return 0.0;
    }
    let c = compensation(alpha, etap, wo.z);
    let p = c.single_probability();
    p * single_scattering_pdf(alpha, etap, wo, wi) + (1.0 - p) * c.pdf(wi)
}

/// A direction for light leaving towards wo (local frame, wo.z > 0): `choice` picks the
/// single-scattering lobe or the compensation lobe and, within it, reflection or refraction;
/// `u` the direction.
pub fn rough_dielectric_sample(
    alpha: f32,
    etap: f32,
    wo: Vec3,
    u: (f32, f32),
    choice: f32,
) -> RoughDielectricSample {
    let c = compensation(alpha, etap, wo.z);
    let p = c.single_probability();
    if choice < p {
        let s = single_scattering_sample(alpha, etap, wo, u, choice / p);
        if s.weight == 0.0 || p >= 1.0 {
            return s;
        }
        // The mixture's f / pdf, written with the lobe's own weight f_s / pdf_s, which stays
        // finite where pdf_s does not (ior 1 makes the refraction a delta).
        let pdf_single = single_scattering_pdf(alpha, etap, wo, s.wi);
        let weight = if pdf_single > 0.0 && pdf_single.is_finite() {
            (s.weight + c.eval(alpha, etap, s.wi) / pdf_single)
                / (p + (1.0 - p) * c.pdf(s.wi) / pdf_single)
        } else {
            s.weight / p
        };
        return RoughDielectricSample { weight, ..s };
    }
    let refracted = (choice - p) / (1.0 - p) < c.transmitted;
    let side = if refracted { -Vec3::Z } else { Vec3::Z };
    let wi = sample_cosine_hemisphere(side, u);
    let pdf = p * single_scattering_pdf(alpha, etap, wo, wi) + (1.0 - p) * c.pdf(wi);
    let f = single_scattering_eval(alpha, etap, wo, wi) + c.eval(alpha, etap, wi);
    RoughDielectricSample {
        wi,
        weight: if pdf > 0.0 { f / pdf } else { 0.0 },
        refracted,
    }
}
