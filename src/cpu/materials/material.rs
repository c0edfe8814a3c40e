//! The BSDF of each material kind, dispatched to its lobes (WGSL side: `shaders/materials/material.wgsl`):
//! `diffuse.rs`, `conductor.rs`, `dielectric.rs`, `pbr.rs` (with `rough_dielectric.rs`), on
//! `microfacet.rs` and `frame.rs`.

use crate::cpu::core::frame::{reflect, to_local, PI};
use crate::cpu::core::rng::Rng;
pub use crate::cpu::materials::bsdf::BsdfSample;
use crate::cpu::materials::conductor::{conductor_eval, conductor_sample, MIN_METAL_ALPHA};
use crate::cpu::materials::dielectric::dielectric_sample;
use crate::cpu::materials::diffuse::{diffuse_eval, diffuse_sample};
use crate::cpu::materials::microfacet::ggx_reflection_pdf;
use crate::cpu::materials::pbr::{
    pbr_eval, pbr_lobes, pbr_pdf, pbr_refraction_is_delta, pbr_sample,
};
use crate::kernel::types::{
    Material, MATERIAL_DIELECTRIC, MATERIAL_METAL, MATERIAL_PBR, MATERIAL_SPECULAR,
};
use glam::Vec3;

/// Mirrors, glass and very smooth metal scatter into single directions.
pub fn is_delta(m: &Material) -> bool {
    m.kind == MATERIAL_SPECULAR
        || m.kind == MATERIAL_DIELECTRIC
        || (m.kind == MATERIAL_METAL && m.alpha < MIN_METAL_ALPHA)
}

/// Whether light sampling may evaluate the material below its surface: a pbr material with a
/// rough transmission lobe (pbr.rs's `pbr_refraction_is_delta` says when it is not rough).
pub fn transmits_roughly(m: &Material) -> bool {
    m.kind == MATERIAL_PBR
        && m.transmission > 0.0
        && m.metallic < 1.0
        && !pbr_refraction_is_delta(m)
}

/// f · cos θi for light arriving from wi and leaving towards wo (n faces wo; `front_face` says
/// whether that is the outside). Zero for delta lobes, and for wi below the surface except
/// through a rough transmission lobe ([`transmits_roughly`]), whose light samples' shadow
/// rays leave through the surface. `coat_n`, facing wo too, is the pbr coat's own shading
/// normal (KHR_materials_clearcoat's: n itself where nothing tilts it).
pub fn bsdf_eval(
    m: &Material,
    wo: Vec3,
    wi: Vec3,
    n: Vec3,
    coat_n: Vec3,
    front_face: bool,
) -> Vec3 {
    let cos_i = wi.dot(n);
    if cos_i == 0.0 || (cos_i < 0.0 && !transmits_roughly(m)) || is_delta(m) {
        return Vec3::ZERO;
    }
    if m.kind == MATERIAL_PBR {
        let lobes = pbr_lobes(m, wo.dot(n), wo.dot(coat_n), front_face);
        return pbr_eval(
            &lobes,
            to_local(wo, n),
            to_local(wi, n),
            to_local(wo, coat_n),
            to_local(wi, coat_n),
        );
    }
    if m.kind == MATERIAL_METAL {
        return conductor_eval(
            Vec3::from(m.albedo),
            m.alpha,
            to_local(wo, n),
            to_local(wi, n),
        );
    }
    diffuse_eval(Vec3::from(m.albedo), cos_i)
}

/// The solid-angle pdf with which [`bsdf_sample`] returns wi.
pub fn bsdf_pdf(m: &Material, wo: Vec3, wi: Vec3, n: Vec3, coat_n: Vec3, front_face: bool) -> f32 {
    if is_delta(m) {
        return 0.0;
    }
    if m.kind == MATERIAL_PBR {
        let lobes = pbr_lobes(m, wo.dot(n), wo.dot(coat_n), front_face);
        return pbr_pdf(
            &lobes,
            to_local(wo, n),
            to_local(wi, n),
            to_local(wo, coat_n),
            to_local(wi, coat_n),
        );
    }
    if m.kind == MATERIAL_METAL {
        return ggx_reflection_pdf(to_local(wo, n), to_local(wi, n), m.alpha);
    }
    wi.dot(n).max(0.0) / PI
}

/// Samples the direction light arrives from, for light leaving towards wo. `n` and `coat_n`
/// face wo (as for [`bsdf_eval`]); `front_face` says whether that is the outside (for glass
/// and transmission).
pub fn bsdf_sample(
    m: &Material,
    wo: Vec3,
    n: Vec3,
    coat_n: Vec3,
    front_face: bool,
    rng: &mut Rng,
) -> BsdfSample {
    if m.kind == MATERIAL_SPECULAR {
        return BsdfSample {
            dir: reflect(-wo, n).normalize(),
            weight: Vec3::from(m.albedo),
            pdf: 0.0,
            is_delta: true,
        };
    }
    if m.kind == MATERIAL_DIELECTRIC {
        return dielectric_sample(Vec3::from(m.albedo), m.ior, wo, n, front_face, rng);
    }
    let u = (rng.next_f32(), rng.next_f32());
    if m.kind == MATERIAL_PBR {
        let lobes = pbr_lobes(m, wo.dot(n), wo.dot(coat_n), front_face);
        return pbr_sample(&lobes, wo, n, coat_n, rng.next_f32(), u);
    }
    if m.kind == MATERIAL_METAL {
        return conductor_sample(Vec3::from(m.albedo), m.alpha, wo, n, u);
    }
    diffuse_sample(Vec3::from(m.albedo), n, u)
}
