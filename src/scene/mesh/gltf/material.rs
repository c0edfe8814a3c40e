//! A glTF material as glint's: the metallic-roughness material and the extensions glint
//! reads onto it, its alpha, and which images its texture maps sample, each value checked
//! (the geometry is read in `primitives.rs`).

use super::document::exists;
use crate::kernel::types::{TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_MIRROR, TEXTURE_WRAP_REPEAT};
use crate::scene::mesh::{check_emission, check_ior, check_normal_scale, check_reflectance};
use crate::scene::texture::Sampling;
use crate::scene::{Alpha, AlphaMode, Material, MaterialKind, PbrLayers};
use glam::Vec3;
use gltf::json;
use json::texture::{MagFilter, WrappingMode};
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
    let pbr = &m.pbr_metallic_roughness;
    let transmission = extensions.and_then(|e| e.transmission.as_ref());
    let volume = extensions.and_then(|e| e.volume.as_ref());
    // glTF's ior 0 (a Fresnel of 1 at every angle) is a special case glint cannot render;
    // its default is 1.5. Any other value passes the scene file's range check.
    let ior = match extensions.and_then(|e| e.ior.as_ref()).map(|i| i.ior.0) {
        None | Some(0.0) => 1.5,
        Some(n) => check_ior(&name, "KHR_materials_ior.ior", n)?,
    };
    let clearcoat: Option<ClearcoatJson> = raw_extension(m, index, "KHR_materials_clearcoat")?;
    let sheen: Option<SheenJson> = raw_extension(m, index, "KHR_materials_sheen")?;
    let kind = {
        let unit = |what: &str, v: f32| {
            if (0.0..=1.0).contains(&v) {
                Ok(v)
            } else {
                Err(format!(
                    "material {name:?}: {what} must be in [0, 1], got {v}"
                ))
            }
        };
        let specular = extensions.and_then(|e| e.specular.as_ref());
        let specular_color = Vec3::from(specular.map_or([1.0; 3], |s| s.specular_color_factor.0));
        if !specular_color.is_finite() || specular_color.min_element() < 0.0 {
            return Err(format!(
                "material {name:?}: KHR_materials_specular specularColorFactor must be ≥ 0, got \
                 {specular_color}"
            ));
        }
        let attenuation_color = check_reflectance(
            &name,
            "KHR_materials_volume attenuationColor",
            Vec3::from(volume.map_or([1.0; 3], |v| v.attenuation_color.0)),
        )?;
        // Absent is glTF's +∞: no attenuation. (JSON has no ∞, so any number given is finite.)
        let attenuation_distance = match volume.map(|v| v.attenuation_distance.0) {
            Some(d) if d.is_infinite() && d > 0.0 => None,
            Some(d) if d > 0.0 && d.is_finite() => Some(d),
            Some(d) => {
                return Err(format!(
                    "material {name:?}: KHR_materials_volume attenuationDistance must be > 0, got \
                     {d}"
                ))
            }
            None => None,
        };
        let mut layers = PbrLayers::default();
        if let Some(c) = &clearcoat {
            layers.clearcoat = unit(
                "KHR_materials_clearcoat clearcoatFactor",
                c.clearcoat_factor,
            )?;
            layers.clearcoat_roughness = unit(
                "KHR_materials_clearcoat clearcoatRoughnessFactor",
                c.clearcoat_roughness_factor,
            )?;
        }
        if let Some(s) = &sheen {
            let color = Vec3::from(s.sheen_color_factor);
            if !color.is_finite() || color.min_element() < 0.0 || color.max_element() > 1.0 {
                return Err(format!(
                    "material {name:?}: KHR_materials_sheen sheenColorFactor must be in [0, 1], \
                     got {color}"
                ));
            }
            layers.sheen_color = color;
            layers.sheen_roughness = unit(
                "KHR_materials_sheen sheenRoughnessFactor",
                s.sheen_roughness_factor,
            )?;
        }
        MaterialKind::Pbr {
            roughness: unit("roughnessFactor", pbr.roughness_factor.0)?,
            metallic: unit("metallicFactor", pbr.metallic_factor.0)?,
            ior,
            specular: unit(
                "KHR_materials_specular specularFactor",
                specular.map_or(1.0, |s| s.specular_factor.0),
            )?,
            specular_color,
            transmission: unit(
                "KHR_materials_transmission transmissionFactor",
                transmission.map_or(0.0, |t| t.transmission_factor.0),
            )?,
            transmission_texture: None,
            attenuation_color,
            attenuation_distance,
            layers,
        }
    };
    let color = check_reflectance(
        &name,
        "baseColorFactor",
        Vec3::from_slice(&pbr.base_color_factor.0[..3]),
    )?;
    let alpha = alpha(m, index)?;
    let strength = match extensions.and_then(|e| e.emissive_strength.as_ref()) {
        Some(s) => {
            let s = s.emissive_strength.0;
            check_emission(&name, "KHR_materials_emissive_strength", Vec3::splat(s))?;
            s
        }
        None => 1.0,
    };
    let emission = check_emission(
        &name,
        "emissiveFactor × emissive strength",
        Vec3::from(m.emissive_factor.0) * strength,
    )?;
    // Occlusion maps are for rasterisers (a path tracer finds the occlusion), so they are
    // ignored without a word.
    let mut other_textures = false;
    // Pushed once `image` (which warns too) is done with `warnings`.
    let mut normal_map_warnings = Vec::new();
    let mut image = |info: &Option<json::texture::Info>, field: &str| {
        let Some(info) = info else {
            return Ok(None);
        };
        let field = format!("materials[{index}].{field}");
        let t = exists(info.index.value(), root.textures.len(), "texture")
            .map_err(|e| format!("{field}.index: {e}"))?;
        let transform = info
            .extensions
            .as_ref()
            .and_then(|e| e.texture_transform.as_ref());
        // KHR_texture_transform's texCoord overrides the reference's.
        let tex_coord = transform
            .and_then(|t| t.tex_coord)
            .unwrap_or(info.tex_coord);
        if tex_coord > 1 {
            warnings.push(format!(
                "{field}: on TEXCOORD_{tex_coord}; glint reads TEXCOORD_0 and TEXCOORD_1 only, \
                 so the texture is ignored"
            ));
            return Ok(None);
        }
        let mut sampling = Sampling {
            uv_set: tex_coord,
            ..Sampling::default()
        };
        if let Some(s) = root.textures[t].sampler {
            let s = exists(s.value(), root.samplers.len(), "sampler")
                .map_err(|e| format!("textures[{t}].sampler: {e}"))?;
            let sampler = &root.samplers[s];
            for (axis, (mode, name)) in [(sampler.wrap_s, "wrapS"), (sampler.wrap_t, "wrapT")]
                .into_iter()
                .enumerate()
            {
                sampling.wrap[axis] = match mode {
                    Checked::Valid(WrappingMode::Repeat) => TEXTURE_WRAP_REPEAT,
                    Checked::Valid(WrappingMode::ClampToEdge) => TEXTURE_WRAP_CLAMP,
                    Checked::Valid(WrappingMode::MirroredRepeat) => TEXTURE_WRAP_MIRROR,
                    Checked::Invalid => {
                        return Err(format!("samplers[{s}].{name}: not a glTF wrap mode"))
                    }
                };
            }
            // Without mipmaps, the magnification filter decides.
            sampling.nearest = sampler.mag_filter == Some(Checked::Valid(MagFilter::Nearest));
        }
        if let Some(t) = transform {
            let [ox, oy] = t.offset.0;
            let [sx, sy] = t.scale.0;
            let (sin, cos) = t.rotation.0.sin_cos();
            // glTF's uv' = T R S uv, R rotating the UVs counterclockwise as the extension's text
            // says, drawn with glTF's v down: u' = cos sx u + sin sy v + ox, v' = −sin sx u +
            // cos sy v + oy. (The GLSL snippet in the extension's README has the opposite sign;
            // Khronos' TextureTransformTest, whose markers say which way is right, and three.js
            // follow the text.) Here in glint's coordinates, whose v is 1 − glTF's.
            sampling.transform = [
                [cos * sx, -sin * sy, ox + sin * sy],
                [sin * sx, cos * sy, 1.0 - cos * sy - oy],
            ];
            if !sampling.transform.iter().flatten().all(|c| c.is_finite()) {
                return Err(format!(
                    "{field}.extensions.KHR_texture_transform: not finite"
                ));
            }
        }
        Ok::<_, String>(Some((root.textures[t].source.value(), sampling)))
    };
    // A normal map (normalTexture, or the coat's clearcoatNormalTexture at `path`) and its
    // scale.
    let mut normal_image =
        |n: &json::material::NormalTexture, path: &str| -> Result<Option<NormalImage>, String> {
            let field = format!("materials[{index}].{path}");
            check_normal_scale(
                &format!("material{index}"),
                &format!("{field}.scale"),
                n.scale,
            )?;
            // The crate keeps a normal texture's extensions unparsed.
            let transform = n
                .extensions
                .as_ref()
                .and_then(|e| e.others.get("KHR_texture_transform"))
                .map(|v| {
                    serde_json::from_value(v.clone())
                        .map_err(|e| format!("{field}.extensions.KHR_texture_transform: {e}"))
                })
                .transpose()?;
            let info = json::texture::Info {
                index: n.index,
                tex_coord: n.tex_coord,
                extensions: Some(json::extensions::texture::Info {
                    texture_transform: transform,
                    others: Default::default(),
                }),
                extras: Default::default(),
            };
            Ok(match image(&Some(info), path)? {
                // Tangents (the file's or MikkTSpace's) follow TEXCOORD_0.
                Some((_, sampling)) if sampling.uv_set != 0 => {
                    normal_map_warnings.push(format!(
                    "{field}: on TEXCOORD_1; glint reads normal maps on TEXCOORD_0 only, so the \
                     texture is ignored"
                ));
                    None
                }
                i => i.map(|i| (i, n.scale)),
            })
        };
    let normal = match &m.normal_texture {
        Some(n) => normal_image(n, "normalTexture")?,
        None => None,
    };
    // The coat's own normal map (without one the coat takes the unmapped normal).
    let clearcoat_normal = match &clearcoat {
        Some(c) if c.clearcoat_factor > 0.0 => match &c.clearcoat_normal_texture {
            Some(n) => normal_image(
                n,
                "extensions.KHR_materials_clearcoat.clearcoatNormalTexture",
            )?,
            None => None,
        },
        _ => None,
    };
    let maps = MaterialImages {
        color: image(
            &pbr.base_color_texture,
            "pbrMetallicRoughness.baseColorTexture",
        )?,
        metallic_roughness: image(
            &pbr.metallic_roughness_texture,
            "pbrMetallicRoughness.metallicRoughnessTexture",
        )?,
        // Without emission the texture multiplies nothing.
        emission: if emission == Vec3::ZERO {
            None
        } else {
            image(&m.emissive_texture, "emissiveTexture")?
        },
        transmission: match transmission {
            Some(t) => image(
                &t.transmission_texture,
                "extensions.KHR_materials_transmission.transmissionTexture",
            )?,
            None => None,
        },
        normal,
        clearcoat_normal,
        // Textures of a layer whose factor is 0 multiply nothing.
        clearcoat: match &clearcoat {
            Some(c) if c.clearcoat_factor > 0.0 => image(
                &c.clearcoat_texture,
                "extensions.KHR_materials_clearcoat.clearcoatTexture",
            )?,
            _ => None,
        },
        clearcoat_roughness: match &clearcoat {
            Some(c) if c.clearcoat_factor > 0.0 => image(
                &c.clearcoat_roughness_texture,
                "extensions.KHR_materials_clearcoat.clearcoatRoughnessTexture",
            )?,
            _ => None,
        },
        sheen_color: match &sheen {
            Some(s) if s.sheen_color_factor.iter().any(|&c| c > 0.0) => image(
                &s.sheen_color_texture,
                "extensions.KHR_materials_sheen.sheenColorTexture",
            )?,
            _ => None,
        },
        sheen_roughness: match &sheen {
            Some(s) if s.sheen_color_factor.iter().any(|&c| c > 0.0) => image(
                &s.sheen_roughness_texture,
                "extensions.KHR_materials_sheen.sheenRoughnessTexture",
            )?,
            _ => None,
        },
    };
    warnings.extend(normal_map_warnings);
    if let Some(specular) = extensions.and_then(|e| e.specular.as_ref()) {
        other_textures |=
            specular.specular_texture.is_some() || specular.specular_color_texture.is_some();
    }
    // KHR_materials_unlit: the surface shows its base colour whatever lights it. A path tracer
    // has no unlit surface: it emits its base colour (× the colour texture) and reflects
    // nothing, so the camera sees the colour as authored, and what is near it gets that light
    // too, as from a lamp of that colour.
    if extensions.is_some_and(|e| e.unlit.is_some()) {
        return Ok((
            Material {
                name,
                kind: MaterialKind::Unlit,
                color: Vec3::ZERO,
                emitted_radiance: color,
                color_texture: None,
                roughness_texture: None,
                emission_texture: None,
                normal_texture: None,
                alpha,
            },
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
            other_textures,
        ));
    }
    Ok((
        Material {
            name,
            kind,
            color,
            emitted_radiance: emission,
            color_texture: None,
            roughness_texture: None,
            emission_texture: None,
            normal_texture: None,
            alpha,
        },
        maps,
        other_textures,
    ))
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

/// A normal map's image (an index into `images`), how it is sampled, and its scale.
pub(super) type NormalImage = ((usize, Sampling), f32);

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
