//! glTF 2.0's metallic-roughness material (its specification's Appendix B, with
//! KHR_materials_ior and KHR_materials_specular), energy-compensated (WGSL side:
//! `shaders/materials/pbr.wgsl`).
//!
//! - A GGX specular lobe, α = roughness², with Schlick's Fresnel: for the dielectric part
//!   f0 = min(((ior − 1)/(ior + 1))² · specular_color, 1) · specular and f90 = specular, for the
//!   metal part f0 = base colour and f90 = 1. As both parts share the microfacet distribution,
//!   `mix(dielectric, metal, metallic)` of the specular lobes is one lobe with the mixed Fresnel.
//! - Multiple scattering between microfacets (Kulla and Conty 2017): a lobe
//!   F_ms · (1 − E(μo))(1 − E(μi)) / (π (1 − E_avg)), E the albedo of the lobe with F = 1 and
//!   F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)), F_avg Schlick's hemispherical average
//!   f0 + (f90 − f0)/21. A white conductor then reflects everything at every roughness.
//! - The diffuse base under the dielectric layer, by albedo scaling made reciprocal (Kulla and
//!   Conty's layering): (1 − metallic) · base/π · (1 − Es(μo))(1 − Es(μi)) / (1 − Es_avg), Es the
//!   dielectric layer's whole albedo (single and multiple scattering). White over white
//!   reflects everything too; where the layer reflects more, the base gets less.
//!
//! - Transmission (KHR_materials_transmission): the extension's dielectric BRDF is
//!   fresnel_mix(layer = specular, base = mix(diffuse, btdf · base colour, transmission)),
//!   which is (1 − T) · (the stack above) + T · (the rough dielectric of `rough_dielectric.rs`,
//!   its refraction tinted by the base colour), T the transmission. The rough dielectric has
//!   the exact Fresnel term of the ior (it decides total internal reflection from inside) and
//!   its own energy compensation (`dielectric_energy.rs`); KHR_materials_specular does not
//!   change it.
//!
//! - Over all that, KHR_materials_sheen's sheen (`sheen.rs`) and over that KHR_materials_
//!   clearcoat's coat (`clearcoat.rs`), as the extensions stack them: f = coat + below_coat ·
//!   (sheen + below_sheen · base), each `below` its layer's albedo scaling. Refraction, which
//!   leaves below the surface, keeps the layers' shares at μo.
//!
//! The tables E, Es are looked up in `ggx_energy.rs`. Sampling picks the transmission lobe,
//! the specular lobe (visible normals), the coat's lobe (visible normals), the sheen's
//! (uniform) or a cosine lobe (for the diffuse and multiple-scattering lobes) with
//! probabilities from their albedos at μo, and weights by the mixture pdf, which MIS uses
//! too. Refracted samples are delta only where the refraction is (roughness 0, or ior 1, where
//! the lobe refracts straight through): elsewhere light sampling evaluates the rough BTDF for
//! lights on the far side (its shadow rays leave through the surface), and what a refracted
//! sample reaches shares its light with it by MIS.

use crate::cpu::core::frame::{from_local, to_local, PI};
use crate::cpu::materials::bsdf::BsdfSample;
use crate::cpu::materials::clearcoat::{
    clearcoat_coupling, clearcoat_eval, clearcoat_lobe, clearcoat_transmitted_o, ClearcoatLobe,
    NO_CLEARCOAT,
};
use crate::cpu::materials::diffuse::sample_cosine_hemisphere;
use crate::cpu::materials::ggx_energy::{ggx_albedo, ggx_albedo_average};
use crate::cpu::materials::microfacet::{
    ggx_d, ggx_lambda, ggx_reflection_pdf, sample_ggx_visible_normal,
};
use crate::cpu::materials::rough_dielectric::{
    rough_dielectric_eval, rough_dielectric_pdf, rough_dielectric_sample,
};
use crate::cpu::materials::sheen::{
    sample_uniform_hemisphere, sheen_eval, sheen_lobe, sheen_transmitted_o, SheenLobe, NO_SHEEN,
    UNIFORM_HEMISPHERE_PDF,
};
use crate::kernel::types::Material;
use glam::Vec3;

/// The smallest GGX α of the material (roughness 0.032): below it the specular lobe would be
/// a delta over a diffuse base, which light sampling could not mix with.
pub const PBR_MIN_ALPHA: f32 = 1e-3;

/// Bounds of the probability of sampling the specular lobe, so neither strategy starves.
const MIN_LOBE_PROBABILITY: f32 = 0.1;
/// The most the coat's and the sheen's lobes are each sampled with, so the stack below them
/// keeps at least 1 − 2 · 0.45 of the samples.
const MAX_LAYER_PROBABILITY: f32 = 0.45;

/// Whether the material's refraction is a delta, which light sampling cannot evaluate:
/// roughness 0 (the lobe's α is then clamped to PBR_MIN_ALPHA, a needle no light sample
/// would meet), or ior 1, where every microfacet refracts straight through.
pub fn pbr_refraction_is_delta(m: &Material) -> bool {
    m.alpha <= 0.0 || m.ior == 1.0
}

/// What the lobes need at one shading point, from the material and μo.
#[derive(Clone, Copy, Debug)]
pub struct PbrLobes {
    base: Vec3,
    metallic: f32,
    alpha: f32,
    dielectric_f0: Vec3,
    dielectric_f90: f32,
    /// E(μo) and E_avg, with F = 1.
    e_o: f32,
    e_average: f32,
    /// F_ms of the dielectric and the metal part.
    ms_dielectric: Vec3,
    ms_metal: Vec3,
    /// The dielectric layer's whole albedo at μo, and its average.
    layer_o: Vec3,
    layer_average: Vec3,
    /// The transmissive share T of the dielectric part, and η(the other side) / η(wo's side).
    transmission: f32,
    etap: f32,
    /// Refracted samples are delta ([`pbr_refraction_is_delta`]).
    refraction_is_delta: bool,
    /// Probabilities of sampling the specular lobe and the transmission lobe (the cosine lobe
    /// has the rest).
    specular_probability: f32,
    transmission_probability: f32,
    /// The coat and the sheen (zero weight and black where the material has none), the
    /// probabilities of sampling their lobes, and the share of light from wo that passes both.
    coat: ClearcoatLobe,
    sheen: SheenLobe,
    coat_probability: f32,
    sheen_probability: f32,
    layers_o: f32,
    /// The factors of the diffuse base and of the multiple-scattering lobe that normalise the
    /// coat's scaling and their own together (clearcoat_coupling; 1 without a coat).
    coat_diffuse_coupling: Vec3,
    coat_ms_coupling: f32,
}

fn average(v: Vec3) -> f32 {
    (v.x + v.y + v.z) * (1.0 / 3.0)
}

/// Kulla and Conty's F_ms for a lobe whose average Fresnel is `f_average`.
fn multiple_scattering_fresnel(f_average: Vec3, e_average: f32) -> Vec3 {
    f_average * f_average * e_average / (Vec3::ONE - f_average * (1.0 - e_average))
}

impl PbrLobes {
    /// The probability with which [`pbr_sample`] samples the specular lobe (tests check the
    /// sampler against it).
    pub fn specular_probability(&self) -> f32 {
        self.specular_probability
    }

    /// The probability with which [`pbr_sample`] samples the transmission lobe.
    pub fn transmission_probability(&self) -> f32 {
        self.transmission_probability
    }

    /// The probabilities with which [`pbr_sample`] samples the coat's and the sheen's lobes.
    pub fn coat_probability(&self) -> f32 {
        self.coat_probability
    }

    pub fn sheen_probability(&self) -> f32 {
        self.sheen_probability
    }
}

/// `front_face` says whether wo is on the outside (which decides η for transmission); `mu_o`
/// is cos θo about the base's shading normal, `coat_mu_o` about the coat's (clearcoat.rs).
pub fn pbr_lobes(m: &Material, mu_o: f32, coat_mu_o: f32, front_face: bool) -> PbrLobes {
    let base = Vec3::from(m.albedo);
    let alpha = m.alpha.max(PBR_MIN_ALPHA);
    let r = (m.ior - 1.0) / (m.ior + 1.0);
    let dielectric_f0 = (r * r * Vec3::from(m.specular_color)).min(Vec3::ONE) * m.specular;
    let dielectric_f90 = m.specular;
    let (a_o, b_o) = ggx_albedo(mu_o, alpha);
    let (a_average, b_average) = ggx_albedo_average(alpha);
    let e_o = a_o + b_o;
    let e_average = a_average + b_average;
    let ms_dielectric = multiple_scattering_fresnel(
        dielectric_f0 + (dielectric_f90 - dielectric_f0) * (1.0 / 21.0),
        e_average,
    );
    let ms_metal = multiple_scattering_fresnel(base + (Vec3::ONE - base) * (1.0 / 21.0), e_average);
    let layer_o =
        dielectric_f0 * a_o + Vec3::splat(dielectric_f90 * b_o) + ms_dielectric * (1.0 - e_o);
    let layer_average = dielectric_f0 * a_average
        + Vec3::splat(dielectric_f90 * b_average)
        + ms_dielectric * (1.0 - e_average);
    let metallic = m.metallic;
    let transmission = m.transmission;
    // The opaque dielectric stack's share.
    let opaque = (1.0 - metallic) * (1.0 - transmission);
    let specular = opaque * (dielectric_f0 * a_o + Vec3::splat(dielectric_f90 * b_o))
        + metallic * (base * a_o + Vec3::splat(b_o));
    let ms = (opaque * ms_dielectric + metallic * ms_metal) * (1.0 - e_o);
    let diffuse = opaque * base * (Vec3::ONE - layer_o);
    let specular_weight = average(specular);
    let other_weight = average(ms + diffuse);
    let transmission_weight = (1.0 - metallic) * transmission;
    let opaque_total = specular_weight + other_weight;
    let total = opaque_total + transmission_weight;
    let transmission_probability = if total > 0.0 {
        transmission_weight / total
    } else {
        0.0
    };
    let specular_share = if opaque_total > 0.0 {
        (specular_weight / opaque_total).clamp(MIN_LOBE_PROBABILITY, 1.0 - MIN_LOBE_PROBABILITY)
    } else {
        0.5
    };
    let mut specular_probability = (1.0 - transmission_probability) * specular_share;
    let mut transmission_probability = transmission_probability;
    // The layers on top: their lobes take shares of the samples by their albedos at μo
    // against the stack's (which they dim), each within [0.1, 0.45] when present.
    // Only materials with a coat or a sheen read their tables.
    let coat = if m.clearcoat > 0.0 {
        clearcoat_lobe(m.clearcoat, m.clearcoat_alpha, coat_mu_o, alpha)
    } else {
        NO_CLEARCOAT
    };
    let sheen_color = Vec3::from(m.sheen_color);
    let sheen = if sheen_color.max_element() > 0.0 {
        sheen_lobe(sheen_color, m.sheen_roughness, mu_o)
    } else {
        NO_SHEEN
    };
    let (mut coat_diffuse_coupling, mut coat_ms_coupling) = (Vec3::ONE, 1.0);
    if coat.weight > 0.0 {
        // What passes the dielectric layer, 1 − Es = (1 − F_ms) − (f0 − F_ms) A − (f90 − F_ms) B,
        // and what the multiple scattering leaves, 1 − E = 1 − A − B.
        coat_diffuse_coupling = clearcoat_coupling(
            &coat,
            alpha,
            Vec3::ONE - ms_dielectric,
            ms_dielectric - dielectric_f0,
            ms_dielectric - Vec3::splat(dielectric_f90),
        );
        coat_ms_coupling = clearcoat_coupling(&coat, alpha, Vec3::ONE, -Vec3::ONE, -Vec3::ONE).x;
    }
    let below_coat = clearcoat_transmitted_o(&coat);
    let layers_o = below_coat * sheen_transmitted_o(&sheen);
    let (mut coat_probability, mut sheen_probability) = (0.0, 0.0);
    if coat.weight > 0.0 || sheen.color.max_element() > 0.0 {
        let coat_weight = coat.specular_albedo_o;
        let sheen_weight = below_coat * sheen.albedo_o;
        let all = coat_weight + sheen_weight + coat.ms_albedo_o + layers_o * total;
        let share = |weight: f32, present: bool| {
            if present && all > 0.0 {
                (weight / all).clamp(MIN_LOBE_PROBABILITY, MAX_LAYER_PROBABILITY)
            } else {
                0.0
            }
        };
        // A coat whose normal wo does not see cannot be sampled (its lobe is black there).
        coat_probability = share(coat_weight, coat.weight > 0.0 && coat_mu_o > 0.0);
        sheen_probability = share(sheen_weight, sheen.color.max_element() > 0.0);
        let rest = 1.0 - coat_probability - sheen_probability;
        specular_probability *= rest;
        transmission_probability *= rest;
    }
    PbrLobes {
        base,
        metallic,
        alpha,
        dielectric_f0,
        dielectric_f90,
        e_o,
        e_average,
        ms_dielectric,
        ms_metal,
        layer_o,
        layer_average,
        transmission,
        etap: if front_face { m.ior } else { 1.0 / m.ior },
        refraction_is_delta: pbr_refraction_is_delta(m),
        specular_probability,
        transmission_probability,
        coat,
        sheen,
        coat_probability,
        sheen_probability,
        layers_o,
        coat_diffuse_coupling,
        coat_ms_coupling,
    }
}

/// f · cos θi; wo and wi in the base's local frame, coat_wo and coat_wi (the same directions)
/// in the coat's.
pub fn pbr_eval(lobes: &PbrLobes, wo: Vec3, wi: Vec3, coat_wo: Vec3, coat_wi: Vec3) -> Vec3 {
    let l = lobes;
    // The transmission lobe's share of the whole.
    let transmissive = (1.0 - l.metallic) * l.transmission;
    if wo.z <= 0.0 || wi.z == 0.0 {
        return Vec3::ZERO;
    }
    if wi.z < 0.0 {
        if transmissive <= 0.0 {
            return Vec3::ZERO;
        }
        return l.base
            * (transmissive * l.layers_o * rough_dielectric_eval(l.alpha, l.etap, wo, wi));
    }
    let opaque = (1.0 - l.metallic) * (1.0 - l.transmission);
    let h = (wo + wi).normalize();
    let c = (1.0 - wo.dot(h)).clamp(0.0, 1.0);
    let s5 = c * c * c * c * c;
    let g2 = 1.0 / (1.0 + ggx_lambda(wo, l.alpha) + ggx_lambda(wi, l.alpha));
    let dg = ggx_d(h.z, l.alpha) * g2 / (4.0 * wo.z);
    // The specular lobes (GGX, and the transmission lobe's reflection) apart from the broad
    // ones: the coat scales them as narrow lobes (clearcoat.rs), the two parts of Schlick's
    // Fresnel f0 (1 − s⁵) + f90 s⁵ each by its own factor.
    let mut narrow_f0 = (opaque * l.dielectric_f0 + l.metallic * l.base) * ((1.0 - s5) * dg);
    let mut narrow_f90 = Vec3::splat((opaque * l.dielectric_f90 + l.metallic) * s5 * dg);
    let (a_i, b_i) = ggx_albedo(wi.z, l.alpha);
    let e_i = a_i + b_i;
    let mut out = Vec3::ZERO;
    if l.e_average < 1.0 {
        let ms = opaque * l.ms_dielectric + l.metallic * l.ms_metal;
        out += ms
            * ((1.0 - l.e_o) * (1.0 - e_i) / (PI * (1.0 - l.e_average))
                * wi.z
                * l.coat_ms_coupling);
    }
    let layer_i =
        l.dielectric_f0 * a_i + Vec3::splat(l.dielectric_f90 * b_i) + l.ms_dielectric * (1.0 - e_i);
    let transmitted = (Vec3::ONE - l.layer_o) * (Vec3::ONE - layer_i);
    let room = Vec3::ONE - l.layer_average;
    let base_weight = Vec3::new(
        if room.x > 0.0 {
            transmitted.x / room.x
        } else {
            0.0
        },
        if room.y > 0.0 {
            transmitted.y / room.y
        } else {
            0.0
        },
        if room.z > 0.0 {
            transmitted.z / room.z
        } else {
            0.0
        },
    );
    out += opaque * l.base * base_weight * l.coat_diffuse_coupling * (wi.z / PI);
    if transmissive > 0.0 {
        // Its exact Fresnel is f90-like: small head-on, all of the reflection at grazing.
        narrow_f90 += Vec3::splat(transmissive * rough_dielectric_eval(l.alpha, l.etap, wo, wi));
    }
    if l.sheen.color.max_element() > 0.0 {
        let (sheen, below) = sheen_eval(&l.sheen, wo, wi);
        out = sheen + below * out;
        narrow_f0 *= below;
        narrow_f90 *= below;
    }
    if l.coat.weight > 0.0 {
        let coat = clearcoat_eval(&l.coat, coat_wo, coat_wi);
        return Vec3::splat(coat.f_cos)
            + coat.below_broad * out
            + coat.below_narrow.x * narrow_f0
            + coat.below_narrow.y * narrow_f90;
    }
    out + narrow_f0 + narrow_f90
}

/// The mixture pdf of [`pbr_sample`]; wo and wi in the base's local frame, coat_wo and coat_wi
/// in the coat's.
pub fn pbr_pdf(lobes: &PbrLobes, wo: Vec3, wi: Vec3, coat_wo: Vec3, coat_wi: Vec3) -> f32 {
    if wo.z <= 0.0 {
        return 0.0;
    }
    let (p_specular, p_transmission) = (lobes.specular_probability, lobes.transmission_probability);
    let mut pdf = 0.0;
    if p_transmission > 0.0 {
        pdf = p_transmission * rough_dielectric_pdf(lobes.alpha, lobes.etap, wo, wi);
    }
    if wi.z > 0.0 {
        let (p_coat, p_sheen) = (lobes.coat_probability, lobes.sheen_probability);
        pdf += p_specular * ggx_reflection_pdf(wo, wi, lobes.alpha)
            + (1.0 - p_specular - p_transmission - p_coat - p_sheen) * (wi.z / PI);
        if p_coat > 0.0 {
            pdf += p_coat * ggx_reflection_pdf(coat_wo, coat_wi, lobes.coat.alpha);
        }
        pdf += p_sheen * UNIFORM_HEMISPHERE_PDF;
    }
    pdf
}

/// `choice` picks the lobe, `u` the direction; `n` (the base's shading normal) and `coat_n`
/// (the coat's) face wo.
pub fn pbr_sample(
    lobes: &PbrLobes,
    wo: Vec3,
    n: Vec3,
    coat_n: Vec3,
    choice: f32,
    u: (f32, f32),
) -> BsdfSample {
    let wo_l = to_local(wo, n);
    let coat_wo = to_local(wo, coat_n);
    let l = lobes;
    let p_transmission = l.transmission_probability;
    let (dir, wi_l) = if choice < p_transmission {
        let s = rough_dielectric_sample(l.alpha, l.etap, wo_l, u, choice / p_transmission);
        let dir = from_local(s.wi, n).normalize();
        if s.refracted {
            // Only the transmission lobe reaches below: the mixture's f cos / pdf is the
            // lobe's own weight times its share over its probability (and at ior 1, where the
            // lobe is a delta, this stays finite where f and pdf do not).
            let share = (1.0 - l.metallic) * l.transmission * l.layers_o / p_transmission;
            return BsdfSample {
                dir,
                weight: l.base * (s.weight * share),
                pdf: p_transmission * rough_dielectric_pdf(l.alpha, l.etap, wo_l, s.wi),
                is_delta: l.refraction_is_delta,
            };
        }
        (dir, s.wi)
    } else if choice < p_transmission + lobes.specular_probability {
        let h = sample_ggx_visible_normal(wo_l, lobes.alpha, u);
        let wi_l = 2.0 * wo_l.dot(h) * h - wo_l;
        (from_local(wi_l, n).normalize(), wi_l)
    } else if choice < p_transmission + lobes.specular_probability + l.coat_probability {
        // The coat's lobe about its own normal.
        let h = sample_ggx_visible_normal(coat_wo, l.coat.alpha, u);
        let coat_wi = 2.0 * coat_wo.dot(h) * h - coat_wo;
        let dir = from_local(coat_wi, coat_n).normalize();
        (dir, to_local(dir, n))
    } else if choice
        < p_transmission + lobes.specular_probability + l.coat_probability + l.sheen_probability
    {
        let wi_l = sample_uniform_hemisphere(u);
        (from_local(wi_l, n).normalize(), wi_l)
    } else {
        let dir = sample_cosine_hemisphere(n, u);
        (dir, to_local(dir, n))
    };
    let coat_wi = to_local(dir, coat_n);
    let pdf = pbr_pdf(lobes, wo_l, wi_l, coat_wo, coat_wi);
    // A reflection below the surface is absorbed: below, f / pdf counts only the transmission
    // lobe's refractions, whose density alone pbr_pdf gives there.
    let weight = if pdf > 0.0 && wi_l.z > 0.0 {
        pbr_eval(lobes, wo_l, wi_l, coat_wo, coat_wi) / pdf
    } else {
        Vec3::ZERO
    };
    BsdfSample {
        dir,
        weight,
        pdf,
        is_delta: false,
    }
}
