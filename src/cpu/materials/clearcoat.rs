//! KHR_materials_clearcoat's coat (WGSL side: `shaders/materials/clearcoat.wgsl`): a GGX dielectric
//! layer of ior 1.5 (f0 = 0.04, f90 = 1, Schlick's Fresnel), α = clearcoat roughness², over
//! the whole pbr stack, weighted by the clearcoat factor c.
//!
//! - The coat reflects c · (its single-scattering lobe + Kulla and Conty's
//!   multiple-scattering lobe, as `pbr.rs` compensates its own dielectric layer), so a rough
//!   coat over a black base reflects what a rough dielectric reflects.
//! - The extension scales what lies below by 1 − c · F_coat; glint scales it instead by the
//!   coat's whole directional albedo L, made reciprocal two ways. Broad lobes (diffuse,
//!   multiple scattering, sheen) as `pbr.rs` scales its diffuse base:
//!   (1 − c L(μo))(1 − c L(μi)) / (1 − c L_avg), whose sum with the coat is exactly 1 over a
//!   white Lambertian base. Specular lobes, whose light leaves near μi ≈ μo, by
//!   1 − c · min(1, max(L(μo), L(μi)) h(μo) h(μi)), each part of their Schlick Fresnel with
//!   its own h (`crate::tables::clearcoat`, which solves h so that the lobe keeps exactly
//!   1 − c L(μo)); with h = 1 that is min(1 − c L(μo), 1 − c L(μi)), exact for a mirror but
//!   up to 4.3% short over glossy metal. The product form loses 12% at grazing angles over a
//!   smooth base, where both factors are small, and √ of the product or their mean gain up to
//!   11–14% over glossy metal (all measured by tests/suite/pbr.rs's furnace). The base's diffuse and
//!   multiple-scattering lobes, which their own layer scales the same way, are normalised with
//!   the coat's scaling together ([`clearcoat_coupling`]). So a coat over a white stack keeps
//!   its energy (within 1% at every coat roughness: README.md), which F_coat's scaling does
//!   not (it cannot see the light the coat's rough lobe misses).
//!
//! L comes from the GGX tables of `ggx_energy.rs`: f0 · A + B + F_ms (1 − E).

use crate::cpu::core::frame::PI;
use crate::cpu::materials::clearcoat_energy::clearcoat_narrow_scale;
use crate::cpu::materials::ggx_energy::{
    ggx_albedo, ggx_albedo_average, ggx_albedo_product_average,
};
use crate::cpu::materials::microfacet::{ggx_d, ggx_lambda};
use glam::{Vec2, Vec3};

pub use crate::tables::clearcoat::CLEARCOAT_F0;
/// The smallest α of the coat (roughness 0.032), as the pbr material's own.
pub const CLEARCOAT_MIN_ALPHA: f32 = 1e-3;

/// What the coat needs at one shading point, from its weight, α and μo.
#[derive(Clone, Copy, Debug)]
pub struct ClearcoatLobe {
    /// The clearcoat factor c (0: no coat).
    pub weight: f32,
    pub alpha: f32,
    /// E(μo) and E_avg with F = 1.
    e_o: f32,
    e_average: f32,
    /// Kulla and Conty's F_ms of the coat.
    ms: f32,
    /// The coat's whole albedo L at μo, and its average.
    albedo_o: f32,
    albedo_average: f32,
    /// c times the single-scattering albedo at μo: the weight of sampling the coat's lobe.
    pub specular_albedo_o: f32,
    /// c times the multiple-scattering albedo at μo (the mixture's cosine lobe samples it).
    pub ms_albedo_o: f32,
    /// The α of the specular lobes below, and the factor h(μo) of their scaling
    /// (`crate::tables::clearcoat`).
    base_alpha: f32,
    narrow_scale_o: Vec2,
}

/// The coat's whole albedo L from its split-sum parts.
fn layer_albedo(a: f32, b: f32, e: f32, ms: f32) -> f32 {
    CLEARCOAT_F0 * a + b + ms * (1.0 - e)
}

/// No coat: everything passes.
pub const NO_CLEARCOAT: ClearcoatLobe = ClearcoatLobe {
    weight: 0.0,
    alpha: 1.0,
    e_o: 1.0,
    e_average: 1.0,
    ms: 0.0,
    albedo_o: 0.0,
    albedo_average: 0.0,
    specular_albedo_o: 0.0,
    ms_albedo_o: 0.0,
    base_alpha: 1.0,
    narrow_scale_o: Vec2::ONE,
};

/// The coat of weight c and α over specular lobes of α `base_alpha`, seen from μo.
pub fn clearcoat_lobe(weight: f32, alpha: f32, mu_o: f32, base_alpha: f32) -> ClearcoatLobe {
    let alpha = alpha.max(CLEARCOAT_MIN_ALPHA);
    let (a_o, b_o) = ggx_albedo(mu_o, alpha);
    let (a_average, b_average) = ggx_albedo_average(alpha);
    let e_o = a_o + b_o;
    let e_average = a_average + b_average;
    let f_average = CLEARCOAT_F0 + (1.0 - CLEARCOAT_F0) * (1.0 / 21.0);
    let ms = f_average * f_average * e_average / (1.0 - f_average * (1.0 - e_average));
    ClearcoatLobe {
        weight,
        alpha,
        e_o,
        e_average,
        ms,
        albedo_o: layer_albedo(a_o, b_o, e_o, ms),
        albedo_average: layer_albedo(a_average, b_average, e_average, ms),
        specular_albedo_o: weight * (CLEARCOAT_F0 * a_o + b_o),
        ms_albedo_o: weight * ms * (1.0 - e_o),
        base_alpha,
        narrow_scale_o: clearcoat_narrow_scale(mu_o, base_alpha, alpha),
    }
}

/// What the broad lobe of a layer below the coat must be scaled by so that the coat's and the
/// layer's reciprocal scalings together keep its energy.
///
/// The layer (the pbr base's dielectric layer over its diffuse base, or its multiple
/// scattering) passes 1 − L'(μ) = q0 + qa A(μ, α) + qb B(μ, α) of the light at each end and
/// normalises by its own average 1 − L'_avg; the coat passes 1 − c L(μ) and normalises by
/// 1 − c L_avg. Both shares fall towards grazing angles, so the average of their product is
/// more than the product of their averages, and the two normalisations together gave up to
/// +1.3% head-on over a smooth white dielectric base (tests/suite/pbr.rs's coat furnace).
/// Normalising by the product's own average instead, (1 − c L_avg)(1 − L'_avg) /
/// 2∫(1 − c L(μ))(1 − L'(μ)) μ dμ times the two scalings, makes the broad lobe's albedo
/// exactly (1 − c L(μo))(1 − L'(μo)) over a white base. The average comes from the tables'
/// product averages, as 1 − c L = p0 + pa A + pb B is linear in A, B too.
pub fn clearcoat_coupling(l: &ClearcoatLobe, alpha: f32, q0: Vec3, qa: Vec3, qb: Vec3) -> Vec3 {
    let p0 = 1.0 - l.weight * l.ms;
    let pa = -l.weight * (CLEARCOAT_F0 - l.ms);
    let pb = -l.weight * (1.0 - l.ms);
    let (coat_a, coat_b) = ggx_albedo_average(l.alpha);
    let (layer_a, layer_b) = ggx_albedo_average(alpha);
    let [aa, ab, ba, bb] = ggx_albedo_product_average(l.alpha, alpha);
    // 1 − c L_avg, as clearcoat_eval divides by it (= p0 + pa Ā + pb B̄).
    let coat_room = 1.0 - l.weight * l.albedo_average;
    let layer_room = q0 + qa * layer_a + qb * layer_b;
    let joint = p0 * layer_room
        + q0 * (pa * coat_a + pb * coat_b)
        + qa * (pa * aa + pb * ba)
        + qb * (pa * ab + pb * bb);
    let ratio = coat_room * layer_room / joint;
    Vec3::select(joint.cmpgt(Vec3::ZERO), ratio, Vec3::ONE)
}

/// The share of light from wo that passes the coat: 1 − c L(μo) (what refraction keeps).
pub fn clearcoat_transmitted_o(l: &ClearcoatLobe) -> f32 {
    1.0 - l.weight * l.albedo_o
}

/// The coat at one pair of directions: its own f · cos θi, and the scales of the broad and the
/// specular lobes below it.
#[derive(Clone, Copy, Debug)]
pub struct ClearcoatEval {
    pub f_cos: f32,
    pub below_broad: f32,
    /// For the two parts of a specular lobe: weighted by 1 − (1 − cos θh)⁵ and by
    /// (1 − cos θh)⁵ (Schlick's f0 and f90 terms).
    pub below_narrow: Vec2,
}

/// The coat for wo, wi in the coat's local frame (about its own normal). With either below the
/// coat's normal (which a normal map tilts from the base's) its lobe is black; below it, wi
/// dims the layers under the coat as its mirror image above does (|cos θi|), continuous across
/// the coat's horizon, where the coat reflects most. Holding the horizon's albedo beyond it
/// instead loses up to 72% in tests/suite/pbr.rs's tilted-coat furnace (metal under a smooth coat
/// tilted 45°), |cos θi| up to 42%; neither creates energy.
pub fn clearcoat_eval(l: &ClearcoatLobe, wo: Vec3, wi: Vec3) -> ClearcoatEval {
    let (a_i, b_i) = ggx_albedo(wi.z.abs(), l.alpha);
    let e_i = a_i + b_i;
    let albedo_i = layer_albedo(a_i, b_i, e_i, l.ms);
    let passed = (1.0 - l.weight * l.albedo_o) * (1.0 - l.weight * albedo_i);
    let room = 1.0 - l.weight * l.albedo_average;
    let below_broad = if room > 0.0 { passed / room } else { 0.0 };
    let narrow_scale_i = clearcoat_narrow_scale(wi.z.abs(), l.base_alpha, l.alpha);
    let larger = l.albedo_o.max(albedo_i) * l.narrow_scale_o * narrow_scale_i;
    let below_narrow = Vec2::ONE - l.weight * larger.min(Vec2::ONE);
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return ClearcoatEval {
            f_cos: 0.0,
            below_broad,
            below_narrow,
        };
    }
    let h = (wo + wi).normalize();
    let c = (1.0 - wo.dot(h)).clamp(0.0, 1.0);
    let s5 = c * c * c * c * c;
    let fresnel = CLEARCOAT_F0 + (1.0 - CLEARCOAT_F0) * s5;
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, l.alpha) + ggx_lambda(wi, l.alpha));
    let mut f_cos = fresnel * ggx_d(h.z, l.alpha) * g2 / (4.0 * wo.z);
    if l.e_average < 1.0 {
        f_cos += l.ms * (1.0 - l.e_o) * (1.0 - e_i) / (PI * (1.0 - l.e_average)) * wi.z;
    }
    ClearcoatEval {
        f_cos: l.weight * f_cos,
        below_broad,
        below_narrow,
    }
}
