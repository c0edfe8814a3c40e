//! `[materials.NAME]`: each material's kind, colour, emission and textures, and references to
//! materials by name.

use super::super::file::{MaterialToml, Real, RoughnessToml, S};
use super::super::limits::{MAX_IOR, MAX_NORMAL_SCALE, MIN_IOR};
use super::super::texture::{TextureSet, TextureUse};
use super::super::{Alpha, AlphaMode, Material, MaterialKind, PbrLayers};
use super::fields::{fail, non_negative, radiance_in_range, real, vec3, FieldError};
use glam::Vec3;
use std::collections::BTreeMap;
use std::path::Path;

/// The scene's materials (mesh files add their own), the textures they use, and their indices
/// by name.
pub(super) struct Materials {
    pub(super) list: Vec<Material>,
    pub(super) textures: TextureSet,
    index_of: BTreeMap<String, u32>,
}

impl Materials {
    /// The index of the material `m` names; an unknown name fails at `field`.
    pub(super) fn reference(&self, m: &S<String>, field: String) -> Result<u32, FieldError> {
        self.index_of.get(m.get_ref()).copied().ok_or_else(|| {
            let known: Vec<_> = self.index_of.keys().map(|k| format!("{k:?}")).collect();
            FieldError {
                span: Some(m.span()),
                field,
                message: format!(
                    "unknown material {:?}; defined materials: {}",
                    m.get_ref(),
                    if known.is_empty() {
                        "none".into()
                    } else {
                        known.join(", ")
                    }
                ),
            }
        })
    }
}

/// The `[materials]` tables, with textures read relative to `folder`.
pub(super) fn validate_materials(
    toml: &BTreeMap<String, S<MaterialToml>>,
    folder: &Path,
) -> Result<Materials, FieldError> {
    let mut materials = Vec::new();
    let mut textures = TextureSet::default();
    let mut index_of = BTreeMap::new();
    for (name, m) in toml {
        index_of.insert(name.clone(), materials.len() as u32);
        materials.push(validate_material(name, m.get_ref(), folder, &mut textures)?);
    }
    Ok(Materials {
        list: materials,
        textures,
        index_of,
    })
}

/// `[materials.NAME]`, its textures added to `textures`. The checks run in the order the
/// fields' errors are reported: the kind and its parameters, fields that do not apply to it,
/// the colour, the emission, alpha and the normal map.
fn validate_material(
    name: &str,
    m: &MaterialToml,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<Material, FieldError> {
    let field = &|f: &str| format!("materials.{name}.{f}");
    let kind = match m.kind.get_ref().as_str() {
        "diffuse" => MaterialKind::Diffuse,
        "specular" => MaterialKind::Specular,
        "metal" => {
            let Some(r) = &m.roughness else {
                return fail(
                    m.kind.span(),
                    field("roughness"),
                    "missing: a metal needs roughness",
                );
            };
            let roughness = match r.get_ref() {
                RoughnessToml::Value(v) => {
                    real(&S::new(r.span(), *v), &field("roughness"))?
                }
                // A texture (read below); the constant is unused.
                RoughnessToml::Other(_) => 1.0,
            };
            if !(0.0..=1.0).contains(&roughness) {
                return fail(
                    r.span(),
                    field("roughness"),
                    format!("must be in [0, 1] (0 = mirror), got {roughness}"),
                );
            }
            MaterialKind::Metal { roughness }
        }
        "dielectric" => {
            let ior = positive(m, &m.ior, "ior", "dielectric", field)?;
            if !(MIN_IOR..=MAX_IOR).contains(&ior) {
                return fail(
                    m.ior.as_ref().unwrap().span(),
                    field("ior"),
                    format!(
                        "the index of refraction must be in [{MIN_IOR}, {MAX_IOR}] (the \
                         numeric range glint supports), got {ior}"
                    ),
                );
            }
            MaterialKind::Dielectric { ior }
        }
        "pbr" => pbr_kind(m, field, folder, textures)?,
        other => {
            return fail(
                m.kind.span(),
                field("type"),
                format!(
                    "unknown material type {other:?}; known types: \"diffuse\", \"specular\", \"metal\", \"dielectric\", \"pbr\""
                ),
            )
        }
    };
    let pbr = matches!(kind, MaterialKind::Pbr { .. });
    check_fields_apply(m, &kind, field)?;
    let roughness_texture = match &m.roughness {
        Some(r) => match r.get_ref() {
            RoughnessToml::Other(value) => Some(texture(
                &S::new(r.span(), value.clone()),
                &field("roughness"),
                folder,
                TextureUse::Roughness,
                textures,
            )?),
            RoughnessToml::Value(_) => None,
        },
        None => None,
    };
    // A pbr material's colour is its base_color.
    let (color_field, color_name) = if pbr {
        (&m.base_color, "base_color")
    } else {
        (&m.color, "color")
    };
    let color_texture = match color_field {
        Some(c) if c.get_ref().is_table() => Some(texture(
            c,
            &field(color_name),
            folder,
            TextureUse::Color,
            textures,
        )?),
        _ => None,
    };
    let color = match (color_field, kind) {
        // Textured: the constant is unused.
        (Some(_), _) if color_texture.is_some() => Vec3::ONE,
        (Some(c), _) => {
            let color = non_negative(c, &field(color_name))?;
            if color.max_element() > 1.0 {
                return fail(
                    c.span(),
                    field(color_name),
                    format!(
                        "a reflectance must be in [0, 1] (more would create energy), got {color}"
                    ),
                );
            }
            color
        }
        // Clear glass unless tinted.
        (None, MaterialKind::Dielectric { .. }) => Vec3::ONE,
        (None, _) => {
            return fail(
                m.kind.span(),
                field(color_name),
                format!("missing: this material needs a {color_name}"),
            );
        }
    };
    let emission = match &m.emission {
        Some(e) if e.get_ref().is_table() => {
            return fail(
                e.span(),
                field("emission"),
                "takes no texture: only color (and a metal's roughness) may be textured",
            )
        }
        Some(e) => non_negative(e, &field("emission"))?,
        None => Vec3::ZERO,
    };
    let strength = match &m.strength {
        Some(s) => {
            let v = real(s, &field("strength"))?;
            if v < 0.0 {
                return fail(s.span(), field("strength"), format!("must be ≥ 0, got {v}"));
            }
            v
        }
        None => 1.0,
    };
    // Each factor may be in range and the product not (1e30 × 1e30): check the product,
    // in f64, where it is exact enough and cannot overflow.
    if let Some(e) = &m.emission {
        let span = m.strength.as_ref().map_or(e.span(), |s| s.span());
        radiance_in_range(
            span,
            &field("emission × strength"),
            emission.as_dvec3() * strength as f64,
        )?;
    }
    let alpha = alpha(m, field)?;
    let normal_texture = m
        .normal_map
        .as_ref()
        .map(|n| normal_map(n, &field("normal_map"), folder, textures))
        .transpose()?;
    Ok(Material {
        name: name.to_string(),
        kind,
        color,
        emitted_radiance: emission * strength,
        color_texture,
        roughness_texture,
        emission_texture: None,
        normal_texture,
        alpha,
    })
}

/// A value that must be given for this kind of material.
fn positive(
    m: &MaterialToml,
    x: &Option<S<Real>>,
    name: &str,
    what: &str,
    field: &dyn Fn(&str) -> String,
) -> Result<f32, FieldError> {
    let Some(x) = x else {
        return fail(
            m.kind.span(),
            field(name),
            format!("missing: a {what} needs {name}"),
        );
    };
    real(x, &field(name))
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
    let v = real(x, &field(name))?;
    if !(0.0..=1.0).contains(&v) {
        return fail(x.span(), field(name), format!("must be in [0, 1], got {v}"));
    }
    Ok(v)
}

/// A `pbr` material's parameters and layers, its textures added to `textures`.
fn pbr_kind(
    m: &MaterialToml,
    field: &dyn Fn(&str) -> String,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<MaterialKind, FieldError> {
    let ior_in_range = |x: &S<Real>| -> Result<f32, FieldError> {
        let ior = real(x, &field("ior"))?;
        if !(MIN_IOR..=MAX_IOR).contains(&ior) {
            return fail(
                x.span(),
                field("ior"),
                format!(
                    "the index of refraction must be in [{MIN_IOR}, {MAX_IOR}] (the \
                     numeric range glint supports), got {ior}"
                ),
            );
        }
        Ok(ior)
    };
    let roughness = match m.roughness.as_ref().map(|r| (r.span(), r.get_ref())) {
        Some((span, RoughnessToml::Value(v))) => {
            let v = real(&S::new(span.clone(), *v), &field("roughness"))?;
            if !(0.0..=1.0).contains(&v) {
                return fail(
                    span,
                    field("roughness"),
                    format!("must be in [0, 1], got {v}"),
                );
            }
            v
        }
        // A texture (read below); the constant is unused.
        Some((_, RoughnessToml::Other(_))) => 1.0,
        None => 0.5,
    };
    let specular_color = match &m.specular_color {
        Some(c) => non_negative(c, &field("specular_color"))?,
        None => Vec3::ONE,
    };
    let attenuation_color = match &m.attenuation_color {
        Some(c) => {
            let color = non_negative(c, &field("attenuation_color"))?;
            if color.max_element() > 1.0 {
                return fail(
                    c.span(),
                    field("attenuation_color"),
                    format!(
                        "must be in [0, 1] (a fraction of the light that remains), got {color}"
                    ),
                );
            }
            color
        }
        None => Vec3::ONE,
    };
    let attenuation_distance = match &m.attenuation_distance {
        Some(d) => {
            let v = real(d, &field("attenuation_distance"))?;
            if v <= 0.0 {
                return fail(
                    d.span(),
                    field("attenuation_distance"),
                    format!("must be > 0 (leave it out for no attenuation), got {v}"),
                );
            }
            Some(v)
        }
        None => None,
    };
    // A constant in [0, 1], or a texture whose first channel is the value.
    let mut scalar = |x: &Option<S<RoughnessToml>>,
                      name: &str,
                      default: f32|
     -> Result<(f32, Option<u32>), FieldError> {
        match x.as_ref().map(|r| (r.span(), r.get_ref())) {
            Some((span, RoughnessToml::Value(v))) => {
                let v = real(&S::new(span.clone(), *v), &field(name))?;
                if !(0.0..=1.0).contains(&v) {
                    return fail(span, field(name), format!("must be in [0, 1], got {v}"));
                }
                Ok((v, None))
            }
            Some((span, RoughnessToml::Other(value))) => Ok((
                1.0,
                Some(texture(
                    &S::new(span, value.clone()),
                    &field(name),
                    folder,
                    TextureUse::Roughness,
                    textures,
                )?),
            )),
            None => Ok((default, None)),
        }
    };
    let (clearcoat, clearcoat_texture) = scalar(&m.clearcoat, "clearcoat", 0.0)?;
    let (clearcoat_roughness, clearcoat_roughness_texture) =
        scalar(&m.clearcoat_roughness, "clearcoat_roughness", 0.0)?;
    let (sheen_roughness, sheen_roughness_texture) =
        scalar(&m.sheen_roughness, "sheen_roughness", 0.0)?;
    let (sheen_color, sheen_color_texture) = match &m.sheen_color {
        Some(c) if c.get_ref().is_table() => (
            Vec3::ONE,
            Some(texture(
                c,
                &field("sheen_color"),
                folder,
                TextureUse::Color,
                textures,
            )?),
        ),
        Some(c) => {
            let color = non_negative(c, &field("sheen_color"))?;
            if color.max_element() > 1.0 {
                return fail(
                    c.span(),
                    field("sheen_color"),
                    format!(
                        "a reflectance must be in [0, 1] (more would create energy), got {color}"
                    ),
                );
            }
            (color, None)
        }
        None => (Vec3::ZERO, None),
    };
    // A coat's normal map without a coat would map nothing: most likely a mistake.
    if let Some(n) = &m.clearcoat_normal_map {
        if clearcoat == 0.0 && clearcoat_texture.is_none() {
            return fail(
                n.span(),
                field("clearcoat_normal_map"),
                "the material has no coat to map: give it clearcoat > 0",
            );
        }
    }
    let clearcoat_normal_texture = m
        .clearcoat_normal_map
        .as_ref()
        .map(|n| normal_map(n, &field("clearcoat_normal_map"), folder, textures))
        .transpose()?;
    let layers = PbrLayers {
        clearcoat,
        clearcoat_roughness,
        clearcoat_texture,
        clearcoat_roughness_texture,
        clearcoat_normal_texture,
        sheen_color,
        sheen_roughness,
        sheen_color_texture,
        sheen_roughness_texture,
    };
    Ok(MaterialKind::Pbr {
        roughness,
        metallic: unit(&m.metallic, "metallic", 0.0, field)?,
        ior: m.ior.as_ref().map_or(Ok(1.5), ior_in_range)?,
        specular: unit(&m.specular, "specular", 1.0, field)?,
        specular_color,
        transmission: unit(&m.transmission, "transmission", 0.0, field)?,
        transmission_texture: None,
        attenuation_color,
        attenuation_distance,
        layers,
    })
}

/// A field that does not apply to the material's kind is most likely a mistake: say so.
fn check_fields_apply(
    m: &MaterialToml,
    kind: &MaterialKind,
    field: &dyn Fn(&str) -> String,
) -> Result<(), FieldError> {
    let pbr = matches!(kind, MaterialKind::Pbr { .. });
    for (span, name, applies) in [
        (
            m.roughness.as_ref().map(|r| r.span()),
            "roughness",
            matches!(kind, MaterialKind::Metal { .. } | MaterialKind::Pbr { .. }),
        ),
        (
            m.ior.as_ref().map(|r| r.span()),
            "ior",
            matches!(
                kind,
                MaterialKind::Dielectric { .. } | MaterialKind::Pbr { .. }
            ),
        ),
        (
            m.color.as_ref().map(|r| r.span()),
            "color",
            !matches!(kind, MaterialKind::Pbr { .. }),
        ),
        (m.base_color.as_ref().map(|r| r.span()), "base_color", pbr),
        (m.metallic.as_ref().map(|r| r.span()), "metallic", pbr),
        (m.specular.as_ref().map(|r| r.span()), "specular", pbr),
        (
            m.specular_color.as_ref().map(|r| r.span()),
            "specular_color",
            pbr,
        ),
        (
            m.transmission.as_ref().map(|r| r.span()),
            "transmission",
            pbr,
        ),
        (
            m.attenuation_color.as_ref().map(|r| r.span()),
            "attenuation_color",
            pbr,
        ),
        (
            m.attenuation_distance.as_ref().map(|r| r.span()),
            "attenuation_distance",
            pbr,
        ),
        (m.clearcoat.as_ref().map(|r| r.span()), "clearcoat", pbr),
        (
            m.clearcoat_roughness.as_ref().map(|r| r.span()),
            "clearcoat_roughness",
            pbr,
        ),
        (
            m.clearcoat_normal_map.as_ref().map(|r| r.span()),
            "clearcoat_normal_map",
            pbr,
        ),
        (m.sheen_color.as_ref().map(|r| r.span()), "sheen_color", pbr),
        (
            m.sheen_roughness.as_ref().map(|r| r.span()),
            "sheen_roughness",
            pbr,
        ),
    ] {
        if let (Some(span), false) = (span, applies) {
            return fail(
                span,
                field(name),
                format!("{name} does not apply to a {} material", m.kind.get_ref()),
            );
        }
    }
    Ok(())
}

/// `alpha_mode` (`"opaque"` unless given), `alpha` (default 1) and `alpha_cutoff` (default
/// 0.5), each checked. The numbers apply only where the mode reads them: `alpha` to mask and
/// blend, `alpha_cutoff` to mask; given elsewhere, they are most likely a mistake.
fn alpha(m: &MaterialToml, field: &dyn Fn(&str) -> String) -> Result<Alpha, FieldError> {
    let unit = |x: &S<Real>, name: &str| -> Result<f32, FieldError> {
        let v = real(x, &field(name))?;
        if !(0.0..=1.0).contains(&v) {
            return fail(x.span(), field(name), format!("must be in [0, 1], got {v}"));
        }
        Ok(v)
    };
    let mode = match &m.alpha_mode {
        None => "opaque",
        Some(mode) => match mode.get_ref().as_str() {
            known @ ("opaque" | "mask" | "blend") => known,
            other => {
                return fail(
                    mode.span(),
                    field("alpha_mode"),
                    format!(
                        "unknown alpha mode {other:?}; known modes: \"opaque\", \"mask\", \"blend\""
                    ),
                )
            }
        },
    };
    if let (Some(a), "opaque") = (&m.alpha, mode) {
        return fail(
            a.span(),
            field("alpha"),
            "an opaque material ignores alpha: add alpha_mode = \"mask\" or \"blend\"",
        );
    }
    if let Some(c) = m.alpha_cutoff.as_ref().filter(|_| mode != "mask") {
        return fail(
            c.span(),
            field("alpha_cutoff"),
            "only alpha_mode = \"mask\" has a cutoff",
        );
    }
    let opacity = m.alpha.as_ref().map_or(Ok(1.0), |a| unit(a, "alpha"))?;
    let mode = match mode {
        "mask" => AlphaMode::Mask {
            cutoff: m
                .alpha_cutoff
                .as_ref()
                .map_or(Ok(0.5), |c| unit(c, "alpha_cutoff"))?,
        },
        "blend" => AlphaMode::Blend,
        _ => AlphaMode::Opaque,
    };
    Ok(Alpha { mode, opacity })
}

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
fn normal_map(
    x: &S<toml::Value>,
    field: &str,
    folder: &Path,
    textures: &mut TextureSet,
) -> Result<(u32, f32), FieldError> {
    let expected = "must be \"file.png\" or { file = \"file.png\", scale = s }";
    let (file, scale) = match x.get_ref() {
        toml::Value::String(file) => (file.as_str(), 1.0),
        toml::Value::Table(table) => {
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
            (file, scale)
        }
        other => return fail(x.span(), field, format!("{expected}, got {other}")),
    };
    let index = textures
        .image(&folder.join(file), TextureUse::Normal)
        .or_else(|message| fail(x.span(), field, format!("{file}: {message}")))?;
    Ok((index, scale as f32))
}

/// A texture as written in a material field: `{ texture = "file" }` (relative to `folder`) or
/// `{ checker = [[r, g, b], [r, g, b]], scale = s }` (scale optional, default 1). Returns its
/// index in `textures`.
fn texture(
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
        _ => fail(
            x.span(),
            field,
            format!("{expected}; unknown keys: {}", keys.join(", ")),
        ),
    }
}
