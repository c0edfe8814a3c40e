//! A validated material as the kernel's `types::Material`: its kind's parameters (roughness
//! squared, the pbr model's extras), texture indices with `NO_TEXTURE` where there is none,
//! and the alpha mode.

use crate::kernel::types::{
    self, ALPHA_BLEND, ALPHA_MASK, ALPHA_OPAQUE, MATERIAL_DIELECTRIC, MATERIAL_DIFFUSE,
    MATERIAL_METAL, MATERIAL_PBR, MATERIAL_SPECULAR, MATERIAL_UNLIT, NO_TEXTURE,
};
use crate::scene::{AlphaMode, Material, MaterialKind, PbrLayers};
use glam::Vec3;

/// What a material's kind sets in the kernel's struct: the kind's code, α (roughness
/// squared), the index of refraction, and the pbr model's parameters, neutral for the others.
struct KindParameters {
    kind: u32,
    alpha: f32,
    ior: f32,
    metallic: f32,
    specular: f32,
    specular_color: Vec3,
    transmission: f32,
    transmission_texture: u32,
    attenuation_color: Vec3,
    attenuation_distance: f32,
    layers: PbrLayers,
}

impl KindParameters {
    fn of(kind: MaterialKind) -> KindParameters {
        let (mut metallic, mut specular, mut specular_color) = (0.0, 0.0, Vec3::ZERO);
        // No transmission nor attenuation but where a pbr material asks for them.
        let (mut transmission, mut transmission_texture) = (0.0, NO_TEXTURE);
        let (mut attenuation_color, mut attenuation_distance) = (Vec3::ONE, 0.0);
        let mut layers = PbrLayers::default();
        let (kind, alpha, ior) = match kind {
            MaterialKind::Diffuse => (MATERIAL_DIFFUSE, 0.0, 1.0),
            MaterialKind::Unlit => (MATERIAL_UNLIT, 0.0, 1.0),
            MaterialKind::Specular => (MATERIAL_SPECULAR, 0.0, 1.0),
            MaterialKind::Metal { roughness } => (MATERIAL_METAL, roughness * roughness, 1.0),
            MaterialKind::Dielectric { ior } => (MATERIAL_DIELECTRIC, 0.0, ior),
            MaterialKind::Pbr {
                roughness,
                metallic: m,
                ior,
                specular: s,
                specular_color: c,
                transmission: t,
                transmission_texture: t_texture,
                attenuation_color: a_color,
                attenuation_distance: a_distance,
                layers: l,
            } => {
                layers = l;
                (metallic, specular, specular_color) = (m, s, c);
                (transmission, transmission_texture) = (t, t_texture.unwrap_or(NO_TEXTURE));
                if let Some(d) = a_distance {
                    (attenuation_color, attenuation_distance) = (a_color, d);
                }
                (MATERIAL_PBR, roughness * roughness, ior)
            }
        };
        KindParameters {
            kind,
            alpha,
            ior,
            metallic,
            specular,
            specular_color,
            transmission,
            transmission_texture,
            attenuation_color,
            attenuation_distance,
            layers,
        }
    }
}

/// `m` as the kernel reads it.
pub(super) fn kernel_material(m: &Material) -> types::Material {
    let KindParameters {
        kind,
        alpha,
        ior,
        metallic,
        specular,
        specular_color,
        transmission,
        transmission_texture,
        attenuation_color,
        attenuation_distance,
        layers,
    } = KindParameters::of(m.kind);
    types::Material {
        albedo: m.color.into(),
        kind,
        emission: m.emitted_radiance.into(),
        alpha,
        ior,
        color_texture: m.color_texture.unwrap_or(NO_TEXTURE),
        roughness_texture: m.roughness_texture.unwrap_or(NO_TEXTURE),
        metallic,
        specular_color: specular_color.into(),
        specular,
        emission_texture: m.emission_texture.unwrap_or(NO_TEXTURE),
        normal_texture: m.normal_texture.map_or(NO_TEXTURE, |(t, _)| t),
        normal_scale: m.normal_texture.map_or(1.0, |(_, s)| s),
        alpha_mode: match m.alpha.mode {
            AlphaMode::Opaque => ALPHA_OPAQUE,
            AlphaMode::Mask { .. } => ALPHA_MASK,
            AlphaMode::Blend => ALPHA_BLEND,
        },
        opacity: m.alpha.opacity,
        alpha_cutoff: match m.alpha.mode {
            AlphaMode::Mask { cutoff } => cutoff,
            // glTF's default, unread.
            AlphaMode::Opaque | AlphaMode::Blend => 0.5,
        },
        transmission,
        transmission_texture,
        attenuation_color: attenuation_color.into(),
        attenuation_distance,
        clearcoat: layers.clearcoat,
        clearcoat_alpha: layers.clearcoat_roughness * layers.clearcoat_roughness,
        clearcoat_texture: layers.clearcoat_texture.unwrap_or(NO_TEXTURE),
        clearcoat_roughness_texture: layers.clearcoat_roughness_texture.unwrap_or(NO_TEXTURE),
        clearcoat_normal_texture: layers
            .clearcoat_normal_texture
            .map_or(NO_TEXTURE, |(t, _)| t),
        clearcoat_normal_scale: layers.clearcoat_normal_texture.map_or(1.0, |(_, s)| s),
        sheen_roughness: layers.sheen_roughness,
        sheen_color_texture: layers.sheen_color_texture.unwrap_or(NO_TEXTURE),
        sheen_color: layers.sheen_color.into(),
        sheen_roughness_texture: layers.sheen_roughness_texture.unwrap_or(NO_TEXTURE),
    }
}
