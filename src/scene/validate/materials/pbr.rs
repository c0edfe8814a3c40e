//! A `pbr` material's parameters (glTF's metallic-roughness material with its transmission,
//! volume, clearcoat and sheen extensions). The fields are checked, and their textures added,
//! in a fixed order: the base roughness, the specular colour, attenuation, the coat and sheen
//! layers, then metallic, ior, specular and transmission.

use super::super::fields::{fail, non_negative, real, FieldError};
use super::maps::{normal_map, texture};
use super::{ior_in_range, reflectance, unit_interval};
use crate::scene::file::{MaterialToml, Real, RoughnessToml, S};
use crate::scene::texture::{TextureSet, TextureUse};
use crate::scene::{MaterialKind, PbrLayers};
use glam::Vec3;
use std::path::Path;

/// A `pbr` material's parameters and layers, its textures added to `textures`.
pub(super) fn pbr_kind(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<MaterialKind, FieldError> {
    let roughness = base_roughness(m, field)?;
    let specular_color = match &m.specular_color {
        Some(c) => non_negative(c, &field("specular_color"))?,
        None => Vec3::ONE,
    };
    let attenuation_color = attenuation_color(m, field)?;
    let attenuation_distance = attenuation_distance(m, field)?;
    let layers = layers(m, field, folder, textures)?;
    Ok(MaterialKind::Pbr {
        roughness,
        metallic: unit(&m.metallic, "metallic", 0.0, field)?,
        ior: m.ior.as_ref().map_or(Ok(1.5), |x| ior_in_range(x, field))?,
        specular: unit(&m.specular, "specular", 1.0, field)?,
        specular_color,
        transmission: unit(&m.transmission, "transmission", 0.0, field)?,
        transmission_texture: None,
        attenuation_color,
        attenuation_distance,
        layers,
    })
}

/// The base layer's `roughness`: a constant in [0, 1] (default 0.5) or a texture, read with
/// the material's other textures (the constant is then unused).
fn base_roughness(m: &MaterialToml, field: &dyn Fn(&str) -> String) -> Result<f32, FieldError> {
    match m.roughness.as_ref().map(|r| (r.span(), r.get_ref())) {
        Some((span, RoughnessToml::Value(v))) => {
            unit_interval(&S::new(span, *v), &field("roughness"))
        }
        // A texture (read below); the constant is unused.
        Some((_, RoughnessToml::Other(_))) => Ok(1.0),
        None => Ok(0.5),
    }
}

/// A number in [0, 1], or `default` when absent.
fn unit(
    x: &Option<S<Real>>,
    name: &str,
    default: f32,
    field: &dyn Fn(&str) -> String,
) -> Result<f32, FieldError> {
    let Some(x) = x else {
        return Ok(default);
    };
    unit_interval(x, &field(name))
}

/// `attenuation_color`: the fraction of the light that remains after `attenuation_distance`,
/// each channel in [0, 1] (default 1).
fn attenuation_color(m: &MaterialToml, field: &dyn Fn(&str) -> String) -> Result<Vec3, FieldError> {
    let Some(c) = &m.attenuation_color else {
        return Ok(Vec3::ONE);
    };
    let color = non_negative(c, &field("attenuation_color"))?;
    if color.max_element() > 1.0 {
        return fail(
            c.span(),
            field("attenuation_color"),
            format!("must be in [0, 1] (a fraction of the light that remains), got {color}"),
        );
    }
    Ok(color)
}

/// `attenuation_distance`: > 0, or absent for no attenuation.
fn attenuation_distance(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
) -> Result<Option<f32>, FieldError> {
    let Some(d) = &m.attenuation_distance else {
        return Ok(None);
    };
    let v = real(d, &field("attenuation_distance"))?;
    if v <= 0.0 {
        return fail(
            d.span(),
            field("attenuation_distance"),
            format!("must be > 0 (leave it out for no attenuation), got {v}"),
        );
    }
    Ok(Some(v))
}

/// The clearcoat and sheen layers: the coat's strength and roughness, the sheen's roughness
/// and colour, then the coat's normal map.
fn layers(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<PbrLayers, FieldError> {
    let mut scalar = |x: &Option<S<RoughnessToml>>, name: &str, default: f32| {
        scalar_or_texture(x, &field(name), default, folder, textures)
    };
    let (clearcoat, clearcoat_texture) = scalar(&m.clearcoat, "clearcoat", 0.0)?;
    let (clearcoat_roughness, clearcoat_roughness_texture) =
        scalar(&m.clearcoat_roughness, "clearcoat_roughness", 0.0)?;
    let (sheen_roughness, sheen_roughness_texture) =
        scalar(&m.sheen_roughness, "sheen_roughness", 0.0)?;
    let (sheen_color, sheen_color_texture) = sheen_color(m, field, folder, textures)?;
    let has_coat = clearcoat != 0.0 || clearcoat_texture.is_some();
    let clearcoat_normal_texture = clearcoat_normal_map(m, has_coat, field, folder, textures)?;
    Ok(PbrLayers {
        clearcoat,
        clearcoat_roughness,
        clearcoat_texture,
        clearcoat_roughness_texture,
        clearcoat_normal_texture,
        sheen_color,
        sheen_roughness,
        sheen_color_texture,
        sheen_roughness_texture,
    })
}

/// A constant in [0, 1] (`default` when absent), or a texture whose first channel is the
/// value (the constant is then 1).
fn scalar_or_texture(
    x: &Option<S<RoughnessToml>>,
    field: &str,
    default: f32,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<(f32, Option<u32>), FieldError> {
    match x.as_ref().map(|r| (r.span(), r.get_ref())) {
        Some((span, RoughnessToml::Value(v))) => {
            Ok((unit_interval(&S::new(span, *v), field)?, None))
        }
        Some((span, RoughnessToml::Other(value))) => Ok((
            1.0,
            Some(texture(
                &S::new(span, value.clone()),
                field,
                folder,
                TextureUse::Roughness,
                textures,
            )?),
        )),
        None => Ok((default, None)),
    }
}

/// `sheen_color`: a reflectance (default 0, no sheen) or a colour texture (the constant is
/// then 1).
fn sheen_color(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<(Vec3, Option<u32>), FieldError> {
    match &m.sheen_color {
        Some(c) if c.get_ref().is_table() => Ok((
            Vec3::ONE,
            Some(texture(
                c,
                &field("sheen_color"),
                folder,
                TextureUse::Color,
                textures,
            )?),
        )),
        Some(c) => Ok((reflectance(c, &field("sheen_color"))?, None)),
        None => Ok((Vec3::ZERO, None)),
    }
}

/// `clearcoat_normal_map`, only where the material has a coat (`has_coat`): a coat's normal
/// map without a coat would map nothing, most likely a mistake.
fn clearcoat_normal_map(
    m: &MaterialToml,
    has_coat: bool,
    field: &dyn Fn(&str) -> String,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<Option<(u32, f32)>, FieldError> {
    let Some(n) = &m.clearcoat_normal_map else {
        return Ok(None);
    };
    if !has_coat {
        return fail(
            n.span(),
            field("clearcoat_normal_map"),
            "the material has no coat to map: give it clearcoat > 0",
        );
    }
    normal_map(n, &field("clearcoat_normal_map"), folder, textures).map(Some)
}
