//! A glTF material as glint's: the metallic-roughness material and the extensions glint
//! reads onto it, its alpha, and which images its texture maps sample, each value checked
//! (the geometry is read in `primitives.rs`).

use super::texture_ref::{NormalImage, TextureRefs};
use crate::scene::mesh::{check_emission, check_ior, check_reflectance};
use crate::scene::texture::Sampling;
use crate::scene::{Alpha, AlphaMode, Material, MaterialKind, PbrLayers};
use glam::Vec3;
use gltf::json;
use json::extensions::material::Material as MaterialExtensions;
use json::validation::Checked;
use serde::Deserialize;

/// KHR_materials_clearcoat as the file holds it (the gltf crate does not parse it), with the
/// extension's defaults.
#[derive(Deserialize, Default)]
#[serde(rename_all = "camelCase", default)]
struct ClearcoatJson {
    clearcoat_factor: f32,
    clearcoat_texture: Option<json::texture::Info>,
    clearcoat_roughness_factor: f32,
    clearcoat_roughness_texture: Option<json::texture::Info>,
    clearcoat_normal_texture: Option<json::material::NormalTexture>,
}

/// KHR_materials_sheen as the file holds it, with the extension's defaults.
#[derive(Deserialize, Default)]
#[serde(rename_all = "camelCase", default)]
struct SheenJson {
    sheen_color_factor: [f32; 3],
    sheen_color_texture: Option<json::texture::Info>,
    sheen_roughness_factor: f32,
    sheen_roughness_texture: Option<json::texture::Info>,
}

/// Extension `name` of material `index`, parsed from the raw JSON; a malformed one is an error
/// naming the material.
fn raw_extension<T: for<'de> Deserialize<'de>>(
    m: &json::Material,
    index: usize,
    name: &str,
) -> Result<Option<T>, String> {
    m.extensions
        .as_ref()
        .and_then(|e| e.others.get(name))
        .map(|v| {
            serde_json::from_value(v.clone())
                .map_err(|e| format!("materials[{index}].extensions.{name}: {e}"))
        })
        .transpose()
}

/// A glTF material as glint's, its colour texture's file, and whether it has other textures:
/// `pbrMetallicRoughness` (baseColorFactor, metallicFactor, roughnessFactor, with glTF's
/// defaults), KHR_materials_ior and KHR_materials_specular's factors,
/// KHR_materials_transmission (factor and texture) and KHR_materials_volume
/// (attenuationColor, attenuationDistance) → `pbr`; emissiveFactor ×
/// KHR_materials_emissive_strength → emission; alphaMode, alphaCutoff and baseColorFactor's
/// alpha → alpha; KHR_materials_clearcoat and KHR_materials_sheen (factors and textures) →
/// the pbr material's layers. Warning lines go to `warnings`.
pub(super) fn material(
    root: &json::Root,
    m: &json::Material,
    index: usize,
    warnings: &mut Vec<String>,
) -> Result<(Material, MaterialImages, bool), String> {
    let name = format!("material{index}");
    let extensions = m.extensions.as_ref();
    let ior = refractive_index(extensions, &name)?;
    let clearcoat: Option<ClearcoatJson> = raw_extension(m, index, "KHR_materials_clearcoat")?;
    let sheen: Option<SheenJson> = raw_extension(m, index, "KHR_materials_sheen")?;
    let kind = pbr_kind(m, &name, ior, clearcoat.as_ref(), sheen.as_ref())?;
    let color = check_reflectance(
        &name,
        "baseColorFactor",
        Vec3::from_slice(&m.pbr_metallic_roughness.base_color_factor.0[..3]),
    )?;
    let alpha = alpha(m, index)?;
    let emission = emission(m, &name)?;
    let maps = material_images(
        TextureRefs::new(root, index, warnings),
        m,
        clearcoat.as_ref(),
        sheen.as_ref(),
        emission,
    )?;
    // Occlusion maps are for rasterisers (a path tracer finds the occlusion), so they are
    // ignored without a word.
    let other_textures = has_specular_textures(extensions);
    if extensions.is_some_and(|e| e.unlit.is_some()) {
        let (material, maps) = unlit(name, color, alpha, maps);
        return Ok((material, maps, other_textures));
    }
    Ok((
        Material::untextured(name, kind, color, emission, alpha),
        maps,
        other_textures,
    ))
}

/// KHR_materials_ior's ior, checked. glTF's ior 0 (a Fresnel of 1 at every angle) is a special
/// case glint cannot render; its default is 1.5. Any other value passes the scene file's range
/// check.
fn refractive_index(extensions: Option<&MaterialExtensions>, name: &str) -> Result<f32, String> {
    match extensions.and_then(|e| e.ior.as_ref()).map(|i| i.ior.0) {
        None | Some(0.0) => Ok(1.5),
        Some(n) => check_ior(name, "KHR_materials_ior.ior", n),
    }
}

/// `v`, checked to lie in [0, 1]; `what` names it in the error.
fn unit(name: &str, what: &str, v: f32) -> Result<f32, String> {
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "material {name:?}: {what} must be in [0, 1], got {v}"
        ))
    }
}

/// The `pbr` kind of material `m` named `name`, of index of refraction `ior`: its factors and
/// those of the extensions on it, each checked (the first error found is the one reported, in
/// this order: specular colour, volume attenuation, the clearcoat and sheen layers, roughness,
/// metallic, specular, transmission).
fn pbr_kind(
    m: &json::Material,
    name: &str,
    ior: f32,
    clearcoat: Option<&ClearcoatJson>,
    sheen: Option<&SheenJson>,
) -> Result<MaterialKind, String> {
    let extensions = m.extensions.as_ref();
    let pbr = &m.pbr_metallic_roughness;
    let specular = extensions.and_then(|e| e.specular.as_ref());
    let transmission = extensions.and_then(|e| e.transmission.as_ref());
    let specular_color = specular_color(name, specular)?;
    let (attenuation_color, attenuation_distance) =
        volume_attenuation(name, extensions.and_then(|e| e.volume.as_ref()))?;
    let layers = pbr_layers(name, clearcoat, sheen)?;
    Ok(MaterialKind::Pbr {
        roughness: unit(name, "roughnessFactor", pbr.roughness_factor.0)?,
        metallic: unit(name, "metallicFactor", pbr.metallic_factor.0)?,
        ior,
        specular: unit(
            name,
            "KHR_materials_specular specularFactor",
            specular.map_or(1.0, |s| s.specular_factor.0),
        )?,
        specular_color,
        transmission: unit(
            name,
            "KHR_materials_transmission transmissionFactor",
            transmission.map_or(0.0, |t| t.transmission_factor.0),
        )?,
        transmission_texture: None,
        attenuation_color,
        attenuation_distance,
        layers,
    })
}

/// KHR_materials_specular's specularColorFactor (white without it), checked to be ≥ 0.
fn specular_color(
    name: &str,
    specular: Option<&json::extensions::material::Specular>,
) -> Result<Vec3, String> {
    let specular_color = Vec3::from(specular.map_or([1.0; 3], |s| s.specular_color_factor.0));
    if !specular_color.is_finite() || specular_color.min_element() < 0.0 {
        return Err(format!(
            "material {name:?}: KHR_materials_specular specularColorFactor must be ≥ 0, got \
             {specular_color}"
        ));
    }
    Ok(specular_color)
}

/// KHR_materials_volume's attenuationColor and attenuationDistance (`None`: no attenuation),
/// checked.
fn volume_attenuation(
    name: &str,
    volume: Option<&json::extensions::material::Volume>,
) -> Result<(Vec3, Option<f32>), String> {
    let attenuation_color = check_reflectance(
        name,
        "KHR_materials_volume attenuationColor",
        Vec3::from(volume.map_or([1.0; 3], |v| v.attenuation_color.0)),
    )?;
    // Absent is glTF's +∞: no attenuation. (JSON has no ∞, so any number given is finite.)
    let attenuation_distance = match volume.map(|v| v.attenuation_distance.0) {
        Some(d) if d.is_infinite() && d > 0.0 => None,
        Some(d) if d > 0.0 && d.is_finite() => Some(d),
        Some(d) => {
            return Err(format!(
                "material {name:?}: KHR_materials_volume attenuationDistance must be > 0, got {d}"
            ))
        }
        None => None,
    };
    Ok((attenuation_color, attenuation_distance))
}

/// The clearcoat and sheen layers' factors (KHR_materials_clearcoat, KHR_materials_sheen),
/// checked; their textures are read with the material's other images.
fn pbr_layers(
    name: &str,
    clearcoat: Option<&ClearcoatJson>,
    sheen: Option<&SheenJson>,
) -> Result<PbrLayers, String> {
    let mut layers = PbrLayers::default();
    if let Some(c) = clearcoat {
        layers.clearcoat = unit(
            name,
            "KHR_materials_clearcoat clearcoatFactor",
            c.clearcoat_factor,
        )?;
        layers.clearcoat_roughness = unit(
            name,
            "KHR_materials_clearcoat clearcoatRoughnessFactor",
            c.clearcoat_roughness_factor,
        )?;
    }
    if let Some(s) = sheen {
        let color = Vec3::from(s.sheen_color_factor);
        if !color.is_finite() || color.min_element() < 0.0 || color.max_element() > 1.0 {
            return Err(format!(
                "material {name:?}: KHR_materials_sheen sheenColorFactor must be in [0, 1], got \
                 {color}"
            ));
        }
        layers.sheen_color = color;
        layers.sheen_roughness = unit(
            name,
            "KHR_materials_sheen sheenRoughnessFactor",
            s.sheen_roughness_factor,
        )?;
    }
    Ok(layers)
}

/// emissiveFactor × KHR_materials_emissive_strength (1 without it), each checked.
fn emission(m: &json::Material, name: &str) -> Result<Vec3, String> {
    let strength = match m
        .extensions
        .as_ref()
        .and_then(|e| e.emissive_strength.as_ref())
    {
        Some(s) => {
            let s = s.emissive_strength.0;
            check_emission(name, "KHR_materials_emissive_strength", Vec3::splat(s))?;
            s
        }
        None => 1.0,
    };
    check_emission(
        name,
        "emissiveFactor × emissive strength",
        Vec3::from(m.emissive_factor.0) * strength,
    )
}

/// Whether KHR_materials_specular has textures (glint reads its factors only).
fn has_specular_textures(extensions: Option<&MaterialExtensions>) -> bool {
    extensions
        .and_then(|e| e.specular.as_ref())
        .is_some_and(|s| s.specular_texture.is_some() || s.specular_color_texture.is_some())
}

/// KHR_materials_unlit: the surface shows its base colour whatever lights it. A path tracer
/// has no unlit surface: it emits its base colour (× the colour texture) and reflects
/// nothing, so the camera sees the colour as authored, and what is near it gets that light
/// too, as from a lamp of that colour. `maps` are the images read for the lit material.
fn unlit(
    name: String,
    color: Vec3,
    alpha: Alpha,
    maps: MaterialImages,
) -> (Material, MaterialImages) {
    (
        Material::untextured(name, MaterialKind::Unlit, Vec3::ZERO, color, alpha),
        MaterialImages {
            // The colour texture stays for its alpha (× black, it adds no colour).
            emission: maps.color,
            color: maps.color,
            metallic_roughness: None,
            transmission: None,
            normal: None,
            clearcoat_normal: None,
            clearcoat: None,
            clearcoat_roughness: None,
            sheen_color: None,
            sheen_roughness: None,
        },
    )
}

/// The images of material `m`'s texture maps, read in this order (the first error found is
/// the one reported): the normal maps, then the colour, metallic-roughness, emission,
/// transmission, clearcoat and sheen textures. Textures that multiply nothing (no
/// emission, a layer whose factor is 0) are not read.
fn material_images(
    mut textures: TextureRefs,
    m: &json::Material,
    clearcoat: Option<&ClearcoatJson>,
    sheen: Option<&SheenJson>,
    emission: Vec3,
) -> Result<MaterialImages, String> {
    let pbr = &m.pbr_metallic_roughness;
    let transmission = m.extensions.as_ref().and_then(|e| e.transmission.as_ref());
    // Textures of a layer whose factor is 0 multiply nothing.
    let coat = clearcoat.filter(|c| c.clearcoat_factor > 0.0);
    let sheen = sheen.filter(|s| s.sheen_color_factor.iter().any(|&c| c > 0.0));
    let normal = match &m.normal_texture {
        Some(n) => textures.normal_image(n, "normalTexture")?,
        None => None,
    };
    // The coat's own normal map (without one the coat takes the unmapped normal).
    let clearcoat_normal = match coat.and_then(|c| c.clearcoat_normal_texture.as_ref()) {
        Some(n) => textures.normal_image(
            n,
            "extensions.KHR_materials_clearcoat.clearcoatNormalTexture",
        )?,
        None => None,
    };
    let maps = MaterialImages {
        color: textures.image(
            pbr.base_color_texture.as_ref(),
            "pbrMetallicRoughness.baseColorTexture",
        )?,
        metallic_roughness: textures.image(
            pbr.metallic_roughness_texture.as_ref(),
            "pbrMetallicRoughness.metallicRoughnessTexture",
        )?,
        // Without emission the texture multiplies nothing.
        emission: if emission == Vec3::ZERO {
            None
        } else {
            textures.image(m.emissive_texture.as_ref(), "emissiveTexture")?
        },
        transmission: match transmission {
            Some(t) => textures.image(
                t.transmission_texture.as_ref(),
                "extensions.KHR_materials_transmission.transmissionTexture",
            )?,
            None => None,
        },
        normal,
        clearcoat_normal,
        clearcoat: match coat {
            Some(c) => textures.image(
                c.clearcoat_texture.as_ref(),
                "extensions.KHR_materials_clearcoat.clearcoatTexture",
            )?,
            None => None,
        },
        clearcoat_roughness: match coat {
            Some(c) => textures.image(
                c.clearcoat_roughness_texture.as_ref(),
                "extensions.KHR_materials_clearcoat.clearcoatRoughnessTexture",
            )?,
            None => None,
        },
        sheen_color: match sheen {
            Some(s) => textures.image(
                s.sheen_color_texture.as_ref(),
                "extensions.KHR_materials_sheen.sheenColorTexture",
            )?,
            None => None,
        },
        sheen_roughness: match sheen {
            Some(s) => textures.image(
                s.sheen_roughness_texture.as_ref(),
                "extensions.KHR_materials_sheen.sheenRoughnessTexture",
            )?,
            None => None,
        },
    };
    textures.finish();
    Ok(maps)
}

/// glTF's alphaMode, alphaCutoff (default 0.5) and baseColorFactor's alpha (the opacity, which
/// the base colour texture's alpha multiplies), each checked: cutoff and opacity in [0, 1].
fn alpha(m: &json::Material, index: usize) -> Result<Alpha, String> {
    let field = |f: &str| format!("materials[{index}].{f}");
    let opacity = m.pbr_metallic_roughness.base_color_factor.0[3];
    if !(0.0..=1.0).contains(&opacity) {
        return Err(format!(
            "{}: its alpha (the fourth value) must be in [0, 1], got {opacity}",
            field("pbrMetallicRoughness.baseColorFactor")
        ));
    }
    let cutoff = m.alpha_cutoff.map_or(0.5, |c| c.0);
    if !(0.0..=1.0).contains(&cutoff) {
        return Err(format!(
            "{}: must be in [0, 1], got {cutoff}",
            field("alphaCutoff")
        ));
    }
    let mode = match m.alpha_mode {
        Checked::Valid(json::material::AlphaMode::Opaque) => AlphaMode::Opaque,
        Checked::Valid(json::material::AlphaMode::Mask) => AlphaMode::Mask { cutoff },
        Checked::Valid(json::material::AlphaMode::Blend) => AlphaMode::Blend,
        Checked::Invalid => {
            return Err(format!(
                "{}: not a glTF alpha mode (\"OPAQUE\", \"MASK\" or \"BLEND\")",
                field("alphaMode")
            ))
        }
    };
    Ok(Alpha { mode, opacity })
}

/// The images (indices into `images`) of a material's texture maps, and how each is sampled.
pub(super) struct MaterialImages {
    pub(super) color: Option<(usize, Sampling)>,
    pub(super) metallic_roughness: Option<(usize, Sampling)>,
    pub(super) emission: Option<(usize, Sampling)>,
    /// KHR_materials_transmission's transmissionTexture (R multiplies the factor).
    pub(super) transmission: Option<(usize, Sampling)>,
    /// The normal map and its scale.
    pub(super) normal: Option<NormalImage>,
    /// KHR_materials_clearcoat's clearcoatNormalTexture and its scale: the coat's own normal
    /// map.
    pub(super) clearcoat_normal: Option<NormalImage>,
    /// KHR_materials_clearcoat's clearcoatTexture (R multiplies the factor) and
    /// clearcoatRoughnessTexture (G multiplies the roughness).
    pub(super) clearcoat: Option<(usize, Sampling)>,
    pub(super) clearcoat_roughness: Option<(usize, Sampling)>,
    /// KHR_materials_sheen's sheenColorTexture (RGB, sRGB) and sheenRoughnessTexture (A).
    pub(super) sheen_color: Option<(usize, Sampling)>,
    pub(super) sheen_roughness: Option<(usize, Sampling)>,
}
