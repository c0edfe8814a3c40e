//! Textures as a material's fields write them: an image file or a checker for a colour or a
//! roughness, and normal maps.

use super::super::fields::{fail, vec3, FieldError};
use crate::scene::file::S;
use crate::scene::limits::MAX_NORMAL_SCALE;
use crate::scene::texture::{TextureSet, TextureUse};
use glam::Vec3;
use std::path::Path;

/// A texture table's optional `scale` (1 when absent), an integer or a float.
fn table_scale(x: &S<toml::Value>, table: &toml::Table, field: &str) -> Result<f64, FieldError> {
    match table.get("scale") {
        None => Ok(1.0),
        Some(toml::Value::Float(v)) => Ok(*v),
        Some(toml::Value::Integer(v)) => Ok(*v as f64),
        Some(other) => fail(
            x.span(),
            format!("{field}.scale"),
            format!("must be a number, got {other}"),
        ),
    }
}

/// `normal_map = "file.png"` or `{ file = "file.png", scale = s }` (relative to `folder`;
/// `scale` finite, default 1): a tangent-space normal map read as glTF's normalTexture
/// (linear, x and y times the scale); the coat's `clearcoat_normal_map` too. Returns its
/// index in `textures` and the scale.
pub(super) fn normal_map(
    x: &S<toml::Value>,
    field: &str,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<(u32, f32), FieldError> {
    let expected = "must be \"file.png\" or { file = \"file.png\", scale = s }";
    let (file, scale) = match x.get_ref() {
        toml::Value::String(file) => (file.as_str(), 1.0),
        toml::Value::Table(table) => normal_map_table(x, table, field, expected)?,
        other => return fail(x.span(), field, format!("{expected}, got {other}")),
    };
    let index = textures
        .image(&folder.join(file), TextureUse::Normal)
        .or_else(|message| fail(x.span(), field, format!("{file}: {message}")))?;
    Ok((index, scale as f32))
}

/// A normal map's `{ file = "file.png", scale = s }`: the file and the scale.
fn normal_map_table<'a>(
    x: &S<toml::Value>,
    table: &'a toml::Table,
    field: &str,
    expected: &str,
) -> Result<(&'a str, f64), FieldError> {
    if let Some(key) = table
        .keys()
        .find(|k| !matches!(k.as_str(), "file" | "scale"))
    {
        return fail(x.span(), field, format!("{expected}; unknown key: {key}"));
    }
    let Some(file) = table.get("file").and_then(|f| f.as_str()) else {
        return fail(
            x.span(),
            format!("{field}.file"),
            "missing: the normal map's image file (a string)",
        );
    };
    let scale = table_scale(x, table, field)?;
    // glTF's scale may be any finite number; within f32's range here.
    if !scale.is_finite() || scale.abs() > MAX_NORMAL_SCALE {
        return fail(
            x.span(),
            format!("{field}.scale"),
            format!("must be a number in [-1e6, 1e6], got {scale}"),
        );
    }
    Ok((file, scale))
}

/// A texture as written in a material field: `{ texture = "file" }` (relative to `folder`) or
/// `{ checker = [[r, g, b], [r, g, b]], scale = s }` (scale optional, default 1). Returns its
/// index in `textures`.
pub(super) fn texture(
    x: &S<toml::Value>,
    field: &str,
    folder: &Path,
    usage: TextureUse,
    textures: &mut TextureSet,
) -> Result<u32, FieldError> {
    let expected = "must be a constant, { texture = \"file.png\" } or { checker = [[r, g, b], [r, g, b]], scale = s }";
    let Some(table) = x.get_ref().as_table() else {
        return fail(x.span(), field, format!("{expected}, got {}", x.get_ref()));
    };
    let keys: Vec<&str> = table.keys().map(|k| k.as_str()).collect();
    match keys.as_slice() {
        ["texture"] => {
            let Some(file) = table["texture"].as_str() else {
                return fail(x.span(), field, "texture must be a file name (a string)");
            };
            textures
                .image(&folder.join(file), usage)
                .or_else(|message| fail(x.span(), field, format!("{file}: {message}")))
        }
        ["checker"] | ["checker", "scale"] | ["scale", "checker"] => {
            checker(x, table, field, textures)
        }
        _ => fail(
            x.span(),
            field,
            format!("{expected}; unknown keys: {}", keys.join(", ")),
        ),
    }
}

/// `{ checker = [[r, g, b], [r, g, b]], scale = s }`: two colours in [0, 1] and a scale in
/// (0, 1e6] squares per unit of u and v.
fn checker(
    x: &S<toml::Value>,
    table: &toml::Table,
    field: &str,
    textures: &mut TextureSet,
) -> Result<u32, FieldError> {
    let colors = match table["checker"].as_array() {
        Some(c) if c.len() == 2 => c,
        _ => {
            return fail(
                x.span(),
                field,
                "checker must be two colors [[r, g, b], [r, g, b]]",
            )
        }
    };
    let mut pair = [Vec3::ZERO; 2];
    for (out, c) in pair.iter_mut().zip(colors) {
        let color = vec3(&S::new(x.span(), c.clone()), &format!("{field}.checker"))?;
        if color.min_element() < 0.0 || color.max_element() > 1.0 {
            return fail(
                x.span(),
                format!("{field}.checker"),
                format!("every value must be in [0, 1], got {color}"),
            );
        }
        *out = color;
    }
    let scale = table_scale(x, table, field)?;
    if !(scale > 0.0 && scale <= 1e6) {
        return fail(
            x.span(),
            format!("{field}.scale"),
            format!("must be in (0, 1e6] squares per unit of u and v, got {scale}"),
        );
    }
    Ok(textures.checker(pair, scale as f32))
}
